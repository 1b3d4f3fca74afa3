"""A camera's normalised ONVIF spaces against the model's poses, its move times, and where its
credentials come from."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from ptztrack.camera.onvif_client import CameraError, camera_address
from ptztrack.camera.onvif_spaces import CameraSpaces, MoveTimes

SPACES = CameraSpaces(pan_deg=(170.0, -170.0), tilt_deg=(-10.0, 80.0), zoom_curve=((0.0, 1.0), (0.3, 2.0), (1.0, 20.0)))


@given(st.floats(-1, 1), st.floats(-1, 1), st.floats(0, 1))
def test_normalised_positions_go_to_poses_and_back(x, y, zoom):
    position = np.array([x, y, zoom])
    np.testing.assert_allclose(SPACES.normalised(SPACES.pose(position)), position, atol=1e-9)


def test_the_ends_of_the_spaces_are_the_calibrated_degrees_and_zoom_follows_its_curve():
    np.testing.assert_allclose(
        SPACES.pose([[-1, -1, 0], [1, 1, 1], [0, 0, 0.3]]), [[170, -10, 1], [-170, 80, 20], [0, 35, 2]]
    )
    np.testing.assert_allclose(SPACES.pose([0, 0, 0.15])[2], 1.5)  # halfway between two points of the curve
    np.testing.assert_allclose(SPACES.normalised([200.0, -90.0, 1.0]), [-1.0, -1.0, 0.0])  # beyond the ends: clipped


def test_a_move_takes_as_long_as_its_slowest_axis():
    times = MoveTimes(pan=(0.2, 0.01), tilt=(0.3, 0.02), zoom=(0.1, 0.5))
    assert times.seconds([0, 0, 1], [30, 5, 1]) == pytest.approx(max(0.2 + 0.3, 0.3 + 0.1))
    assert times.seconds([0, 0, 1], [0, 0, 3]) == pytest.approx(1.1)
    assert times.seconds([1, 2, 3], [1, 2, 3]) == 0.0
    np.testing.assert_allclose(times.seconds([0, 0, 1], [[30, 5, 1], [0, 0, 3], [0, 0, 1]]), [0.5, 1.1, 0.0])


def test_credentials_come_from_the_url_then_the_file_then_the_environment():
    environ = {"PTZTRACK_CAMERA_USER": "env-user", "PTZTRACK_CAMERA_PASSWORD": "env-pass"}
    from_url = camera_address("onvif://admin:p%40ss@10.0.0.5:8000", {"username": "f", "password": "g"}, environ)
    assert (from_url.host, from_url.port, from_url.username, from_url.password) == ("10.0.0.5", 8000, "admin", "p@ss")
    from_file = camera_address("camera.local", {"username": "file-user", "password": "file-pass"}, environ)
    assert (from_file.port, from_file.username, from_file.password) == (80, "file-user", "file-pass")
    from_environment = camera_address("onvif://camera.local:81", None, environ)
    assert (from_environment.username, from_environment.password) == ("env-user", "env-pass")
    assert "env-pass" not in repr(from_environment) and "env-pass" not in str(from_environment)


def test_a_bad_camera_url_is_one_line_without_the_password():
    with pytest.raises(CameraError, match="expected onvif://") as error:
        camera_address("rtsp://admin:secret@camera.local/stream")
    assert "secret" not in str(error.value)
    for url in ("http://admin:secret@camera.local", "https://camera.local:443"):  # a web address is not ONVIF's
        with pytest.raises(CameraError, match="expected onvif://"):
            camera_address(url)
    for port in ("99999", "0", "x"):
        with pytest.raises(CameraError, match="the port is not a number from 1 to 65535"):
            camera_address(f"onvif://camera.local:{port}")
