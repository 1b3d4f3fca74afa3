"""Bad dataset files: multi-view datasets for ``ptztrack experiment occupancy`` and one-view datasets for
``ptztrack experiment pets --dataset``.

One PETS view (View_001: its Tsai XML or pinhole JSON calibration, detections and the first frames' ground
truth) with missing or contradictory fields, parameters beyond the machine (cells, windows, samples),
areas it does not see, ground truth outside the area or beyond the video, calibrations that do not fit its
detections, image folders and videos of the wrong size, and detection files that are huge, truncated or
outside the image.
"""

import gzip
from pathlib import Path

from bad_input_files import (
    A_FEW_STEPS,
    DETECTION_ROWS,
    FIRST_TEN_FRAMES,
    FIRST_TWO_FRAMES,
    GROUND_TRUTH_ROWS,
    PINHOLE,
    TSAI,
    Case,
    _detections_of,
    _ground_truth,
    _gzip_bomb,
    _pinhole_with_k_scaled,
    _png,
    _with_field,
    video_bytes,
)


def calibration_fit_case(name: str, k_scale: float, extra: tuple[str, ...], says: tuple[str, ...] = ()) -> Case:
    """A dataset whose one view, View_001, has the ground truth's own boxes as detections and PETS's pinhole
    calibration with K scaled by ``k_scale`` (1: the calibration that projects the people onto the boxes)."""
    return _dataset(
        name,
        view="image_size_px: [768, 576], detections: det.txt",
        calibration="c.json",
        files={
            "c.json": _pinhole_with_k_scaled(k_scale),
            "det.txt": _detections_of(FIRST_TEN_FRAMES),
            "gt.txt": _ground_truth(FIRST_TEN_FRAMES),
        },
        extra=extra,
        exit_status=0,
        says=says,
    )


def _dataset(
    name: str,
    view: str = "detections: det.txt",
    top: str = "",
    files: dict | None = None,
    extra: tuple = (),
    exit_status: int = 2,
    area: str = "[[-12, -13], [-3, -5]]",
    says: tuple[str, ...] = (),
    calibration: str = "c.xml",
) -> Case:
    """A one-view PETS dataset file (``view``: the view's fields besides its name and calibration;
    ``top``: more top-level lines), its calibration, two frames of detections and the first
    ground-truth rows; run by ``experiment occupancy``. ``area``: its area_m, by default one that
    View_001 sees whole and that holds those rows' people; ``calibration``: the view's file (c.xml, the
    Tsai XML, is always written); ``says``: as :class:`Case`'s."""
    document = (
        f"frame_rate_hz: 10\narea_m: {area}\nground_truth: gt.txt\n"
        f"views:\n  - {{name: View_001, calibration: {calibration}, {view}}}\n{top}"
    )
    given = {"d.yaml": document, "c.xml": TSAI, "det.txt": "\n".join(DETECTION_ROWS) + "\n"}
    given["gt.txt"] = _ground_truth(FIRST_TWO_FRAMES)
    return Case(
        name, ("experiment", "occupancy", "{dir}/d.yaml", *extra), {**given, **(files or {})}, exit_status, says
    )


def _ptz_dataset(
    name: str,
    scratch: Path | None,
    view: str = "video: v.avi",
    top: str = "ground_truth: gt.txt\n",
    files: dict | None = None,
    extra: tuple = (),
    exit_status: int = 2,
    says: tuple[str, ...] = (),
    frame_rate: str = "10",
) -> Case:
    """A one-view dataset file for the PTZ tables (``view``: the view's fields besides its name, pinhole
    calibration and image size; ``top``: the top-level lines besides its frame rate and area), a video of
    four grey 768 x 576 frames and the first two frames' ground truth, at ``frame_rate`` fps; run by ``experiment pets
    --dataset`` for two steps of ``fix``."""
    document = (
        f"frame_rate_hz: {frame_rate}\narea_m: [[-12, -13], [-3, -5]]\n{top}"
        f"views:\n  - {{name: View_001, calibration: c.json, image_size_px: [768, 576], {view}}}\n"
    )
    given = {"d.yaml": document, "c.json": PINHOLE, "v.avi": video_bytes(4, (768, 576), scratch)}
    given["gt.txt"] = _ground_truth(FIRST_TWO_FRAMES)
    argv = ("experiment", "pets", "--dataset", "{dir}/d.yaml", "--strategies", "fix", *A_FEW_STEPS, *extra)
    return Case(name, argv, {**given, **(files or {})}, exit_status, says)


