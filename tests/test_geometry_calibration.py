"""Pinhole calibrations made, not read: a camera aimed at a point, its centre, its JSON."""

import numpy as np
import pytest

from ptztrack.files import write_json
from ptztrack.geometry.calibration import (
    aimed_pinhole,
    camera_centre_m,
    load_pinhole,
    pinhole_document,
    project_pinhole,
)


@pytest.mark.parametrize(
    ("centre_m", "target_m"),
    [
        ((12.5, 0.0, 6.0), (12.5, 9.0)),  # the side camera of examples/render_side_camera.yaml
        ((-3.0, 40.0, 2.0), (10.0, 5.0)),
        ((0.1, 0.1, 2.8), (2.5, 3.0, 0.9)),  # the room's corner camera, aimed above the floor
        ((4.0, 5.0, 10.0), (4.0, 5.0)),  # straight down
    ],
)
def test_an_aimed_camera_sees_its_target_at_the_image_centre_level_and_from_where_it_stands(centre_m, target_m):
    camera = aimed_pinhole(centre_m, target_m, 400.0, (960, 540))
    target = np.append(target_m, 0.0)[:3] if len(target_m) == 2 else np.asarray(target_m)
    assert project_pinhole(camera, 1000.0 * target[None])[0] == pytest.approx([480.0, 270.0], abs=1e-6)
    assert camera.R @ camera.R.T == pytest.approx(np.eye(3), abs=1e-12)
    assert np.linalg.det(camera.R) == pytest.approx(1.0)
    assert camera.R[0, 2] == pytest.approx(0.0, abs=1e-12)  # no roll: the image's x axis is level
    assert camera_centre_m(camera) == pytest.approx(centre_m)
    assert camera.K == pytest.approx(np.array([[400.0, 0, 480], [0, 400, 270], [0, 0, 1]]))
    assert not camera.dist.any()
    # Up in the world is up in the image (for a camera that is not looking straight down).
    if not np.allclose(centre_m[:2], target[:2]):
        above = project_pinhole(camera, 1000.0 * (target + [0.0, 0.0, 1.0])[None])
        assert above[0, 1] < 270.0 and above[0, 0] == pytest.approx(480.0, abs=1e-6)


def test_a_camera_cannot_look_at_itself():
    with pytest.raises(ValueError, match="its own centre"):
        aimed_pinhole((1.0, 2.0, 3.0), (1.0, 2.0, 3.0), 400.0, (640, 480))


def test_a_calibration_written_as_json_reads_back(tmp_path):
    camera = aimed_pinhole((12.5, 0.0, 6.0), (12.5, 9.0), 400.0, (960, 540))
    write_json(tmp_path / "calibration.json", {"side": pinhole_document(camera)})
    read = load_pinhole(tmp_path / "calibration.json", "side")
    for name in ("K", "dist", "R", "t"):
        assert getattr(read, name) == pytest.approx(getattr(camera, name), abs=1e-12)
