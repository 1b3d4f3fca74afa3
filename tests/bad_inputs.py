"""A regression corpus of bad and near-miss inputs to the ``ptztrack`` command.

Each case is the files it needs (written into a scratch directory), the command line
(``{dir}`` is the scratch directory, ``{data}`` the built-in PETS folder) and the exit status
expected: 2 for a clean one-line error, 0 where the input is legitimate.
Used by tests/test_bad_inputs.py: every case in-process (:func:`run_case_in_process`), a few also in a
fresh process (:func:`run_case`).
"""

import functools
import gzip
import json
import os
import subprocess
import sys
import tempfile
import threading
import time
import zlib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import cv2
import numpy as np

PETS = resources.files("ptztrack.data") / "pets2009_s2l1"
PINHOLE = (PETS / "pinhole.json").read_text()
TSAI = (PETS / "View_001.xml").read_text()
GROUND_TRUTH_ROWS = (PETS / "gt_mot15.txt").read_text().splitlines()[:40]
A_FEW_STEPS = ["--frames", "2"]


@dataclass(frozen=True)
class Case:
    name: str
    argv: tuple[str, ...]
    files: dict[str, bytes | str | None] = field(default_factory=dict)  # None: no such file
    exit_status: int = 2
    says: tuple[str, ...] = ()  # what the line must name (the field, the file, the bound)


def _scenario(name: str, text: str | bytes, *extra: str, exit_status: int = 2) -> Case:
    """A scenario file run for a few steps, unless it sets ``frames`` itself."""
    steps = () if isinstance(text, str) and text.startswith("frames") else A_FEW_STEPS
    return Case(name, ("run", "--scenario", "{dir}/s.yaml", *steps, *extra), {"s.yaml": text}, exit_status)


def _recording(
    name: str, option: str, filename: str, content: bytes | str, *extra: str, says: tuple[str, ...] = ()
) -> Case:
    argv = ("run", "--scenario", "pets", *A_FEW_STEPS, option, f"{{dir}}/{filename}", *extra)
    return Case(name, argv, {filename: content}, says=says)


def _ground_truth(rows: list[str]) -> str:
    return "\n".join(rows) + "\n"


def _with_field(row: str, index: int, value: str) -> str:
    fields = row.split(",")
    fields[index] = value
    return ",".join(fields)


def _xml_with_entity(declaration: str, reference: str) -> str:
    body = TSAI.split("\n", 1)[1].replace('name="View_001"', f'name="{reference}"')
    return f'<?xml version="1.0"?>\n<!DOCTYPE Camera [{declaration}]>\n{body}'


def video_bytes(frames: int, size_px: tuple[int, int], directory: Path | None, codec: str = "MJPG") -> bytes:
    """A small AVI of ``frames`` grey frames of ``size_px`` (width, height) in ``codec`` (a fourcc);
    made in ``directory``, or in a temporary one."""
    if directory is None:
        with tempfile.TemporaryDirectory() as scratch:
            return video_bytes(frames, size_px, Path(scratch), codec)
    path = directory / f"video_{frames}_{size_px[0]}_{codec}.avi"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*codec), 7.0, size_px)
    for _ in range(frames):
        writer.write(np.full((size_px[1], size_px[0], 3), 128, np.uint8))
    writer.release()
    return path.read_bytes()


