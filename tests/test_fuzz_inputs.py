"""Fuzzing every reader: generated scenario documents, valid and near-valid, and mutations of every
file format. Whatever the input, the result is a value or one clean :class:`InputError` line,
never another exception; a small dataset file goes through the command itself, which exits 0, or 2
with one line. Derandomised, so that a run is repeatable; the examples per test are in ``EXAMPLES``.
"""

import gzip
import json
import logging
import math
import re
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from bad_dataset_inputs import _dataset
from bad_input_files import video_bytes
from bad_inputs import write_case
from ptztrack.builders.budget import refuse_if_too_large
from ptztrack.builders.camera_calibration import camera_spaces, pose_timeline
from ptztrack.builders.episode import run_episode
from ptztrack.cli import main
from ptztrack.config import (
    MultiViewDataset,
    Scenario,
    ScenarioError,
    dataset_from_dict,
    load_camera_calibration,
    load_dataset,
    load_scenario,
    scenario_from_dict,
)
from ptztrack.config.camera_calibration import CameraCalibrationFile, write_camera_calibration
from ptztrack.files import InputError
from ptztrack.geometry.calibration import load_calibration
from ptztrack.geometry.registration import ReferenceIndex, load_index, save_index
from ptztrack.occupancy.multiview import load_mot_detections
from ptztrack.scene.pets import RecordedVideo, load_cvml, load_mot_ground_truth

