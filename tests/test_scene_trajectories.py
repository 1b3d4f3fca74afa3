"""Recorded trajectories replayed as the synthetic crowd (ptztrack.scene.trajectories, people.trajectories)."""

import logging
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bad_input_files import Case
from bad_inputs import write_case
from ptztrack.builders.episode import run_episode
from ptztrack.builders.network import network_world
from ptztrack.builders.world import build_scene
from ptztrack.cli import main
from ptztrack.config import ScenarioError, load_scenario, scenario_from_dict
from ptztrack.evaluate.metrics import episode_metrics
from ptztrack.experiments.cells import cell_metrics
from ptztrack.experiments.ptz_tables import synthetic_cells
from ptztrack.files import InputError
from ptztrack.loop.executors import execute_cells
from ptztrack.scene.pets import DatasetError, load_mot_ground_truth
from ptztrack.scene.trajectories import (
    MAX_GAP_S,
    Trajectories,
    centring_offset_m,
    read_trajectories,
    replay_truth,
    trajectories_outside_area,
    trajectories_too_fast,
)

PETS_TRUTH = Path(str(resources.files("ptztrack.data") / "pets2009_s2l1" / "gt_mot15.txt"))

# Two people, ETH/UCY style (frame numbers stepping by 10, tab-separated, frames and ids written as floats):
# person 1 at 0, 1 and 2 s at 10 frames per second; person 2 at 0.5 s and again at 4 s, a gap longer
# than MAX_GAP_S.
TWO_PEOPLE = "0.0\t1.0\t0.0\t0.0\n10.0\t1.0\t1.0\t2.0\n5.0\t2.0\t4.0\t4.0\n20.0\t1.0\t3.0\t2.0\n40.0\t2.0\t6.0\t4.0\n"


def test_the_replay_interpolates_each_person_between_their_samples_and_not_across_long_gaps(tmp_path):
    path = tmp_path / "two.txt"
    path.write_text(TWO_PEOPLE)
    trajectories = read_trajectories(path, 10.0)
    assert list(trajectories.people) == [1, 2] and list(trajectories.line) == [1, 2, 3, 4, 5]
    assert MAX_GAP_S < 3.5
    truth = replay_truth(trajectories, 10, 4.0, [1.7, 1.8], 0.5, (10.0, 20.0))
    expected = np.full((10, 2, 2), np.nan)
    # Steps at 0, 0.25, ..., 2.25 s; person 1 walks (0, 0) -> (1, 2) -> (3, 2) over 0, 1 and 2 s.
    expected[:9, 0] = [(0, 0), (0.25, 0.5), (0.5, 1), (0.75, 1.5), (1, 2), (1.5, 2), (2, 2), (2.5, 2), (3, 2)]
    expected[2, 1] = (4, 4)  # person 2 at 0.5 s; from there to 4 s is a gap of 3.5 s: absent
    np.testing.assert_allclose(truth.positions_m, expected + (10.0, 20.0))
    assert truth.frame_rate_hz == 4.0 and list(truth.heights_m) == [1.7, 1.8] and list(truth.widths_m) == [0.5, 0.5]
    # Frames from 1, comma-separated: the same people, the same times.
    ones = tmp_path / "ones.txt"
    ones.write_text(
        "".join(f"{int(float(f)) + 1},{i},{x},{y}\n" for f, i, x, y in map(str.split, TWO_PEOPLE.splitlines()))
    )
    again = replay_truth(read_trajectories(ones, 10.0), 10, 4.0, [1.7, 1.8], 0.5, (10.0, 20.0))
    np.testing.assert_array_equal(again.positions_m, truth.positions_m)


