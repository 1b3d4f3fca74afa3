"""Property tests of the PTZ camera model in ptztrack.geometry.ptz: ground <-> image mappings, batched
poses, the feet Jacobian, the pan and tilt conventions and the pose noise."""

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from ptz_strategies import (
    CAMERA,
    CENTRE,
    PROPERTY,
    horizon_row_px,
    pose_and_ground_points,
    poses,
    unit,
    with_z,
    zooms,
)
from ptztrack.geometry.ptz import (
    apply_homography,
    camera_depth_m,
    feet_jacobian,
    ground_footprint,
    ground_to_image,
    head_from_feet_homology,
    image_to_ground,
    look_at,
    pixels_to_ground,
    plane_homography,
    pose_noise_px2,
    project_people,
    projection_matrix,
    rotation_world_to_camera,
)

# ---------------------------------------------------------------------------
# ground <-> image round trip


@PROPERTY
@given(pose_and_ground_points())
def test_ground_image_round_trip(sample):
    pose, pixels, ground_xy = sample
    H = ground_to_image(CAMERA, pose)
    H_inv = image_to_ground(CAMERA, pose)

    back_px = apply_homography(H, ground_xy)
    np.testing.assert_allclose(back_px, pixels, rtol=1e-9, atol=1e-7)

    back_xy = apply_homography(H_inv, apply_homography(H, ground_xy))
    np.testing.assert_allclose(back_xy, ground_xy, rtol=1e-9, atol=1e-7)

    # H is invertible and image_to_ground really is its inverse.
    np.testing.assert_allclose(H @ H_inv, np.eye(3), atol=1e-9)
    np.testing.assert_allclose(H_inv @ H, np.eye(3), atol=1e-9)


@PROPERTY
@given(pose_and_ground_points(), st.lists(st.tuples(unit, unit), min_size=1, max_size=4))
def test_pixels_to_ground_is_image_to_ground_below_the_horizon_and_nan_above(sample, fractions):
    pose, pixels, ground_xy = sample
    np.testing.assert_allclose(pixels_to_ground(CAMERA, pose, pixels), ground_xy, rtol=1e-9, atol=1e-7)
    horizon = horizon_row_px(pose)
    assume(horizon > 1.0)
    above = np.array(fractions) * [CAMERA.image_width_px, horizon - 1.0]
    assert np.all(np.isnan(pixels_to_ground(CAMERA, pose, above)))


@PROPERTY
@given(poses, st.lists(st.tuples(st.floats(-40, 40), st.floats(-40, 40)), min_size=1, max_size=6))
def test_ground_to_image_matches_projection_matrix(pose, xy):
    xy = np.array(xy, dtype=float)
    X = with_z(xy)
    depth = camera_depth_m(CAMERA, pose, X)
    assume(np.all(np.abs(depth) > 1e-3))
    P = projection_matrix(CAMERA, pose)
    homogeneous = (P[:, :3] @ X.T + P[:, 3:]).T
    expected = homogeneous[:, :2] / homogeneous[:, 2:]
    np.testing.assert_allclose(apply_homography(ground_to_image(CAMERA, pose), xy), expected, rtol=1e-9, atol=1e-7)
    # The third homogeneous coordinate of P is the depth along the optical axis.
    np.testing.assert_allclose(homogeneous[:, 2], depth, rtol=1e-12, atol=1e-9)


def test_rotation_is_orthonormal_with_documented_rows():
    rng = np.random.default_rng(0)
    pan = rng.uniform(-180, 180, 50)
    tilt = rng.uniform(-89, 89, 50)
    R = rotation_world_to_camera(pan, tilt)
    assert R.shape == (50, 3, 3)
    np.testing.assert_allclose(R @ np.swapaxes(R, -1, -2), np.broadcast_to(np.eye(3), R.shape), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-12)
    # right is horizontal, down has a downward (negative z) component when looking below the horizon
    np.testing.assert_allclose(R[:, 0, 2], 0.0, atol=1e-15)
    np.testing.assert_allclose(R[:, 2, 2], -np.sin(np.deg2rad(tilt)), atol=1e-15)
    assert np.all(R[:, 1, 2] < 0)


# ---------------------------------------------------------------------------
# vectorisation over leading pose axes