def _truncated(video: bytes) -> bytes:
    """The first half of a video, as a copy cut short leaves it: its header still counts every frame, and
    a frame cut in the middle makes FFmpeg's decoder print lines of its own (MPEG-4 Part 2 does, as
    PETS's MS-MPEG-4 does; MJPG does not)."""
    return video[: len(video) // 2]


YAML_LAUGHS = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"{chr(98 + level)}: &{chr(98 + level)} [{', '.join(['*' + chr(97 + level)] * 9)}]\n" for level in range(8)
)
YAML_DEEP_LAUGHS = (
    "a: &a ["
    + ", ".join(["xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx"] * 20)
    + "]\n"
    + "".join(
        f"{chr(98 + level)}: &{chr(98 + level)} [{', '.join(['*' + chr(97 + level)] * 20)}]\n" for level in range(6)
    )
)
XML_LAUGHS = '<!ENTITY a "aaaaaaaaaa">' + "".join(
    f'<!ENTITY {chr(98 + level)} "{("&" + chr(97 + level) + ";") * 10}">' for level in range(8)
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


def _pinhole_with_k_scaled(scale: float) -> str:
    """PETS's pinhole calibrations with View_001's focal lengths and principal point scaled."""
    views = json.loads(PINHOLE)
    views["View_001"]["K"] = (np.diag([scale, scale, 1.0]) @ np.asarray(views["View_001"]["K"])).tolist()
    return json.dumps(views)


def _detections_of(rows: list[str]) -> str:
    """Detection rows that are the ground-truth rows' View_001 boxes."""
    return "".join(f"{','.join(row.split(',')[:1] + ['-1'] + row.split(',')[2:6])},1,-1,-1,-1\n" for row in rows)


FIRST_TEN_FRAMES = [row for row in GROUND_TRUTH_ROWS if int(row.split(",")[0]) <= 10]
FIRST_TWO_FRAMES = [row for row in GROUND_TRUTH_ROWS if row.split(",")[0] in ("1", "2")]
DETECTION_ROWS = ["1,-1,300,200,40,100,0.9,-1,-1,-1", "2,-1,302,201,40,100,0.9,-1,-1,-1"]


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


def _png(size_px: tuple[int, int]) -> bytes:
    """A grey PNG image of ``size_px`` (width, height)."""
    return cv2.imencode(".png", np.full((size_px[1], size_px[0], 3), 128, np.uint8))[1].tobytes()


@functools.cache
def _gzip_bomb(uncompressed_bytes: int) -> bytes:
    """A gzip file of ``uncompressed_bytes`` of commas, made in pieces (about 1000 times smaller)."""
    compressor = zlib.compressobj(9, zlib.DEFLATED, 16 + zlib.MAX_WBITS)
    piece = b"," * 1_000_000
    return b"".join(compressor.compress(piece) for _ in range(uncompressed_bytes // len(piece))) + compressor.flush()


def cases(scratch: Path | None) -> list[Case]:
    """Every case; ``scratch`` is where video files are made (None: a temporary folder)."""
    truth = GROUND_TRUTH_ROWS
    return [
        _scenario("binary scenario", b"\x89PNG\r\n\x1a\n\xff\xfe\x00\x01" * 40),
        _recording("binary ground truth", "--gt", "gt.txt", b"\xff\xfe\x00\x81" * 100),
        _recording(
            "ground truth 1000 m from its boxes' people",
            "--gt",
            "gt.txt",
            _ground_truth([_with_field(row, 7, str(float(row.split(",")[7]) + 1000)) for row in GROUND_TRUTH_ROWS]),
            says=("gt.txt: none of its", "lies in the image of"),
        ),
        Case(
            "recording calibration with K halved",
            ("run", "--scenario", "pets", *A_FEW_STEPS, "--calibration", "{dir}/c.json"),
            {"c.json": _pinhole_with_k_scaled(0.5)},
            exit_status=0,
            says=("box heights from their boxes' feet in", "is this the view's calibration?"),
        ),
        _scenario("people.count 1e20", "people: {count: 1e20}\n"),
        _scenario("people.count 1e6", "people: {count: 1000000}\n"),
        _scenario("frames 1e9", "frames: 1000000000\n"),
        _scenario("frames 1e13", "frames: 1e13\n"),
        _scenario("control.samples 1e9", "control: {samples: 1000000000}\n"),
        _scenario("image_size_px 1e8", "camera: {image_size_px: [100000000, 100000000]}\n"),
        _scenario("area_m 1e308", "area_m: [1e308, 1e308]\n"),
        _scenario("area_m inf", "area_m: [.inf, 15]\n"),
        Case("--seed -5", ("run", *A_FEW_STEPS, "--seed", "-5")),
        Case(
            "follow --target x",
            ("follow", "--target", "x"),
            says=("error: argument --target: expected a whole number >= 0, got 'x'",),
        ),
        _recording(
            "XML external entity",
            "--calibration",
            "c.xml",
            _xml_with_entity('<!ENTITY e SYSTEM "file:///etc/passwd">', "&e;"),
        ),
        _recording(
            "XML entity over HTTP",
            "--calibration",
            "c.xml",
            _xml_with_entity('<!ENTITY e SYSTEM "http://127.0.0.1:9/e">', "&e;"),
        ),
        _recording("XML entity bomb", "--calibration", "c.xml", _xml_with_entity(XML_LAUGHS, "&i;")),
        _recording("Tsai focal nan", "--calibration", "c.xml", TSAI.replace('focal="5.5549183034e+00"', 'focal="nan"')),
        _recording(
            "ground truth NaN position", "--gt", "gt.txt", _ground_truth([_with_field(truth[0], 7, "nan"), *truth[1:]])
        ),
        _recording(
            "ground truth inf position", "--gt", "gt.txt", _ground_truth([_with_field(truth[0], 8, "inf"), *truth[1:]])
        ),
        _scenario("YAML billion laughs", YAML_LAUGHS),
        _scenario("YAML deeper anchor bomb", YAML_DEEP_LAUGHS),
        _recording("pinhole fx NaN", "--calibration", "c.json", PINHOLE.replace("1125.8236906695045", "NaN")),
        _recording(
            "pinhole K all NaN",
            "--calibration",
            "c.json",
            '{"View_001": {"K": [[NaN, NaN, NaN], [NaN, NaN, NaN], [NaN, NaN, NaN]], '
            '"dist": [0, 0, 0, 0, 0], "R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 0, 0]}}',
        ),
        _scenario("pixel_noise_px inf", "detector: {pixel_noise_px: .inf}\n"),
        Case("--beta nan", ("experiment", "pets", "--beta", "nan", *A_FEW_STEPS)),
        Case("--beta -3", ("experiment", "pets", "--beta", "-3", *A_FEW_STEPS)),
        Case("--beta inf", ("experiment", "pets", "--beta", "inf", *A_FEW_STEPS)),
        _scenario("duplicate YAML keys", "frames: 5\npeople: {count: 3}\nframes: 6\n"),
        _recording("duplicate ground-truth rows", "--gt", "gt.txt", _ground_truth([truth[0], *truth])),
        _recording(
            "fractional ground-truth frame", "--gt", "gt.txt", _ground_truth([_with_field(truth[0], 0, "1.5"), *truth])
        ),
        _recording("a text file as the video", "--video", "text.avi", "not a video\n"),
        _recording(
            "a video too short for HOG",
            "--video",
            "short.avi",
            video_bytes(3, (768, 576), scratch),
            "--detector",
            "hog",
            "--frames",
            "10",
        ),
        _recording(
            "a truncated video",
            "--video",
            "cut.avi",
            _truncated(video_bytes(40, (768, 576), scratch, "mp4v")),
            "--frames",
            "20",
            says=("cut.avi: the video cannot be read at frame 38, which the run needs",),
        ),
        Case(
            "a folder as the video",
            ("run", "--scenario", "pets", *A_FEW_STEPS, "--video", "{dir}"),
            says=("{dir}: is a folder, expected a video file",),
        ),
        _recording(
            "a video of the wrong size",
            "--video",
            "small.avi",
            video_bytes(3, (320, 240), scratch),
            "--detector",
            "hog",
        ),
        Case("--out names a file", ("run", *A_FEW_STEPS, "--out", "{dir}/file"), {"file": "keep me\n"}),
        Case("--out in a missing folder", ("run", *A_FEW_STEPS, "--out", "{dir}/missing/out")),
        Case("--out not empty", ("run", *A_FEW_STEPS, "--out", "{dir}/out"), {"out/metrics.json": "{}\n"}),
        Case(
            "--out where nothing can be written",
            ("run", *A_FEW_STEPS, "--out", "/proc/x"),
            says=("--out /proc/x: cannot write into /proc (",),
        ),
        Case(
            "serve-camera: --truth-log where nothing can be written",
            ("serve-camera", "--port", "0", "--truth-log", "/proc/x.csv"),
            says=("--truth-log /proc/x.csv: cannot write into /proc (",),
        ),
        Case(
            "--json in a missing folder",
            ("experiment", "synthetic", "--sequences", "1", *A_FEW_STEPS, "--json", "{dir}/missing/x.json"),
        ),
        Case("--json names a folder", ("experiment", "synthetic", "--sequences", "1", *A_FEW_STEPS, "--json", "{dir}")),
        _scenario("a camera network run as one camera", "cameras: [{position_m: [0, 0, 3]}]\n"),
        Case("network: no setting", ("experiment", "network")),
        Case("network: --max-ptz 0", ("experiment", "network", "synthetic", "--max-ptz", "0")),
        Case("network: --first-sequence -1", ("experiment", "network", "synthetic", "--first-sequence", "-1")),
        Case(
            "network pets: the development sequences of the synthetic setting",
            ("experiment", "network", "pets", "--first-sequence", "1000", *A_FEW_STEPS),
            says=("--first-sequence",),
        ),
        Case(
            "network pets: the synthetic setting's option",
            ("experiment", "network", "pets", "--max-ptz", "2", *A_FEW_STEPS),
            says=("--max-ptz",),
        ),
        Case(
            "network pets: a view the dataset does not have",
            ("experiment", "network", "pets", "--dataset-view", "View_009", *A_FEW_STEPS),
            says=("no view 'View_009'", "View_001, View_003"),
        ),
        Case(
            "network: --json in a missing folder",
            ("experiment", "network", "synthetic", "--sequences", "1", *A_FEW_STEPS, "--json", "{dir}/missing/x.json"),
        ),
        Case("--plot in a missing folder", ("experiment", "msg", "--runs", "1", "--plot", "{dir}/missing/x.png")),
        Case("--trails in a missing folder", ("experiment", "msg", "--runs", "1", "--trails", "{dir}/missing/x.png")),
        Case(
            "experiment follow: a person not annotated after one who is",
            ("experiment", "follow", "--targets", "9", "999"),
            says=("gt_mot15.txt: no person 999 (the people are 1, 2,",),
        ),
        Case(
            "experiment follow: --otb-tracks 0",
            ("experiment", "follow", "--otb-tracks", "0"),
            says=("expected 1 to 19",),
        ),
        Case(
            "experiment follow: --otb-tracks 1000",
            ("experiment", "follow", "--otb-tracks", "1000"),
            says=("--otb-tracks 1000: expected 1 to 19, as ",),
        ),
        Case("scenario missing", ("run", "--scenario", "{dir}/missing.yaml")),
        _scenario("scenario a list", "- 1\n- 2\n"),
        _scenario("scenario a huge value", "frames: [" + ", ".join(["123456789"] * 20000) + "]\n"),
        _scenario("scenario empty", "", exit_status=0),
        _scenario("negative frame rate", "frame_rate_hz: -5\n"),
        _scenario("NaN frame rate", "frame_rate_hz: .nan\n"),
        _scenario("bad pose error", "camera: {pose_error: {pan_tilt_sigma_deg: .inf}}\n"),
        _recording("ground truth empty", "--gt", "gt.txt", ""),
        _recording(
            "ground truth beyond the video",
            "--gt",
            "gt.txt",
            _ground_truth([*truth, _with_field(truth[0], 0, "99999999")]),
            "--frames",
            "3",
            says=(f"gt.txt: line {len(truth) + 1}: frame 99999999 is beyond the 795 frames of", "View_001.avi"),
        ),
        _recording("ground truth negative frame", "--gt", "gt.txt", _ground_truth([_with_field(truth[0], 0, "-3")])),
        _recording("calibration empty", "--calibration", "c.json", ""),
        _recording("calibration binary", "--calibration", "c.xml", b"\x00\xff" * 50),
        _dataset("dataset: a good one", exit_status=0),
        Case("dataset missing", ("experiment", "occupancy", "{dir}/missing.yaml")),
        Case(
            "occupancy --lead-in on the room",
            ("experiment", "occupancy", "synthetic-room", "--lead-in", "5"),
            says=("--lead-in", "synthetic-plaza only"),
        ),
        Case(
            "occupancy --lead-in negative",
            ("experiment", "occupancy", "synthetic-plaza", "--lead-in", "-1"),
            says=("--lead-in",),
        ),
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
        Case("live: not an ONVIF URL", ("live", "--camera", "rtsp://op:pw@127.0.0.1/x", "--calibration", "virtual")),
        Case(
            "live: port 0",
            ("live", "--camera", "onvif://127.0.0.1:0", "--calibration", "virtual"),
            says=("--camera onvif://127.0.0.1:0: the port is not a number from 1 to 65535",),
        ),
        Case(
            "live: a truth log that is not there",
            ("live", "--camera", "onvif://127.0.0.1:9", "--calibration", "virtual", "--truth", "{dir}/missing.csv"),
            says=("{dir}/missing.csv: no such truth log file",),
        ),
        Case(
            "live: --time-scale 0", ("live", "--camera", "127.0.0.1", "--calibration", "virtual", "--time-scale", "0")
        ),
        Case(
            "live: a zoom curve that falls",
            ("live", "--camera", "127.0.0.1:9", "--calibration", "{dir}/c.yaml"),
            {"c.yaml": "pan_deg: [-90, 90]\ntilt_deg: [-45, 45]\nzoom_curve: [[0, 4], [1, 1]]\n"},
        ),
        Case(
            "live: two cameras, three calibrations",
            ("live", "--camera", "127.0.0.1:9", "--camera", "127.0.0.1:10", *("--calibration", "virtual") * 3),
            says=("3 --calibration for 2 --camera",),
        ),
        Case(
            "live: a network deciding by fix",
            ("live", "--camera", "127.0.0.1:9", "--camera", "127.0.0.1:10", "--calibration", "virtual")
            + ("--policy", "fix"),
            says=("intg or smpl", "fix"),
        ),
        Case("serve-camera: a user without a password", ("serve-camera", "--port", "0", "--user", "op")),
        Case(
            "serve-camera: cameras past the last port",
            ("serve-camera", "--port", "65535", "--cameras", "2"),
            says=("past port 65535",),
        ),
        Case("view: a folder without view states", ("view", "{dir}")),
        Case("view: a file, not a folder", ("view", "{dir}/f"), {"f": "keep me\n"}),
        Case("view: a line that is not a state", ("view", "{dir}/run"), {"run/view_states.jsonl": '{"step": 0}\n'}),
        Case("view: --steps-per-s 0", ("view", "{dir}", "--steps-per-s", "0")),
        Case(
            "occupancy --frames 1e6",
            ("experiment", "occupancy", "synthetic-room", "--frames", "1000000"),
            says=("--frames", "at most 100000"),
        ),
        _dataset("occupancy --out not empty", files={"out/keep.txt": "keep me\n"}, extra=("--out", "{dir}/out")),
    ]


@dataclass(frozen=True)
class Outcome:
    exit_status: int
    stderr: str
    seconds: float
    peak_memory_mb: float


def write_case(case: Case, directory: Path) -> list[str]:
    """Write the case's files into ``directory``; its command line there."""
    for name, content in case.files.items():
        if content is None:
            continue
        path = directory / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)
    return [part.replace("{dir}", str(directory)) for part in case.argv]


def run_case(case: Case, directory: Path, timeout_s: float = 60.0) -> Outcome:
    """Write the case's files into ``directory`` and run the command in a fresh process, measuring its
    wall time and peak resident memory (killed after ``timeout_s``)."""
    argv = write_case(case, directory)
    with tempfile.TemporaryFile("w+") as stderr:
        start = time.perf_counter()
        process = subprocess.Popen(
            [sys.executable, "-m", "ptztrack.cli", *argv], stdout=subprocess.DEVNULL, stderr=stderr
        )
        timer = threading.Timer(timeout_s, process.kill)
        timer.start()
        _, status, usage = os.wait4(process.pid, 0)
        timer.cancel()
        seconds = time.perf_counter() - start
        process.returncode = os.waitstatus_to_exitcode(status)
        stderr.seek(0)
        return Outcome(process.returncode, stderr.read(), seconds, usage.ru_maxrss / 1024)
