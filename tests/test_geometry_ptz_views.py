"""Property tests of the PTZ camera model in ptztrack.geometry.ptz: what a pose looks at and sees (aiming
at a point or pixel, the rotation homography between views, the ground footprint and the image's bounds)."""

import numpy as np
from hypothesis import assume, given
from hypothesis import strategies as st

from ptz_strategies import (
    CAMERA,
    CENTRE,
    PROPERTY,
    horizon_row_px,
    pans,
    poses,
    unit,
    with_z,
    zooms,
)
from ptztrack.geometry.ptz import (
    aim_at,
    apply_homography,
    camera_depth_m,
    ground_footprint,
    ground_to_image,
    inside_image,
    look_at,
    projection_matrix,
    rotation_homography,
    rotation_world_to_camera,
)

# ---------------------------------------------------------------------------
# optical axis and principal point


@PROPERTY
@given(
    st.floats(-30, 45),
    st.floats(-30, 45),
    zooms,
)
def test_look_at_target_projects_to_principal_point(x, y, zoom):
    target = np.array([x, y])
    assume(np.linalg.norm(target - CAMERA.centre_m[:2]) > 0.5)
    pose = look_at(CAMERA, target, zoom)
    assert pose.shape == (3,)
    assert pose[2] == zoom
    pixel = apply_homography(ground_to_image(CAMERA, pose), target[None])[0]
    np.testing.assert_allclose(pixel, CENTRE, rtol=0, atol=1e-9)
    assert camera_depth_m(CAMERA, pose, with_z(target[None]))[0] > 0


def test_look_at_batched():
    targets = np.array([[0.0, 0.0], [15.0, 15.0], [7.5, 10.0], [20.0, -4.0]])
    batch = look_at(CAMERA, targets, 2.0)
    assert batch.shape == (4, 3)
    for k, target in enumerate(targets):
        np.testing.assert_allclose(batch[k], look_at(CAMERA, target, 2.0), rtol=1e-14)
    pixels = apply_homography(ground_to_image(CAMERA, batch), targets[:, None, :])[:, 0]
    np.testing.assert_allclose(pixels, np.broadcast_to(CENTRE, (4, 2)), atol=1e-9)
    # straight ahead along +y: pan 0; towards +x of the camera: pan 90.
    np.testing.assert_allclose(batch[2, 0], 0.0, atol=1e-12)
    np.testing.assert_allclose(batch[3, 0], 90.0, atol=1e-12)
    np.testing.assert_allclose(batch[2, 1], np.rad2deg(np.arctan2(7.0, 14.0)), atol=1e-12)


@PROPERTY
@given(
    st.floats(10.0, 50.0),
    st.floats(-180.0, 180.0),
    st.floats(0.0, 2.0),
    st.tuples(unit, unit),
    zooms,
)
def test_aim_at_shows_the_point_at_the_pixel(distance_m, bearing_deg, height_m, fractions, zoom):
    """The pose aim_at returns sees the point in front of the camera, at the pixel asked for.

    At 10 m or more from a camera 7 m up every pixel can reach the point with a tilt below 90 deg."""
    bearing = np.deg2rad(bearing_deg)
    point = CAMERA.centre_m + [distance_m * np.sin(bearing), distance_m * np.cos(bearing), 0.0]
    point[2] = height_m
    pixel = np.array(fractions) * [CAMERA.image_width_px, CAMERA.image_height_px]
    pose = aim_at(CAMERA, point, pixel, zoom)
    homogeneous = projection_matrix(CAMERA, pose) @ np.append(point, 1.0)
    assert homogeneous[2] > 0
    np.testing.assert_allclose(homogeneous[:2] / homogeneous[2], pixel, rtol=0, atol=1e-7)
    assert pose[2] == zoom


def test_aim_at_the_principal_point_is_look_at_and_batches():
    targets = np.array([[0.0, 0.0], [15.0, 15.0], [7.5, 10.0], [20.0, -4.0]])
    poses = aim_at(CAMERA, with_z(targets), CENTRE, 2.0)
    np.testing.assert_allclose(poses, look_at(CAMERA, targets, 2.0), atol=1e-9)


@PROPERTY
@given(poses, poses, st.lists(st.tuples(unit, unit), min_size=1, max_size=5))
def test_rotation_homography_maps_the_pixels_of_one_view_onto_the_other(pose1, pose2, fractions):
    """A point seen at a pixel of one view is seen where the homography puts that pixel in the other."""
    pixels = np.array(fractions) * [CAMERA.image_width_px, CAMERA.image_height_px]
    R1 = rotation_world_to_camera(pose1[0], pose1[1])
    rays_camera = np.c_[(pixels - CENTRE) / (pose1[2] * CAMERA.f_min_px), np.ones(len(pixels))]
    points = CAMERA.centre_m + 7.0 * rays_camera @ R1  # anywhere along the rays
    homogeneous = (projection_matrix(CAMERA, pose2) @ np.c_[points, np.ones(len(points))].T).T
    assume(np.all(homogeneous[:, 2] > 1e-3))
    expected = homogeneous[:, :2] / homogeneous[:, 2:]
    mapped = apply_homography(rotation_homography(CAMERA, pose1, pose2), pixels)
    np.testing.assert_allclose(mapped, expected, rtol=1e-7, atol=1e-6)
    np.testing.assert_allclose(rotation_homography(CAMERA, pose1, pose1), np.eye(3), atol=1e-12)


