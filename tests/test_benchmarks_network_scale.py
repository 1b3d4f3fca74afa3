import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import network_scale  # noqa: E402


def test_a_tiny_run_writes_a_row_per_size(tmp_path, monkeypatch):
    path = tmp_path / "scale.json"
    argv = ["network_scale.py", "--cameras", "1", "2", "--people", "3", "--steps", "1", "--warmup", "1"]
    monkeypatch.setattr(sys, "argv", [*argv, "--no-ray", "--json", str(path)])
    network_scale.main()
    document = json.loads(path.read_text())
    assert document["executor"] == "in-process"
    assert [(row["cameras"], row["people"]) for row in document["rows"]] == [(1, 3), (2, 3)]
    for row in document["rows"]:
        assert {"cameras", "people", "decisions_per_s", "belief_update_ms"} <= set(row)
        assert row["decisions_per_s"] > 0 and row["belief_update_ms"] >= 0


def test_each_camera_stands_beyond_its_cell_facing_the_area_centre():
    scenario = network_scale.grid_scenario(4, 10, 2)
    assert scenario.area_m == (30.0, 30.0)
    positions = [camera.position_m for camera in scenario.cameras]
    # The cell at (7.5, 7.5): its camera 13.5 m further from the area's centre (15, 15), on the diagonal.
    assert positions[0] == pytest.approx((7.5 - 13.5 / 2**0.5, 7.5 - 13.5 / 2**0.5, 2.5))
    assert network_scale.grid_scenario(1, 10, 2).cameras[0].position_m == pytest.approx((7.5, -6.0, 2.5))
