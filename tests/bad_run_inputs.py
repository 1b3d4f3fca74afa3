"""Bad inputs to ``ptztrack run``: scenario files, and the recording's files that replace the scenario's.

Scenario files with huge, infinite or NaN values, YAML bombs and duplicate keys; ground truth (MOTChallenge
rows) that is binary, misplaced, non-finite, fractional or beyond the video; calibrations (Tsai XML, pinhole
JSON) with external entities, entity bombs, NaN or K scaled; videos that are text, short, cut or of the
wrong size. Run a few steps of the built-in ``pets`` or the given scenario.
"""

from pathlib import Path

from bad_input_files import (
    A_FEW_STEPS,
    GROUND_TRUTH_ROWS,
    PINHOLE,
    TSAI,
    XML_LAUGHS,
    YAML_DEEP_LAUGHS,
    YAML_LAUGHS,
    Case,
    _ground_truth,
    _pinhole_with_k_scaled,
    _truncated,
    _with_field,
    _xml_with_entity,
    video_bytes,
)


def _scenario(name: str, text: str | bytes, *extra: str, exit_status: int = 2) -> Case:
    """A scenario file run for a few steps, unless it sets ``frames`` itself."""
    steps = () if isinstance(text, str) and text.startswith("frames") else A_FEW_STEPS
    return Case(name, ("run", "--scenario", "{dir}/s.yaml", *steps, *extra), {"s.yaml": text}, exit_status)


def _recording(
    name: str, option: str, filename: str, content: bytes | str, *extra: str, says: tuple[str, ...] = ()
) -> Case:
    argv = ("run", "--scenario", "pets", *A_FEW_STEPS, option, f"{{dir}}/{filename}", *extra)
    return Case(name, argv, {filename: content}, says=says)


def run_cases(scratch: Path | None) -> list[Case]:
    """The cases of ``ptztrack run``'s files; ``scratch`` is where video files are made (None: a temporary folder)."""
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
        _scenario("a camera network run as one camera", "cameras: [{position_m: [0, 0, 3]}]\n"),
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
    ]