@settings(deadline=None, max_examples=30)
@given(st.lists(pose_and_ground_points(count=5), min_size=1, max_size=4))
def test_batched_poses_equal_loop(samples):
    batch_poses = np.stack([s[0] for s in samples])  # (P, 3)
    batch_xy = np.stack([s[2] for s in samples])  # (P, N, 2)
    batch_px = np.stack([s[1] for s in samples])
    heights = np.linspace(1.5, 1.9, batch_xy.shape[1])
    close = dict(rtol=1e-12, atol=1e-9)

    H = ground_to_image(CAMERA, batch_poses)
    H_inv = image_to_ground(CAMERA, batch_poses)
    W = head_from_feet_homology(CAMERA, batch_poses, 1.8)
    P = projection_matrix(CAMERA, batch_poses)
    J = feet_jacobian(CAMERA, batch_poses, batch_xy)
    pixels = apply_homography(H, batch_xy)
    ground = apply_homography(H_inv, batch_px)
    depth = camera_depth_m(CAMERA, batch_poses, with_z(batch_xy))
    people = project_people(CAMERA, batch_poses, batch_xy, heights, 0.5)
    footprint = ground_footprint(CAMERA, batch_poses)

    assert H.shape == (len(samples), 3, 3)
    assert P.shape == (len(samples), 3, 4)
    assert J.shape == batch_xy.shape + (2,)
    assert pixels.shape == batch_xy.shape
    assert depth.shape == batch_xy.shape[:-1]
    assert people.box_px.shape == batch_xy.shape[:-1] + (4,)
    assert footprint.shape == (len(samples), 64, 2)

    for k, (pose, px, xy) in enumerate(samples):
        np.testing.assert_allclose(H[k], ground_to_image(CAMERA, pose), **close)
        np.testing.assert_allclose(H_inv[k], image_to_ground(CAMERA, pose), **close)
        np.testing.assert_allclose(W[k], head_from_feet_homology(CAMERA, pose, 1.8), **close)
        np.testing.assert_allclose(P[k], projection_matrix(CAMERA, pose), **close)
        np.testing.assert_allclose(J[k], feet_jacobian(CAMERA, pose, xy), **close)
        np.testing.assert_allclose(pixels[k], apply_homography(ground_to_image(CAMERA, pose), xy), **close)
        np.testing.assert_allclose(ground[k], apply_homography(image_to_ground(CAMERA, pose), px), **close)
        np.testing.assert_allclose(depth[k], camera_depth_m(CAMERA, pose, with_z(xy)), **close)
        single = project_people(CAMERA, pose, xy, heights, 0.5)
        np.testing.assert_allclose(people.feet_px[k], single.feet_px, **close)
        np.testing.assert_allclose(people.head_px[k], single.head_px, **close)
        np.testing.assert_allclose(people.box_px[k], single.box_px, **close)
        np.testing.assert_allclose(people.depth_m[k], single.depth_m, **close)
        np.testing.assert_allclose(footprint[k], ground_footprint(CAMERA, pose), **close)


def test_two_leading_pose_axes_and_height_broadcast():
    rng = np.random.default_rng(1)
    grid = np.stack(
        [rng.uniform(-60, 60, (2, 3)), rng.uniform(20, 70, (2, 3)), rng.uniform(1, 4, (2, 3))], axis=-1
    )  # (2, 3, 3)
    heights = np.array([[0.0, 1.0, 2.0], [0.5, 1.5, 2.5]])  # (2, 3) one plane height per pose
    H = plane_homography(CAMERA, grid, heights)
    assert H.shape == (2, 3, 3, 3)
    for i in range(2):
        for j in range(3):
            np.testing.assert_allclose(H[i, j], plane_homography(CAMERA, grid[i, j], heights[i, j]), rtol=1e-12)


# ---------------------------------------------------------------------------
# Jacobian of the feet pixel


@PROPERTY
@given(pose_and_ground_points())
def test_feet_jacobian_matches_central_differences(sample):
    pose, _, ground_xy = sample
    H = ground_to_image(CAMERA, pose)
    J = feet_jacobian(CAMERA, pose, ground_xy)
    assert J.shape == ground_xy.shape + (2,)

    step_m = 1e-4
    J_fd = np.empty_like(J)
    for axis in range(2):
        offset = np.zeros(2)
        offset[axis] = step_m
        plus = apply_homography(H, ground_xy + offset)
        minus = apply_homography(H, ground_xy - offset)
        J_fd[:, :, axis] = (plus - minus) / (2 * step_m)
    for n in range(len(ground_xy)):
        error = np.linalg.norm(J[n] - J_fd[n]) / np.linalg.norm(J[n])
        assert error < 1e-6, (n, error)


# ---------------------------------------------------------------------------
# pan / tilt conventions


