"""Where the camera lands and the reference views' poses."""

import numpy as np
import pytest

from ptztrack.camera import pose_feedback
from ptztrack.camera.parameters import LandingErrorParameters


def test_a_perfect_camera_lands_exactly_where_it_is_sent():
    commanded = np.array([12.5, 20.0, 3.0])
    landed = pose_feedback.landed_pose(commanded, LandingErrorParameters(), np.random.default_rng(0))
    np.testing.assert_array_equal(landed, commanded)


def test_bias_and_noise_of_the_landing_pose_have_the_configured_size():
    error = LandingErrorParameters(
        pan_tilt_sigma_deg=2.0, pan_tilt_bias_deg=(1.0, -0.5), zoom_sigma=0.03, zoom_bias=1.1
    )
    rng = np.random.default_rng(1)
    commanded = np.array([10.0, 20.0, 2.0])
    landed = np.array([pose_feedback.landed_pose(commanded, error, rng) for _ in range(20000)])
    offset = landed - commanded
    np.testing.assert_allclose(offset[:, :2].mean(axis=0), [1.0, -0.5], atol=0.05)
    np.testing.assert_allclose(offset[:, :2].std(axis=0), [2.0, 2.0], rtol=0.03)
    relative_zoom = landed[:, 2] / (commanded[2] * 1.1)
    assert relative_zoom.mean() == pytest.approx(1.0, abs=1e-3)
    assert relative_zoom.std() == pytest.approx(0.03, rel=0.03)


def test_reference_poses_cover_the_grid_with_the_calibrated_view_first():
    poses = pose_feedback.reference_poses(np.array([50.0, 15.0, 1.0]), (-10.0, 10.0), (-5.0, 5.0), 3, 3, (1.0, 2.0))
    np.testing.assert_array_equal(poses[0], [50.0, 15.0, 1.0])
    # The grid's centre at zoom 1 is the calibrated view itself: listed once.
    assert len(poses) == 2 * 3 * 3
    assert len(np.unique(poses, axis=0)) == len(poses)
    np.testing.assert_allclose([poses[:, 0].min(), poses[:, 0].max()], [40.0, 60.0])
    np.testing.assert_allclose([poses[:, 1].min(), poses[:, 1].max()], [11.0, 19.0])
    assert set(poses[:, 2]) == {1.0, 2.0}