@PROPERTY
@given(poses, st.floats(0.1, 200.0))
def test_point_on_optical_axis_projects_to_principal_point(pose, distance_m):
    R = rotation_world_to_camera(pose[0], pose[1])
    forward = R[2]
    point = CAMERA.centre_m + distance_m * forward
    P = projection_matrix(CAMERA, pose)
    homogeneous = P @ np.append(point, 1.0)
    np.testing.assert_allclose(homogeneous[:2] / homogeneous[2], CENTRE, rtol=0, atol=1e-9)
    np.testing.assert_allclose(homogeneous[2], distance_m, rtol=1e-12)
    np.testing.assert_allclose(camera_depth_m(CAMERA, pose, point[None]), [distance_m], rtol=1e-12)


# ---------------------------------------------------------------------------
# ground footprint


def is_on_border(pixels, atol=1e-6):
    u, v = pixels[..., 0], pixels[..., 1]
    on_vertical = (np.abs(u) < atol) | (np.abs(u - CAMERA.image_width_px) < atol)
    on_horizontal = (np.abs(v) < atol) | (np.abs(v - CAMERA.image_height_px) < atol)
    inside = (u > -atol) & (u < CAMERA.image_width_px + atol) & (v > -atol) & (v < CAMERA.image_height_px + atol)
    return (on_vertical | on_horizontal) & inside


@PROPERTY
@given(st.floats(-180, 180), st.floats(50, 90), zooms, st.sampled_from([4, 8, 16]))
def test_footprint_looking_down_maps_back_to_image_border(pan, tilt, zoom, per_edge):
    pose = np.array([pan, tilt, zoom])
    max_range_m = 60.0
    footprint = ground_footprint(CAMERA, pose, per_edge, max_range_m)
    assert footprint.shape == (4 * per_edge, 2)
    ranges = np.linalg.norm(footprint - CAMERA.centre_m[:2], axis=-1)
    assert np.all(np.isfinite(footprint))
    assert np.all(ranges < max_range_m * (1 - 1e-9))  # tilt >= 50 deg never reaches 60 m
    pixels = apply_homography(ground_to_image(CAMERA, pose), footprint)
    assert np.all(is_on_border(pixels)), pixels[~is_on_border(pixels)]
    # the vertices are the sampled border points in order: first one is the top-left corner
    np.testing.assert_allclose(pixels[0], [0.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(pixels[per_edge], [640.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(pixels[2 * per_edge], [640.0, 480.0], atol=1e-6)
    np.testing.assert_allclose(pixels[3 * per_edge], [0.0, 480.0], atol=1e-6)
    # every footprint vertex lies in front of the camera
    assert np.all(camera_depth_m(CAMERA, pose, with_z(footprint)) > 0)


@PROPERTY
@given(pans, st.floats(-10, 25), st.floats(1, 3), st.floats(10, 100))
def test_footprint_seeing_horizon_is_finite_and_bounded(pan, tilt, zoom, max_range_m):
    pose = np.array([pan, tilt, zoom])
    # the top image row is at or above the horizon
    assume(horizon_row_px(pose) >= 0.0)
    footprint = ground_footprint(CAMERA, pose, 16, max_range_m)
    assert np.all(np.isfinite(footprint))
    ranges = np.linalg.norm(footprint - CAMERA.centre_m[:2], axis=-1)
    assert np.all(ranges <= max_range_m * (1 + 1e-12))
    # the top edge (first 16 vertices) sees the sky, so it is cut at max_range
    np.testing.assert_allclose(ranges[:16], max_range_m, rtol=1e-12)
    # the cut vertices lie along the ray of their border pixel (same image column direction):
    # points near the camera (within range) still map back to the border
    within = ranges < max_range_m * (1 - 1e-9)
    if np.any(within):
        pixels = apply_homography(ground_to_image(CAMERA, pose), footprint[within])
        assert np.all(is_on_border(pixels))


def test_footprint_batched_shapes():
    batch = np.array([[0.0, 40.0, 1.0], [30.0, 10.0, 2.0], [-45.0, 89.0, 4.0]])
    footprint = ground_footprint(CAMERA, batch, points_per_edge=5, max_range_m=30.0)
    assert footprint.shape == (3, 20, 2)
    assert np.all(np.isfinite(footprint))
    assert np.all(np.linalg.norm(footprint - CAMERA.centre_m[:2], axis=-1) <= 30.0 + 1e-9)


# ---------------------------------------------------------------------------
# inside_image


def test_inside_image_simple_cases():
    pixels = np.array(
        [
            [320.0, 240.0],
            [0.0, 0.0],  # corners are inside (closed interval)
            [640.0, 480.0],
            [640.0, 0.0],
            [-1e-9, 100.0],
            [640.000001, 100.0],
            [100.0, -0.5],
            [100.0, 480.5],
            [np.nan, 100.0],
            [np.inf, 100.0],
        ]
    )
    expected = [True, True, True, True, False, False, False, False, False, False]
    np.testing.assert_array_equal(inside_image(CAMERA, pixels), expected)
    assert inside_image(CAMERA, [10.0, 10.0]).shape == ()
    assert bool(inside_image(CAMERA, [10.0, 10.0]))
    grid = np.zeros((2, 3, 2))
    grid[1, 2] = [1000.0, 0.0]
    np.testing.assert_array_equal(inside_image(CAMERA, grid), [[True] * 3, [True, True, False]])