def test_only_the_people_present_during_the_steps_are_kept_with_their_own_heights(tmp_path):
    path = tmp_path / "late.txt"
    path.write_text(TWO_PEOPLE + "100 3 1 1\n110 3 2 1\n")
    truth = replay_truth(read_trajectories(path, 10.0), 4, 2.0, [1.6, 1.7, 1.8], 0.5, (0.0, 0.0))
    assert truth.positions_m.shape == (4, 2, 2) and list(truth.heights_m) == [1.6, 1.7]
    late = replay_truth(read_trajectories(path, 10.0), 30, 2.0, [1.6, 1.7, 1.8], 0.5, (0.0, 0.0))
    assert list(late.heights_m) == [1.6, 1.7, 1.8] and np.array_equal(late.positions_m[20, 2], (1.0, 1.0))


@st.composite
def one_person(draw):
    """A person's samples: increasing frames at most a gap's worth apart, positions in metres."""
    rate_hz = draw(st.sampled_from([2.5, 5.0, 7.0, 10.0, 25.0]))
    # Gaps of at most 0.9 MAX_GAP_S: at MAX_GAP_S itself, rounding decides.
    steps = draw(st.lists(st.integers(1, int(0.9 * rate_hz * MAX_GAP_S)), min_size=1, max_size=20))
    frame = np.cumsum([draw(st.integers(0, 5)), *steps])
    position_m = np.asarray(
        draw(st.lists(st.tuples(*[st.floats(-500, 500)] * 2), min_size=len(frame), max_size=len(frame)))
    )
    return rate_hz, frame, position_m


@settings(max_examples=60, deadline=None)
@given(person=one_person(), offset_m=st.tuples(st.floats(-100, 100), st.floats(-100, 100)))
def test_a_replay_at_the_files_own_rate_gives_its_samples_exactly_and_lies_between_them(person, offset_m):
    rate_hz, frame, position_m = person
    trajectories = Trajectories(Path("p.txt"), frame, np.ones(len(frame), int), position_m, frame + 1, rate_hz)
    truth = replay_truth(trajectories, int(frame[-1]) + 1, rate_hz, [1.7], 0.5, offset_m)
    assert np.array_equal(truth.positions_m[frame, 0], position_m + np.asarray(offset_m))
    assert not truth.present[: frame[0], 0].any() and truth.present[frame[0] :, 0].all()
    low, high = position_m.min(axis=0) + offset_m, position_m.max(axis=0) + offset_m
    between = truth.positions_m[frame[0] :, 0]
    assert np.all((between >= low - 1e-9 * (1 + np.abs(low))) & (between <= high + 1e-9 * (1 + np.abs(high))))


def test_pets_ground_truth_at_its_own_frames_is_its_annotated_positions():
    trajectories = read_trajectories(PETS_TRUTH, 10.0)
    annotations = load_mot_ground_truth(PETS_TRUTH)
    offset_m = centring_offset_m(trajectories, (30.0, 27.0))
    assert trajectories_outside_area(trajectories, offset_m, (30.0, 27.0)) is None
    assert trajectories_too_fast(trajectories) is None
    truth = replay_truth(trajectories, 20, 5.0, np.full(len(trajectories.people), 1.7), 0.5, offset_m)
    for step in (0, 7, 19):
        annotated = annotations.select(annotations.frame == 2 * step)
        replayed = truth.positions_m[step][truth.present[step]]
        assert len(replayed) == len(annotated.frame)
        np.testing.assert_array_equal(np.sort(replayed, axis=0), np.sort(annotated.ground_m + offset_m, axis=0))


def pets_crowd(**people) -> dict:
    """A synthetic scenario whose crowd is PETS 2009 S2.L1's annotated people."""
    return {"area_m": [30, 27], "people": {"trajectories": str(PETS_TRUTH), "trajectories_frame_rate_hz": 10, **people}}


def test_pets_annotated_people_are_the_synthetic_scenes_crowd_in_an_episode():
    scenario = scenario_from_dict({**pets_crowd(), "frames": 20})
    metrics = episode_metrics(run_episode(scenario, "fix", 0))
    assert metrics["objects"] > 20 and metrics["matches"] > 0