def dataset_cases(scratch: Path | None) -> list[Case]:
    """The cases of dataset files; ``scratch`` is where video files are made (None: a temporary folder)."""
    truth = GROUND_TRUTH_ROWS
    return [
        _dataset("dataset: a good one", exit_status=0),
        Case("dataset missing", ("experiment", "occupancy", "{dir}/missing.yaml")),
        Case("dataset a list", ("experiment", "occupancy", "{dir}/d.yaml"), {"d.yaml": "- 1\n- 2\n"}),
        _dataset("dataset duplicate keys", top="frame_rate_hz: 15\n"),
        _dataset("dataset frames 1e9", top="frames: 1000000000\n"),
        _dataset("dataset cell_m 1e-5", top="occupancy: {cell_m: 0.00001}\n"),
        _dataset(
            "dataset cell_m 1000 on a 40 m area",
            top="occupancy: {cell_m: 1000}\n",
            area="[[-20, -15], [20, 25]]",
            says=("occupancy.cell_m 1000 m makes 1 x 1 cells", "at most occupancy.separation_m (0.5 m)"),
        ),
        _dataset(
            "dataset window_m 1000",
            top="occupancy: {window_m: 1000}\n",
            says=("occupancy.window_m 1000 m's windows of 40001 x 40001 cells", "GB available"),
        ),
        _dataset(
            "dataset window_m 1000 on a partly seen area",
            top="occupancy: {window_m: 1000}\n",
            area="[[-20, -15], [20, 25]]",
            says=("occupancy.window_m 1000 m's windows",),
        ),
        _dataset(
            "dataset window_m 300",
            top="occupancy: {window_m: 300}\n",
            says=("occupancy.window_m 300 m's windows", "GB available"),
        ),
        _dataset("dataset separation_m 1000", top="occupancy: {separation_m: 1000}\n", says=("separation_m 1000 m",)),
        _dataset(
            "dataset kernel_sigma_m 1000",
            top="occupancy: {kernel_sigma_m: 1000}\n",
            says=("occupancy.kernel_sigma_m 1000 m's smoothing", "at most 2 s"),
        ),
        _dataset(
            "dataset outline_points_per_box 10000",
            top="occupancy: {outline_points_per_box: 10000, samples_per_height: 1000}\n",
            says=("box outlines (10000 points a box, 3 heights of 1000 samples)", "outline_points_per_box"),
        ),
        _dataset(
            "dataset canny_low above canny_high",
            top="occupancy: {canny_low: 200}\n",
            says=("occupancy: canny_low (200) must be at most canny_high (150)",),
        ),
        _dataset("dataset samples 1e9", top="occupancy: {samples_per_height: 1000000000}\n"),
        _ptz_dataset("pets --dataset: a well-formed one", scratch, exit_status=0),
        _ptz_dataset(
            "pets --dataset: a view without a video",
            scratch,
            view="detections: det.txt",
            says=("d.yaml: no view with a video",),
        ),
        _ptz_dataset("pets --dataset: no ground truth", scratch, top="", says=("has no ground truth",)),
        _ptz_dataset(
            "pets --dataset: frames of another size than the file states",
            scratch,
            files={"v.avi": video_bytes(4, (640, 480), scratch)},
            says=("v.avi: frames are 640x480 px, expected 768x576",),
        ),
        _ptz_dataset(
            "pets --dataset: ground truth beyond the video",
            scratch,
            files={"gt.txt": _ground_truth([*FIRST_TWO_FRAMES, _with_field(FIRST_TWO_FRAMES[0], 0, "9")])},
            says=(f"gt.txt: line {len(FIRST_TWO_FRAMES) + 1}: frame 9 is beyond the 4 frames of",),
        ),
        _ptz_dataset(
            "pets --dataset: a view it does not have",
            scratch,
            extra=("--dataset-view", "View_9"),
            says=("no view 'View_9'",),
        ),
        _ptz_dataset(
            "pets --dataset: the detections detector on a view without boxes",
            scratch,
            extra=("--detector", "detections"),
            says=("detector.kind 'detections' needs", "detections"),
        ),
        _ptz_dataset(
            "pets --dataset: 12.5 fps give 6.25 Hz steps, warned",
            scratch,
            top="ground_truth: gt.txt\n",
            frame_rate="12.5",
            exit_status=0,
            says=("its 12.5 fps give steps of 6.25 Hz (every 2 frames), not the protocol's 5 Hz",),
        ),
        _ptz_dataset("pets --dataset: no such file", scratch, files={"d.yaml": None}, says=("d.yaml",)),
        _dataset("dataset view without evidence", view="weight: 1"),
        _dataset("dataset view calibration missing", files={"c.xml": None}),
        _dataset("dataset area behind the view", area="[[-60, -60], [-40, -40]]"),
        _dataset("dataset area outside the view's image", area="[[-40, 0], [-30, 10]]"),
        _dataset("dataset area partly seen", extra=("--methods",), area="[[-20, -15], [20, 25]]", exit_status=0),
        _dataset("dataset calibration of another size", view="detections: det.txt, image_size_px: [640, 480]"),
        _dataset(
            "dataset ground truth 1000 m away",
            files={"gt.txt": _ground_truth([_with_field(row, 7, "1000") for row in FIRST_TWO_FRAMES])},
            says=("gt.txt: no row of the 2 frames used lies in area_m [[-12, -13], [-3, -5]] (line 1: (1000, ",),
        ),
        _dataset(
            "dataset ground truth partly outside the area",
            files={"gt.txt": _ground_truth([_with_field(FIRST_TWO_FRAMES[0], 7, "1000"), *FIRST_TWO_FRAMES[1:]])},
            extra=("--methods",),
            exit_status=0,
            says=(f"gt.txt: 1 of {len(FIRST_TWO_FRAMES)} rows of the 2 frames used lie outside area_m",),
        ),
        calibration_fit_case(
            "dataset calibration with K halved",
            0.5,
            ("--methods",),
            says=("c.json: views.0 (View_001): its detections stand a median", "is this the view's calibration?"),
        ),
        _dataset(
            "dataset ground truth frame 99999999",
            files={"gt.txt": _ground_truth([*FIRST_TWO_FRAMES, _with_field(truth[0], 0, "99999999")])},
            extra=("--frames", "2"),
            says=(f"gt.txt: line {len(FIRST_TWO_FRAMES) + 1}: frame 99999999 is beyond the 100000 frames",),
        ),
        _dataset(
            "dataset ground truth beyond the video",
            view="video: v.avi",
            files={
                "v.avi": video_bytes(3, (768, 576), scratch),
                "gt.txt": _ground_truth([*FIRST_TWO_FRAMES, _with_field(truth[0], 0, "5")]),
            },
            says=(f"gt.txt: line {len(FIRST_TWO_FRAMES) + 1}: frame 5 is beyond the 3 frames of the views' videos",),
        ),
        _dataset(
            "dataset image folder whose last frame has another size",
            view="images: frames",
            files={f"frames/{frame}.png": _png((768, 576)) for frame in ("0001", "0002")}
            | {"frames/0003.png": _png((640, 480))},
            says=("frames/0003.png: 640x480 px, but 0001.png is 768x576 px",),
        ),
        _dataset("detections frame 1e9", files={"det.txt": "1000000000,-1,300,200,40,100,0.9,-1,-1,-1\n"}),
        _dataset("detections a box of width 0", files={"det.txt": "1,-1,300,200,0,100,0.9,-1,-1,-1\n"}),
        _dataset(
            "detections a box outside the image",
            files={"det.txt": DETECTION_ROWS[0] + "\n" + _with_field(DETECTION_ROWS[1], 2, "5000") + "\n"},
            says=("det.txt: line 2: the box at (5000, 201) px, 40 x 100 px, lies outside the view's 768x576 px image",),
        ),
        _dataset("detections 9 fields", files={"det.txt": "1,-1,300,200,40,100,0.9,-1,-1\n"}),
        _dataset("detections gzip bomb", view="detections: det.txt.gz", files={"det.txt.gz": _gzip_bomb(210_000_000)}),
        _dataset(
            "detections gzip truncated",
            view="detections: det.txt.gz",
            files={"det.txt.gz": gzip.compress(b"1,-1,300,200,40,100,0.9,-1,-1,-1\n" * 100)[:-8]},
        ),
        _dataset("occupancy --out not empty", files={"out/keep.txt": "keep me\n"}, extra=("--out", "{dir}/out")),
    ]
