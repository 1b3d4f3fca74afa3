import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import any_recording  # noqa: E402

pytestmark = pytest.mark.slow


@pytest.mark.parametrize("seed", range(20))
def test_the_drawn_geometries_are_cameras_on_an_edge_looking_in(seed):
    geometry = any_recording.random_geometry(np.random.default_rng(seed), 12.0)
    (width_m, depth_m), (x_m, y_m, height_m) = geometry["area_m"], geometry["camera"]["position_m"]
    on_an_edge = np.isclose([x_m, x_m - width_m, y_m, y_m - depth_m], 0.0).any()
    assert on_an_edge and 0 <= x_m <= width_m and 0 <= y_m <= depth_m and 3 <= height_m <= 10
    assert tuple(geometry["camera"]["image_size_px"]) in any_recording.IMAGE_SIZES_PX
    assert geometry["frames"] == round(12.0 * geometry["frame_rate_hz"])


def test_a_short_random_recording_runs_the_table_and_writes_its_rows_and_geometry(tmp_path, monkeypatch):
    path = tmp_path / "any.json"
    monkeypatch.setattr(sys, "argv", ["any_recording.py", "--seed", "3", "--seconds", "3", "--json", str(path)])
    assert any_recording.main() == 0
    document = json.loads(path.read_text())
    assert [row["strategy"] for row in document["rows"]] == ["fix", "intg", "smpl"]
    assert all(-10.0 <= row["mota"] <= 1.0 for row in document["rows"])
    recording = document["recording"]
    assert {"image_size_px", "frame_rate_hz", "camera_position_m"} <= set(recording)
    assert recording["steps"] >= 1 and recording["step_rate_hz"] > 0
