"""``ptztrack render``: a scenario file in, a dataset folder out; bad input is one line and status 2."""

import pytest
import yaml

from ptztrack.cli import main
from ptztrack.config import load_dataset

SCENARIO = """
area_m: [10.0, 8.0]
frames: 4
frame_rate_hz: 12.5
people: {count: 2}
camera: {position_m: [5.0, -2.0, 4.0], image_size_px: [320, 180], f_min_px: 200.0}
"""


def test_render_writes_the_dataset_folder_and_says_where(tmp_path, capsys):
    scenario = tmp_path / "scenario.yaml"
    scenario.write_text(SCENARIO)
    assert main(["render", "--scenario", str(scenario), "--out", str(tmp_path / "out"), "--seed", "2"]) == 0
    printed = capsys.readouterr()
    assert printed.out == f"wrote {tmp_path / 'out' / 'dataset.yaml'}: 1 view, 4 frames at 12.5 Hz\n"
    assert printed.err == ""  # no progress bar where stderr is not a terminal
    assert load_dataset(tmp_path / "out" / "dataset.yaml").views[0].video == str(tmp_path / "out" / "camera_1.avi")


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        (None, "no such scenario file"),
        ("area_m: [10, 8\n", "not valid YAML"),
        ("frames: -1\n", "frames"),
        ("camera: {position_m: [5, -2, 0]}\n", "camera.position_m"),
    ],
)
def test_a_bad_scenario_exits_2_with_one_line(tmp_path, capsys, text, expected):
    scenario = tmp_path / "scenario.yaml"
    if text is not None:
        scenario.write_text(text)
    assert main(["render", "--scenario", str(scenario), "--out", str(tmp_path / "out")]) == 2
    error = capsys.readouterr().err
    assert error.startswith("ptztrack: error: ") and error.count("\n") == 1 and expected in error
    assert not (tmp_path / "out").exists()


def test_a_scenario_with_a_recording_exits_2(tmp_path, capsys, excerpt_scenario):
    excerpt_scenario(tmp_path)  # writes pets.yaml into tmp_path
    assert main(["render", "--scenario", str(tmp_path / "pets.yaml"), "--out", str(tmp_path / "out")]) == 2
    assert "render takes a scenario without one" in capsys.readouterr().err


def test_a_folder_that_is_not_empty_exits_2_untouched_unless_overwritten(tmp_path, capsys):
    scenario = tmp_path / "scenario.yaml"
    scenario.write_text(SCENARIO)
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    assert main(["render", "--scenario", str(scenario), "--out", str(out)]) == 2
    assert "--out" in capsys.readouterr().err and [path.name for path in out.iterdir()] == ["keep.txt"]
    assert main(["render", "--scenario", str(scenario), "--out", str(out), "--overwrite"]) == 0
    assert yaml.safe_load((out / "dataset.yaml").read_text())["views"][0]["name"] == "camera_1"
    assert not (out / "keep.txt").exists()