def test_pan0_tilt90_looks_straight_down():
    below = np.array([[7.5, -4.0]])
    for pan in (0.0, 37.0, -120.0):
        for zoom in (1.0, 3.0):
            pose = np.array([pan, 90.0, zoom])
            pixel = apply_homography(ground_to_image(CAMERA, pose), below)[0]
            np.testing.assert_allclose(pixel, CENTRE, atol=1e-9)
            np.testing.assert_allclose(camera_depth_m(CAMERA, pose, with_z(below)), [7.0], rtol=1e-12)
    # and at pan 0 the image "up" direction (v decreasing) points along world +y, right along +x
    pose = np.array([0.0, 90.0, 1.0])
    up, right = apply_homography(ground_to_image(CAMERA, pose), np.array([[7.5, -3.0], [8.5, -4.0]]))
    np.testing.assert_allclose(up, [320.0, 240.0 - 400.0 / 7.0], atol=1e-9)
    np.testing.assert_allclose(right, [320.0 + 400.0 / 7.0, 240.0], atol=1e-9)


@PROPERTY
@given(st.floats(20, 60), st.floats(5, 40), st.floats(0.5, 5), zooms)
def test_positive_pan_turns_towards_plus_x(tilt, ahead_m, side_m, zoom):
    pose0 = np.array([0.0, tilt, zoom])
    # pan 0 looks along +y; a point to the +x side of that axis is right of centre
    ahead = CAMERA.centre_m[:2] + np.array([0.0, ahead_m])
    side = ahead + np.array([side_m, 0.0])
    H0 = ground_to_image(CAMERA, pose0)
    u_ahead, u_side = apply_homography(H0, np.stack([ahead, side]))[:, 0]
    np.testing.assert_allclose(u_ahead, 320.0, atol=1e-9)
    assert u_side > 320.0
    # the point to the -x side is left of centre, mirror-symmetric
    u_mirror = apply_homography(H0, (ahead - np.array([side_m, 0.0]))[None])[0, 0]
    np.testing.assert_allclose(u_mirror - 320.0, -(u_side - 320.0), rtol=1e-9, atol=1e-9)

    pose = look_at(CAMERA, side, zoom)
    assert pose[0] > 0
    np.testing.assert_allclose(pose[0], np.rad2deg(np.arctan2(side_m, ahead_m)), rtol=1e-12)
    np.testing.assert_allclose(apply_homography(ground_to_image(CAMERA, pose), side[None])[0], CENTRE, atol=1e-9)
    # a slightly larger pan moves the point left of centre
    turned = pose + np.array([1.0, 0.0, 0.0])
    assert apply_homography(ground_to_image(CAMERA, turned), side[None])[0, 0] < 320.0


def test_tilt_down_moves_points_up_in_image():
    target = np.array([[7.5, 6.0]])
    pose = look_at(CAMERA, target[0], 1.0)
    lower = pose + np.array([0.0, 5.0, 0.0])
    v = apply_homography(ground_to_image(CAMERA, lower), target)[0, 1]
    assert v < 240.0


@given(st.floats(-60, 60), st.floats(5, 60), st.floats(1.0, 8.0))
def test_pose_noise_is_the_image_shift_of_a_small_pose_error_at_the_centre_and_over_the_image(pan, tilt, zoom):
    """A pan or tilt error of ``e`` moves the image centre by ``f cos(tilt) e`` or ``f e`` px, as
    projecting the point seen there at the two poses shows; a zoom error ``e`` moves a point spread
    evenly over the image by ``e / z`` of its offset from the centre, whose mean square is ``(w^2 or
    h^2) / 12``."""
    pose, error_deg = np.array([pan, tilt, zoom]), 1e-4
    centre = CAMERA.principal_point_px
    for axis in (0, 1):
        seen_m = apply_homography(image_to_ground(CAMERA, pose), centre[None])[0]
        assume(np.all(np.isfinite(seen_m)))
        moved = pose.copy()
        moved[axis] += error_deg
        shift_px = np.linalg.norm(apply_homography(ground_to_image(CAMERA, moved), seen_m[None])[0] - centre)
        sd = np.zeros(3)
        sd[axis] = error_deg
        np.testing.assert_allclose(np.sqrt(np.trace(pose_noise_px2(CAMERA, pose, sd))), shift_px, rtol=1e-3)
    zoom_noise = pose_noise_px2(CAMERA, pose, [0.0, 0.0, 0.01 * zoom])
    np.testing.assert_allclose(np.diag(zoom_noise), np.array([640.0, 480.0]) ** 2 * 1e-4 / 12)
    assert zoom_noise[0, 1] == 0.0
