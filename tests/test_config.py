from pathlib import Path

import pytest

from ptztrack.builders.recording import pets_scenario
from ptztrack.builders.world import action_grid
from ptztrack.config import Scenario, ScenarioError, load_scenario, scenario_from_dict

EXAMPLE = Path(__file__).parent.parent / "examples" / "scenario.yaml"


def test_the_documented_example_is_valid_and_states_the_defaults():
    assert load_scenario(EXAMPLE) == Scenario()


def test_the_default_grid_is_the_papers_280_actions():
    grid = action_grid(Scenario())
    assert grid.shape == (7, 10, 4)
    assert grid.size == 280
    assert grid.max_steps == (2, 2, 1)


@pytest.mark.parametrize(
    "text, expected",
    [
        ("area_m: [15, 15]\nwalls: 3\n", "walls: unknown key (got 3)"),
        ("area_m: [-15, 15]\n", "area_m.0: Input should be greater than 0 (got -15)"),
        ("frames: many\n", "frames: Input should be a valid integer"),
        ("people: {count: -1}\n", "people.count: Input should be greater than or equal to 0 (got -1)"),
        (
            "detector: {kind: perfect}\n",
            "detector.kind: expected one of ideal, realistic, hog, detections (got 'perfect')",
        ),
        ("people: {speed_m_s: [2.0, 1.0]}\n", "people: speed_m_s must be [low, high]"),
        ("actions: {zoom: [2, 1]}\n", "actions: zoom must be a non-empty increasing list"),
        ("camera: {live_view: {gain: [1.3, 0.7]}}\n", "camera.live_view: gain must be [low, high]"),
        ("camera: {live_view: {jpeg_quality: 0}}\n", "camera.live_view.jpeg_quality: Input should be greater than"),
        ("- 1\n- 2\n", "expected a mapping of scenario fields (got list)"),
        ("area_m: [1, 2\n", "not valid YAML at line"),
        ('{"frames": 5, [1, 2]: 3}\n', "not valid YAML at line 1"),
        ("cameras: [{kind: pan, position_m: [0, 0, 3]}]\n", "cameras.0.kind: Input should be 'ptz' or 'fixed'"),
        ("cameras: [{kind: ptz}]\n", "cameras.0.position_m: Field required"),
        ("cameras: [{position_m: [0, 0, -3]}]\n", "cameras.0.position_m.2: Input should be greater than 0 (got -3)"),
        ("cameras: [{position_m: [0, 0, 3], detector: {kind: x}}]\n", "cameras.0.detector.kind: expected one of"),
        (
            "cameras: [{position_m: [0, 0, 3]}]\ntracker: {kind: particle}\n",
            "cameras: a network's one belief is the 'ekf' tracker measured by the detector (got tracker.kind",
        ),
    ],
)
def test_bad_scenarios_get_one_line_naming_the_file_field_and_value(tmp_path, text, expected):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(ScenarioError) as error:
        load_scenario(path)
    message = str(error.value)
    assert "\n" not in message
    assert message.startswith(str(path))
    assert expected in message


def test_a_missing_file_is_named(tmp_path):
    with pytest.raises(ScenarioError, match="nope.yaml: no such scenario file"):
        load_scenario(tmp_path / "nope.yaml")


def test_overrides_apply_on_top_of_the_file(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text("frames: 20\ndetector: {pixel_noise_px: 1.0}\n")
    scenario = load_scenario(path, **{"detector.kind": "ideal", "frames": 10})
    assert scenario.frames == 10
    assert scenario.detector.kind == "ideal"
    assert scenario.detector.pixel_noise_px == 1.0


def test_an_unknown_association_is_refused_naming_the_field():
    with pytest.raises(ScenarioError) as error:
        scenario_from_dict({"tracker": {"association": "jpda"}})
    assert "tracker.association: Input should be 'hungarian' or 'cjpdaf' (got 'jpda')" in str(error.value)
    with pytest.raises(ScenarioError, match="tracker.clutter_density_per_px2: Input should be greater than or equal"):
        scenario_from_dict({"tracker": {"clutter_density_per_px2": -1e-6}})


def test_the_long_run_tracker_options_are_read_and_student_t_noise_is_refused_for_the_cjpdaf():
    tracker = load_scenario(EXAMPLE.parent / "long_run.yaml").tracker
    assert (tracker.noise_dof, tracker.negative_information, tracker.keep_within_area) == (4.0, True, True)
    assert (tracker.association_cost, tracker.lost_tracks_kept, tracker.velocity_time_constant_s) == (
        "likelihood",
        20,
        5,
    )
    assert scenario_from_dict({}).tracker.noise_dof == float("inf")
    with pytest.raises(ScenarioError, match="tracker: association cjpdaf assumes Gaussian pixel noise"):
        scenario_from_dict({"tracker": {"association": "cjpdaf", "noise_dof": 4}})
    with pytest.raises(ScenarioError, match="tracker.noise_dof: Input should be greater than 2"):
        scenario_from_dict({"tracker": {"noise_dof": 2}})


def test_hog_needs_a_recording_with_video():
    with pytest.raises(ScenarioError, match="'hog' needs a recording with a video"):
        scenario_from_dict({"detector": {"kind": "hog"}})


def test_the_scenario_chooses_the_search_and_refuses_a_falling_height_range():
    scenario = pets_scenario("hog")
    assert scenario.detector.hog_search == "ground" and scenario.detector.hog_person_height_m == (1.5, 2.0)
    with pytest.raises(ScenarioError, match="hog_person_height_m must be"):
        pets_scenario("hog", **{"detector.hog_person_height_m": (2.0, 1.5)})
    with pytest.raises(ScenarioError, match="hog_search"):
        pets_scenario("hog", **{"detector.hog_search": "sky"})


def test_a_camera_network_needs_the_synthetic_scene_and_runs_as_a_network(excerpt_scenario, tmp_path):
    from ptztrack.builders.episode import run_episode

    with pytest.raises(ScenarioError, match="cameras: a network of cameras runs on the synthetic scene"):
        excerpt_scenario(tmp_path, cameras=[{"position_m": (0.0, 0.0, 3.0)}])
    network = scenario_from_dict({"cameras": [{"position_m": (0.0, 0.0, 3.0)}]})
    with pytest.raises(ScenarioError, match="a camera network decides by intg or smpl, not 'fix'"):
        run_episode(network, "fix", 0)
