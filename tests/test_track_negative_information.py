import numpy as np
import pytest
from scipy.stats import truncnorm

from ptztrack.geometry.ptz import PTZCamera, apply_homography, ground_to_image, inside_image, look_at
from ptztrack.track.negative_information import after_miss, moment_matched, position_points, within_area

CAMERA = PTZCamera((7.5, -4.0, 7.0), 640, 480, 400.0)
AREA_M = np.array([[0.0, 0.0], [15.0, 0.0], [15.0, 15.0], [0.0, 15.0]])


def track(mean, position_sd_m, speed_sd_m_s=0.5, position_velocity_correlation=0.0):
    """One track (1, 4), (1, 4, 4): independent axes, each position correlated with its own velocity."""
    position_sd_m = np.asarray(position_sd_m, dtype=float)
    cross = position_velocity_correlation * position_sd_m * speed_sd_m_s
    covariance = np.zeros((4, 4))
    covariance[:2, :2] = np.diag(np.square(position_sd_m))
    covariance[2:, 2:] = speed_sd_m_s**2 * np.eye(2)
    covariance[0, 2] = covariance[2, 0] = cross[0]
    covariance[1, 3] = covariance[3, 1] = cross[1]
    return np.asarray(mean, dtype=float)[None], covariance[None]


def test_a_half_plane_cut_gives_the_truncated_normals_moments_and_moves_the_velocity_by_the_regression():
    """Weights 1 where x > m_x: x's posterior is a normal truncated at its mean (scipy's truncnorm), y is
    untouched, and x's velocity moves by Cov(v, x) / Var(x) times x's shift."""
    mean, covariance = track([4.0, 7.0, 1.0, 0.0], [0.8, 0.5], 0.6, 0.7)
    points = position_points(mean, covariance)
    weights = (points[..., 0] > 4.0).astype(float)
    after_mean, after_covariance = moment_matched(mean, covariance, points, weights)
    half = truncnorm(0.0, np.inf, loc=4.0, scale=0.8)
    assert after_mean[0, 0] == pytest.approx(half.mean(), abs=0.01)
    assert after_covariance[0, 0, 0] == pytest.approx(half.var(), rel=0.03)
    assert after_mean[0, 1] == pytest.approx(7.0, abs=0.01)
    assert after_covariance[0, 1, 1] == pytest.approx(0.25, rel=0.03)
    regression = 0.7 * 0.8 * 0.6 / 0.8**2
    assert after_mean[0, 2] - 1.0 == pytest.approx(regression * (after_mean[0, 0] - 4.0), rel=1e-6)
    assert np.all(np.linalg.eigvalsh(after_covariance[0]) > 0)


def test_a_track_inside_the_area_is_left_exactly_as_it_was_and_one_on_its_edge_is_moved_in():
    inside = track([7.0, 7.0, 0.0, 0.0], [0.3, 0.3])
    mean, covariance = within_area(*inside, AREA_M)
    np.testing.assert_array_equal(mean, inside[0])
    np.testing.assert_array_equal(covariance, inside[1])
    on_edge = track([15.0, 7.0, 1.0, 0.0], [1.0, 1.0], 0.5, 0.5)
    mean, covariance = within_area(*on_edge, AREA_M)
    half = truncnorm(-np.inf, 0.0, loc=15.0, scale=1.0)
    assert mean[0, 0] == pytest.approx(half.mean(), abs=0.02)
    assert mean[0, 1] == pytest.approx(7.0, abs=0.02)
    assert mean[0, 2] < 1.0, "a track carried out of the area by its velocity turns back"
    assert covariance[0, 0, 0] < 1.0


def test_a_track_with_one_quadrature_point_in_the_area_is_moved_onto_it_with_a_covariance_still_positive_definite():
    """Evidence on a single point (a track all but wholly outside the area) leaves a position spread of one
    point's share of the prior, not 0: the track can be truncated again, and its mean is that point."""
    mean, covariance = track([7.5, 7.5, 0.0, 0.0], [1.0, 1.0], 0.5, 0.5)
    points = position_points(mean, covariance)
    weights = np.zeros(points.shape[:2])
    weights[0, 17] = 1.0
    after_mean, after_covariance = moment_matched(mean, covariance, points, weights)
    np.testing.assert_allclose(after_mean[0, :2], points[0, 17])
    np.testing.assert_allclose(np.linalg.eigvalsh(after_covariance[0, :2, :2]), [1.0 / 256, 1.0 / 256])
    assert np.all(np.linalg.eigvalsh(after_covariance[0]) > 0)
    again_mean, _ = within_area(after_mean, after_covariance, AREA_M)
    np.testing.assert_allclose(again_mean, after_mean)


def test_a_track_wholly_outside_the_area_is_left_as_it_is():
    outside = track([30.0, 30.0, 0.0, 0.0], [0.5, 0.5])
    mean, covariance = within_area(*outside, AREA_M)
    np.testing.assert_array_equal(mean, outside[0])
    np.testing.assert_array_equal(covariance, outside[1])


def feet_in_image(mean, pose):
    return inside_image(CAMERA, apply_homography(ground_to_image(CAMERA, pose), mean[:, :2]))


def test_a_miss_moves_a_track_out_of_the_view_and_leaves_one_wholly_in_view_where_it_was():
    """A track a fifth of which lies beyond the view's edge, missed where the detector would have found
    its person with probability 0.9, moves away from where the camera looked and spreads; a track wholly
    in view, missed by a detector that finds half the people anywhere in the image, loses existence only
    (its position's posterior is its prior)."""
    looked_at_m = np.array([7.5, 6.0])
    pose = look_at(CAMERA, looked_at_m, 6.0)
    straddling = track([8.0, 6.0, 0.0, 0.0], [1.0, 1.0])
    assert 0.7 < feet_in_image(position_points(*straddling)[0], pose).mean() < 0.9
    mean, covariance = after_miss(CAMERA, pose, *straddling, np.array([0.9]))
    assert np.linalg.norm(mean[0, :2] - looked_at_m) > 1.2
    assert np.all(np.sqrt(np.diag(covariance[0, :2, :2])) > 1.2)
    assert np.linalg.eigvalsh(covariance[0])[0] > 0
    in_view = track([7.5, 6.0, 0.0, 0.0], [0.05, 0.05])
    points = position_points(*in_view)
    share_in_image = feet_in_image(points[0], pose).mean()
    assert share_in_image == 1.0
    mean, covariance = after_miss(CAMERA, pose, *in_view, np.array([0.5]))
    np.testing.assert_allclose(mean, in_view[0], atol=1e-12)
    np.testing.assert_allclose(covariance, in_view[1], atol=1e-12)


def test_a_look_that_cannot_have_found_a_track_leaves_it_as_it_was():
    pose = look_at(CAMERA, [7.5, 6.0], 3.0)
    away = track([1.0, 14.0, 0.5, 0.0], [0.4, 0.4])
    mean, covariance = after_miss(CAMERA, pose, *away, np.array([0.0]))
    np.testing.assert_array_equal(mean, away[0])
    np.testing.assert_array_equal(covariance, away[1])