def test_the_synthetic_experiment_runs_on_a_file_of_frame_id_x_y(tmp_path):
    path = tmp_path / "walk.txt"
    samples = [f"{10 * k} {person} {2 + k * 0.4 + person} {3 + 2 * person}" for k in range(30) for person in range(4)]
    path.write_text("\n".join(samples) + "\n")
    scenario = scenario_from_dict(
        {"frames": 8, "people": {"trajectories": str(path), "trajectories_frame_rate_hz": 25}}
    )
    rows = execute_cells(synthetic_cells(scenario, sequences=2, strategies=("fix", "smpl")), cell_metrics, "serial")
    assert [row["strategy"] for row in rows] == ["fix", "fix", "smpl", "smpl"]
    assert all(row["objects"] == 4 * 8 for row in rows)
    first, second = (build_scene(scenario, np.random.default_rng(seed)).truth for seed in (0, 1))
    assert np.array_equal(first.positions_m, second.positions_m) and not np.array_equal(
        first.heights_m, second.heights_m
    )


def test_a_camera_network_replays_the_same_people():
    network = scenario_from_dict(
        {**pets_crowd(), "frames": 5, "cameras": [{"position_m": [15, -6, 4]}, {"position_m": [-6, 13, 4]}]}
    )
    world = network_world(network, 0)
    alone = build_scene(network.model_copy(update={"cameras": ()}), np.random.default_rng(0)).truth
    for camera in world.cameras:
        np.testing.assert_array_equal(camera.truth.positions_m, alone.positions_m)


def test_a_scenario_file_names_its_trajectories_relative_to_itself(tmp_path):
    (tmp_path / "people").mkdir()
    (tmp_path / "people" / "two.txt").write_text(TWO_PEOPLE)
    path = tmp_path / "s.yaml"
    path.write_text(
        "people: {trajectories: people/two.txt, trajectories_frame_rate_hz: 10, trajectories_offset_m: [5, 5]}\n"
    )
    scenario = load_scenario(path)
    assert Path(scenario.people.trajectories) == tmp_path / "people" / "two.txt"
    truth = build_scene(scenario, np.random.default_rng(0)).truth
    np.testing.assert_array_equal(truth.positions_m[0, 0], (5.0, 5.0))


@pytest.mark.parametrize(
    "people, expected",
    [
        ({"trajectories": "t.txt"}, "people: trajectories_frame_rate_hz is required with trajectories"),
        ({"trajectories_frame_rate_hz": 10}, "people: trajectories_frame_rate_hz is set but trajectories"),
        (
            {"trajectories": "t.txt", "trajectories_frame_rate_hz": 0},
            "people.trajectories_frame_rate_hz: Input should be greater than 0",
        ),
    ],
)
def test_a_scenario_refuses_trajectories_without_their_rate(people, expected):
    with pytest.raises(ScenarioError, match=expected):
        scenario_from_dict({"people": people}, "s.yaml")


def test_a_recording_and_trajectories_are_refused_together():
    recording = {"ground_truth": str(PETS_TRUTH), "calibration": "c.json"}
    with pytest.raises(ScenarioError, match=r"s.yaml: \(top level\): people.trajectories replays a file .*got both"):
        scenario_from_dict({**pets_crowd(), "recording": recording}, "s.yaml")


def _trajectories_case(
    name: str, rows: str | None, *people: str, exit_status: int = 2, says: tuple[str, ...] = ()
) -> Case:
    """A scenario replaying the file t.txt of ``rows`` at 10 Hz (``people``: more fields of its people), for 2 steps."""
    fields = ", ".join(["trajectories: t.txt", "trajectories_frame_rate_hz: 10", *people])
    scenario = f"people: {{{fields}}}\n"
    return Case(
        name,
        ("run", "--scenario", "{dir}/s.yaml", "--frames", "2"),
        {"s.yaml": scenario, "t.txt": rows},
        exit_status,
        says,
    )