EXAMPLES = 200
RUN_EXAMPLES = 20
"""Valid small scenarios run for a few steps each: fewer examples, each a closed-loop episode."""
DATASET_RUN_EXAMPLES = 60
"""Mutated small dataset files run through the command: fewer examples, the valid ones each an experiment."""
FUZZ = settings(
    max_examples=EXAMPLES,
    derandomize=True,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
PETS = resources.files("ptztrack.data") / "pets2009_s2l1"
EXAMPLE_SCENARIO = Path(__file__).parents[1] / "examples" / "scenario.yaml"
EXAMPLE_DATASET = PETS / "dataset.yaml"

# Values a user might write by mistake: near the edges of every range, and of the wrong kind.
NEAR_MISSES = st.one_of(
    st.sampled_from([0, -1, 1, 2, 0.5, -0.0, 1e308, -1e308, 10**20, math.nan, math.inf, -math.inf]),
    st.sampled_from(["", "abc", "1e3", "nan", None, True, [], {}, [1], [1, 2, 3], {"a": 1}]),
    st.integers(-(10**12), 10**12),
    st.floats(allow_nan=True, allow_infinity=True),
    st.lists(st.floats(-1e3, 1e3), max_size=4),
)


def _fields(model) -> dict:
    """{field: sub-model or None} of a pydantic model class, for generating documents like it."""
    fields = {}
    for name, info in model.model_fields.items():
        annotation = info.annotation
        fields[name] = annotation if isinstance(annotation, type) and hasattr(annotation, "model_fields") else None
    return fields


def documents(model=Scenario, depth: int = 0) -> st.SearchStrategy:
    """Mappings of some of ``model``'s fields (nested sections as mappings) to near-miss values,
    plus now and then an unknown key."""
    fields = _fields(model)

    def value(name):
        section = fields[name]
        if section is not None and depth < 2:
            return st.one_of(documents(section, depth + 1), NEAR_MISSES)
        return NEAR_MISSES

    keys = st.sampled_from([*fields, "unknown_key"])
    return st.dictionaries(keys, st.none(), max_size=4).flatmap(
        lambda chosen: st.fixed_dictionaries({key: value(key) if key in fields else NEAR_MISSES for key in chosen})
    )


def one_clean_line(error: InputError) -> None:
    message = str(error)
    assert "\n" not in message and len(message) <= 300, message


@FUZZ
@given(documents())
def test_a_scenario_document_is_a_scenario_or_one_clean_error(document):
    try:
        scenario = scenario_from_dict(document, "fuzz")
    except ScenarioError as error:
        one_clean_line(error)
        return
    try:
        refuse_if_too_large(scenario, ("fix", "intg", "smpl"), available_bytes=64e9)
    except ScenarioError as error:
        one_clean_line(error)


SMALL_VALID = st.fixed_dictionaries(
    {
        "frames": st.integers(1, 3),
        "area_m": st.tuples(st.floats(1.0, 60.0), st.floats(1.0, 60.0)),
        "people": st.fixed_dictionaries(
            {"count": st.integers(0, 9), "speed_m_s": st.just((0.5, 2.0)), "enter_leave": st.booleans()}
        ),
        "camera": st.fixed_dictionaries(
            {"image_size_px": st.tuples(st.integers(16, 320), st.integers(16, 240)), "f_min_px": st.floats(20, 2000)}
        ),
        "control": st.fixed_dictionaries({"samples": st.integers(1, 30), "beta": st.floats(0, 10)}),
        "detector": st.fixed_dictionaries(
            {"kind": st.sampled_from(["ideal", "realistic"]), "false_positives_per_frame": st.floats(0, 3)}
        ),
    }
)


@settings(FUZZ, max_examples=RUN_EXAMPLES)
@given(SMALL_VALID, st.sampled_from(["fix", "patrol", "random", "intg", "smpl"]))
def test_a_valid_small_scenario_runs(document, policy):
    episode = run_episode(scenario_from_dict(document, "fuzz"), policy, 0)
    assert len(episode.actions) == document["frames"]


def mutations(original: bytes) -> st.SearchStrategy:
    """``original`` with one or a few edits: a number replaced by a near miss, a byte range replaced
    by random bytes, a span deleted, or a line repeated."""
    numbers = [match.span() for match in re.finditer(rb"-?\d+(\.\d+)?(e[-+]?\d+)?", original)]
    tokens = st.sampled_from([b"nan", b"inf", b"-inf", b"-1", b"0", b"1e400", b"", b"x", b"1.5", b"99999999999"])

    @st.composite
    def edit(draw, data: bytes) -> bytes:
        kind = draw(st.sampled_from(["number", "bytes", "delete", "repeat"]))
        if kind == "number" and numbers:
            start, stop = draw(st.sampled_from(numbers))
            return data[:start] + draw(tokens) + data[stop:]
        start = draw(st.integers(0, len(data)))
        stop = draw(st.integers(start, min(len(data), start + 64)))
        if kind == "bytes":
            return data[:start] + draw(st.binary(max_size=16)) + data[stop:]
        if kind == "delete":
            return data[:start] + data[stop:]
        lines = data.splitlines(keepends=True)
        index = draw(st.integers(0, max(0, len(lines) - 1)))
        return b"".join(lines[: index + 1] + lines[index:])

    return edit(original)


def _read_mutated(tmp_path: Path, name: str, data: bytes, reader) -> None:
    path = tmp_path / name
    path.write_bytes(data)
    try:
        reader(path)
    except InputError as error:
        one_clean_line(error)


@FUZZ
@given(data=mutations(EXAMPLE_SCENARIO.read_bytes()))
def test_a_mutated_scenario_file_is_read_or_refused_in_one_line(tmp_path, data):
    _read_mutated(tmp_path, "scenario.yaml", data, load_scenario)


@FUZZ
@given(documents(MultiViewDataset))
def test_a_dataset_document_is_a_dataset_or_one_clean_error(document):
    try:
        dataset_from_dict(document, "fuzz")
    except ScenarioError as error:
        one_clean_line(error)


@FUZZ
@given(data=mutations(EXAMPLE_DATASET.read_bytes()))
def test_a_mutated_dataset_file_is_read_or_refused_in_one_line(tmp_path, data):
    _read_mutated(tmp_path, "dataset.yaml", data, load_dataset)


SMALL_DATASET = _dataset(
    "fuzz",
    top="frames: 2\noccupancy: {cell_m: 0.05, kernel_sigma_m: 0.1, separation_m: 0.5, window_m: 0.25, block_px: 4}\n",
    extra=("--quiet", "--methods"),
)
"""One PETS view's calibration, two frames of its detections and ground truth (tests/bad_dataset_inputs.py), and the
parameters whose cost grows with them."""


@settings(FUZZ, max_examples=DATASET_RUN_EXAMPLES)
@given(data=mutations(SMALL_DATASET.files["d.yaml"].encode()))
def test_a_mutated_dataset_file_runs_or_exits_2_with_one_line(tmp_path, capfd, caplog, data):
    """Through the command, in-process: the experiment runs (exit 0), or one line says why not (exit 2)."""
    argv = write_case(SMALL_DATASET, tmp_path)
    (tmp_path / "d.yaml").write_bytes(data)
    capfd.readouterr()
    caplog.clear()
    status = main(argv)
    stderr = capfd.readouterr().err
    assert status in (0, 2) and "Traceback" not in stderr, stderr
    if status == 2:
        warned = [record.getMessage() for record in caplog.records if record.levelno >= logging.WARNING]
        lines = stderr.strip().splitlines() + warned
        assert len(lines) == 1 and len(lines[0]) <= 300 and lines[0].startswith("ptztrack: error: "), lines


DETECTIONS_HEAD = b"".join(gzip.decompress((PETS / "View_003_det.txt.gz").read_bytes()).splitlines(keepends=True)[:30])


@FUZZ
@given(data=mutations(DETECTIONS_HEAD), compressed=st.booleans())
def test_mutated_detections_are_read_or_refused_in_one_line(tmp_path, data, compressed):
    name, content = ("det.txt.gz", gzip.compress(data)) if compressed else ("det.txt", data)
    _read_mutated(tmp_path, name, content, lambda path: load_mot_detections(path, 100_000))


@FUZZ
@given(data=mutations(gzip.compress(DETECTIONS_HEAD)))
def test_a_mutated_gzip_file_is_read_or_refused_in_one_line(tmp_path, data):
    _read_mutated(tmp_path, "det.txt.gz", data, lambda path: load_mot_detections(path, 100_000))


GROUND_TRUTH_HEAD = b"".join((PETS / "gt_mot15.txt").read_bytes().splitlines(keepends=True)[:30])


@FUZZ
@given(data=mutations(GROUND_TRUTH_HEAD))
def test_a_mutated_ground_truth_is_read_or_refused_in_one_line(tmp_path, data):
    _read_mutated(tmp_path, "gt.txt", data, load_mot_ground_truth)


CVML = b"""<?xml version="1.0"?>
<dataset><frame number="0"><objectlist>
<object id="1"><box h="80.5" w="30.25" xc="100.0" yc="200.0"/></object>
<object id="2"><box h="70" w="28" xc="300" yc="220"/></object>
</objectlist></frame><frame number="1"><objectlist>
<object id="1"><box h="81" w="30" xc="102" yc="201"/></object>
</objectlist></frame></dataset>
"""


@FUZZ
@given(data=mutations(CVML))
def test_mutated_cvml_annotations_are_read_or_refused_in_one_line(tmp_path, data):
    _read_mutated(tmp_path, "annotations.xml", data, load_cvml)


@FUZZ
@given(data=mutations((PETS / "View_001.xml").read_bytes()))
def test_a_mutated_tsai_calibration_is_read_or_refused_in_one_line(tmp_path, data):
    _read_mutated(tmp_path, "calibration.xml", data, load_calibration)


@FUZZ
@given(data=mutations((PETS / "pinhole.json").read_bytes()))
def test_a_mutated_pinhole_calibration_is_read_or_refused_in_one_line(tmp_path, data):
    _read_mutated(tmp_path, "calibration.json", data, load_calibration)


CAMERA_CALIBRATION = CameraCalibrationFile(
    pan_deg=(-170.0, 170.0),
    tilt_deg=(-30.0, 90.0),
    zoom_curve=[(0.0, 1.0), (0.4, 3.5), (1.0, 20.0)],
    position_m=(1.5, -2.0, 4.2),
    f_min_px=820.0,
    move_times={"pan": (0.3, 0.012), "tilt": (0.25, 0.015), "zoom": (0.4, 0.2)},
)
"""A real camera's calibration as ``ptztrack camera calibrate`` leaves it: spaces, position, focal
length and measured move times."""


@pytest.fixture(scope="module")
def camera_calibration_files(tmp_path_factory) -> dict[str, bytes]:
    """The calibration written as ``ptztrack camera calibrate`` writes it (YAML), and as JSON (YAML reads it)."""
    path = tmp_path_factory.mktemp("camera") / "camera.yaml"
    write_camera_calibration(path, CAMERA_CALIBRATION)
    return {"yaml": path.read_bytes(), "json": json.dumps(CAMERA_CALIBRATION.model_dump(mode="json")).encode()}


@FUZZ
@given(data=st.data(), kind=st.sampled_from(["yaml", "json"]))
def test_a_mutated_camera_calibration_is_read_or_refused_in_one_line(tmp_path, camera_calibration_files, data, kind):
    """Read, a calibration maps every normalised position to a finite pose and back, and its move times to
    finite speeds (what a live run does with it before it connects)."""

    def read(path):
        calibration = load_camera_calibration(path)
        spaces = camera_spaces(calibration)
        normalised = np.stack(np.meshgrid([-1.0, 0.0, 1.0], [-1.0, 0.5, 1.0], [0.0, 0.3, 1.0]), axis=-1)
        pose = spaces.pose(normalised)
        assert np.all(np.isfinite(pose)) and np.all(np.isfinite(spaces.normalised(pose)))
        speeds = pose_timeline(calibration).speeds
        assert speeds is None or np.all(np.isfinite(speeds) & (speeds > 0))

    _read_mutated(tmp_path, f"camera.{kind}", data.draw(mutations(camera_calibration_files[kind])), read)


def _small_index_bytes(tmp_path: Path) -> bytes:
    rng = np.random.default_rng(0)
    index = ReferenceIndex(
        poses=rng.uniform(-10, 10, (3, 3)),
        keypoints_px=rng.uniform(0, 100, (12, 2)),
        descriptors=rng.random((12, 128)).astype(np.float32),
        view=np.repeat(np.arange(3), 4),
        image_size_px=(160, 120),
    )
    save_index(tmp_path / "index.npz", index)
    return (tmp_path / "index.npz").read_bytes()


@pytest.fixture(scope="module")
def index_bytes(tmp_path_factory):
    return _small_index_bytes(tmp_path_factory.mktemp("index"))


@FUZZ
@given(data=st.data())
def test_a_mutated_registration_index_is_read_or_refused_in_one_line(tmp_path, index_bytes, data):
    _read_mutated(tmp_path, "index.npz", data.draw(mutations(index_bytes)), load_index)


@pytest.fixture(scope="module")
def small_video_bytes():
    return video_bytes(4, (64, 48), None)


@FUZZ
@given(data=st.data())
def test_a_mutated_video_is_read_or_refused_in_one_line(tmp_path, small_video_bytes, data):
    def read(path):
        video = RecordedVideo(path, (64, 48), frames_needed=4)
        for frame in range(4):
            assert video.frame(frame).shape == (48, 64, 3)

    _read_mutated(tmp_path, "video.avi", data.draw(mutations(small_video_bytes)), read)