FOUR_ROWS = "1 1 2.0 3.0\n1 2 4.0 3.0\n2 1 2.1 3.0\n2 2 4.1 3.0\n"
CASES = [
    _trajectories_case("a good file", FOUR_ROWS, exit_status=0),
    _trajectories_case("no such file", None, says=("{dir}/t.txt: no such trajectory file",)),
    _trajectories_case("an empty file", "\n", says=("{dir}/t.txt: no trajectory rows",)),
    _trajectories_case(
        "a person twice in a frame",
        FOUR_ROWS + "2 1 2.2 3.0\n",
        says=("{dir}/t.txt: line 5: person 1 is annotated 2 times in frame 2, expected once",),
    ),
    _trajectories_case(
        "a NaN position",
        FOUR_ROWS.replace("2.1", "nan"),
        says=("{dir}/t.txt: line 3 has a NaN or infinite field",),
    ),
    _trajectories_case(
        "a pixel-like coordinate", FOUR_ROWS.replace("4.1", "1e6"), says=("{dir}/t.txt: line 4: position (1e+06, 3)",)
    ),
    _trajectories_case(
        "a fractional frame",
        FOUR_ROWS.replace("2 2 4.1", "2.5 2 4.1"),
        says=("{dir}/t.txt: line 4: frame and id must be whole",),
    ),
    _trajectories_case(
        "five fields", FOUR_ROWS + "3 1 2.2 3.0 0\n", says=("{dir}/t.txt: line 5 has 5 fields, expected 4",)
    ),
    _trajectories_case(
        "none inside the area",
        FOUR_ROWS,
        "trajectories_offset_m: [1000, 1000]",
        says=("{dir}/t.txt: none of its 4 positions lies in area_m [0, 15] x [0, 15] once moved by (1000, 1000) m",),
    ),
    _trajectories_case(
        "some outside the area",
        FOUR_ROWS,
        "trajectories_offset_m: [13, 0]",
        exit_status=0,
        says=("{dir}/t.txt: 2 of 4 positions lie more than 1 m outside area_m", "line 2: (4, 3)"),
    ),
    _trajectories_case(
        "centimetres",
        FOUR_ROWS.replace("2.1", "12.0").replace("4.1", "14.0"),
        exit_status=0,
        says=("{dir}/t.txt: its people move a median 100 m/s", "are the positions metres"),
    ),
]


def refusal_and_warnings(case: Case, directory: Path, caplog) -> tuple[str | None, list[str]]:
    """The case's scenario file loaded and its scene built: the error's line (None if built) and the
    warnings logged."""
    write_case(case, directory)
    caplog.clear()
    try:
        build_scene(load_scenario(directory / "s.yaml", frames=2), np.random.default_rng(0))
        refusal = None
    except InputError as error:
        refusal = str(error)
    return refusal, [record.getMessage() for record in caplog.records if record.levelno >= logging.WARNING]


@pytest.mark.parametrize("name", [case.name for case in CASES])
def test_a_bad_trajectory_file_gets_one_line_naming_it(name, tmp_path, caplog):
    case = next(case for case in CASES if case.name == name)
    refusal, warnings = refusal_and_warnings(case, tmp_path, caplog)
    lines = warnings if refusal is None else [refusal, *warnings]
    assert (refusal is not None) == (case.exit_status == 2), lines
    assert len(lines) == len(case.says[:1]), lines
    said = "\n".join(lines)
    assert "\n" not in said and all(part.replace("{dir}", str(tmp_path)) in said for part in case.says), lines


def test_the_command_refuses_a_bad_trajectory_file_in_one_line(tmp_path, capfd):
    case = next(case for case in CASES if case.name == "a person twice in a frame")
    assert main(write_case(case, tmp_path)) == 2
    assert capfd.readouterr().err.splitlines() == [
        f"ptztrack: error: {tmp_path / 't.txt'}: line 5: person 1 is annotated 2 times in frame 2, expected once"
    ]


def test_positions_far_outside_are_refused_in_a_call_too(tmp_path):
    path = tmp_path / "mm.txt"
    path.write_text("0 1 2000 3000\n1 1 2100 3000\n0 2 40000 3000\n")
    with pytest.raises(DatasetError, match=r"mm.txt: line 3: position \(40000, 3000\) lies 3.79e\+04 m from"):
        read_trajectories(path, 10.0)
