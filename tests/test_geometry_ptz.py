"""Property tests of the PTZ camera model in ptztrack.geometry.ptz."""

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from ptztrack.geometry.ptz import (
    PTZCamera,
    aim_at,
    apply_homography,
    camera_depth_m,
    feet_jacobian,
    ground_footprint,
    ground_to_image,
    head_from_feet_homology,
    image_to_ground,
    inside_image,
    look_at,
    pixels_to_ground,
    plane_homography,
    pose_noise_px2,
    project_people,
    projection_matrix,
    rotation_homography,
    rotation_world_to_camera,
    standing_height_px,
)

CAMERA = PTZCamera((7.5, -4.0, 7.0), 640, 480, 400.0)
CENTRE = np.array([320.0, 240.0])
PROPERTY = settings(deadline=None, max_examples=100)

unit = st.floats(0.0, 1.0, allow_nan=False, allow_infinity=False)
pans = st.floats(-80.0, 80.0, allow_nan=False, allow_infinity=False)
tilts = st.floats(5.0, 80.0, allow_nan=False, allow_infinity=False)
zooms = st.floats(1.0, 10.0, allow_nan=False, allow_infinity=False)
poses = st.tuples(pans, tilts, zooms).map(lambda p: np.array(p, dtype=float))


def horizon_row_px(pose):
    """The image row of the horizon (no roll, so it is a horizontal line)."""
    focal_px = pose[2] * CAMERA.f_min_px
    return CAMERA.image_height_px / 2.0 - focal_px * np.tan(np.deg2rad(pose[1]))


@st.composite
def ground_pixels(draw, pose, count):
    """``count`` pixels inside the image, safely below the horizon (ground within a few hundred m)."""
    focal_px = pose[2] * CAMERA.f_min_px
    # 0.05 f below the horizon keeps every ray at least ~0.5 deg below horizontal.
    top = max(0.0, horizon_row_px(pose) + 0.05 * focal_px)
    assume(top < CAMERA.image_height_px - 1.0)
    fractions = np.array(draw(st.lists(st.tuples(unit, unit), min_size=count, max_size=count)), dtype=float)
    u = fractions[:, 0] * CAMERA.image_width_px
    v = top + fractions[:, 1] * (CAMERA.image_height_px - top)
    return np.stack([u, v], axis=-1)


@st.composite
def pose_and_ground_points(draw, count=6):
    """A pose and ``count`` ground points that it sees (in the image, in front of the camera)."""
    pose = draw(poses)
    pixels = draw(ground_pixels(pose, count))
    ground_xy = apply_homography(image_to_ground(CAMERA, pose), pixels)
    depth = camera_depth_m(CAMERA, pose, np.concatenate([ground_xy, np.zeros((count, 1))], axis=-1))
    assert np.all(depth > 0), "pixels below the horizon must see the ground in front of the camera"
    return pose, pixels, ground_xy


def with_z(xy, z=0.0):
    xy = np.asarray(xy, dtype=float)
    return np.concatenate([xy, np.full(xy.shape[:-1] + (1,), z)], axis=-1)


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
# head/feet homology and project_people


@PROPERTY
@given(pose_and_ground_points(), st.floats(0.3, 2.5))
def test_homology_maps_feet_to_head(sample, height_m):
    pose, _, ground_xy = sample
    head_depth = camera_depth_m(CAMERA, pose, with_z(ground_xy, height_m))
    keep = head_depth > 0.5  # the head must not sit (almost) in the camera's focal plane
    assume(np.any(keep))
    ground_xy = ground_xy[keep]
    people = project_people(CAMERA, pose, ground_xy, height_m, 0.5)
    W = head_from_feet_homology(CAMERA, pose, height_m)
    np.testing.assert_allclose(apply_homography(W, people.feet_px), people.head_px, rtol=1e-9, atol=1e-6)
    # feet_px of project_people is the ground homography image of the feet
    np.testing.assert_allclose(
        people.feet_px, apply_homography(ground_to_image(CAMERA, pose), ground_xy), rtol=1e-9, atol=1e-6
    )
    # and the head is the image of the plane z = height through plane_homography
    np.testing.assert_allclose(
        people.head_px, apply_homography(plane_homography(CAMERA, pose, height_m), ground_xy), rtol=1e-9, atol=1e-6
    )


@PROPERTY
@given(pose_and_ground_points(), st.floats(0.5, 2.2), st.floats(0.2, 1.0))
def test_project_people_box(sample, height_m, width_m):
    pose, _, ground_xy = sample
    head_depth = camera_depth_m(CAMERA, pose, with_z(ground_xy, height_m))
    keep = head_depth > 0.5
    assume(np.any(keep))
    ground_xy = ground_xy[keep]
    people = project_people(CAMERA, pose, ground_xy, height_m, width_m)
    box = people.box_px
    np.testing.assert_allclose(people.height_px, np.abs(people.feet_px[:, 1] - people.head_px[:, 1]), rtol=1e-12)
    # the box spans the rows of feet and head and is centred between them
    np.testing.assert_allclose(box[:, 1], np.minimum(people.feet_px[:, 1], people.head_px[:, 1]), rtol=1e-12)
    np.testing.assert_allclose(box[:, 3], np.maximum(people.feet_px[:, 1], people.head_px[:, 1]), rtol=1e-12)
    np.testing.assert_allclose(box[:, 0] + box[:, 2], people.feet_px[:, 0] + people.head_px[:, 0], rtol=1e-9, atol=1e-6)
    # People shorter than the camera's 7 m who stand ahead of it (not past the nadir) have
    # the head above the feet in the image.
    pan = np.deg2rad(pose[0])
    ahead = (ground_xy - CAMERA.centre_m[:2]) @ np.array([np.sin(pan), np.cos(pan)]) > 0
    assert np.all(people.head_px[ahead, 1] < people.feet_px[ahead, 1])
    np.testing.assert_allclose(people.depth_m, camera_depth_m(CAMERA, pose, with_z(ground_xy)), rtol=1e-12)
    # the box is as wide as width_m seen at the mean depth of feet and head (the lean is not added)
    focal_px = pose[2] * CAMERA.f_min_px
    mean_depth = 0.5 * (people.depth_m + head_depth[keep])
    expected_width = focal_px * width_m / mean_depth
    np.testing.assert_allclose(box[:, 2] - box[:, 0], expected_width, rtol=1e-9)

    # Doubling the zoom at the same pan/tilt doubles the box (about the principal point).
    double = pose * np.array([1.0, 1.0, 2.0])
    zoomed = project_people(CAMERA, double, ground_xy, height_m, width_m)
    np.testing.assert_allclose(zoomed.box_px[:, 2] - zoomed.box_px[:, 0], 2 * (box[:, 2] - box[:, 0]), rtol=1e-9)
    np.testing.assert_allclose(zoomed.height_px, 2 * people.height_px, rtol=1e-9)
    np.testing.assert_allclose(zoomed.feet_px - CENTRE, 2 * (people.feet_px - CENTRE), rtol=1e-9, atol=1e-7)
    np.testing.assert_allclose(zoomed.depth_m, people.depth_m, rtol=1e-12)


def test_project_people_per_person_sizes():
    pose = look_at(CAMERA, (7.5, 8.0), 1.0)
    xy = np.array([[7.5, 8.0], [7.5, 8.0], [6.0, 9.0]])
    people = project_people(CAMERA, pose, xy, np.array([1.0, 2.0, 1.5]), np.array([0.4, 0.8, 0.5]))
    # same feet, twice the height -> the head is higher and the box taller
    np.testing.assert_allclose(people.feet_px[0], people.feet_px[1])
    assert people.height_px[1] > people.height_px[0] > 0
    # the person looked at stands at the centre column, with symmetric box around u = 320
    np.testing.assert_allclose(people.feet_px[0], CENTRE, atol=1e-9)
    np.testing.assert_allclose(people.head_px[0, 0], 320.0, atol=1e-9)
    np.testing.assert_allclose(people.box_px[0, 0] + people.box_px[0, 2], 640.0, atol=1e-9)


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


@PROPERTY
@given(pose_and_ground_points())
def test_standing_height_is_the_distance_from_the_feet_to_the_projected_head(sample):
    pose, feet_px, ground_xy = sample
    head_px = apply_homography(plane_homography(CAMERA, pose, 1.75), ground_xy)
    expected_px = np.linalg.norm(head_px - feet_px, axis=-1)
    standing = standing_height_px(CAMERA, pose, 1.75, feet_px)
    np.testing.assert_allclose(standing, expected_px, rtol=1e-9)


def test_a_person_under_a_steep_camera_has_the_head_below_the_feet_in_the_image_and_is_still_measured():
    """Tilted 60 deg down, the nadir is in the image: a person standing below it appears upside down."""
    pose = np.array([0.0, 60.0, 1.0])
    feet_px = np.array([[0.0, 480.0]])
    ground_xy = apply_homography(image_to_ground(CAMERA, pose), feet_px)
    head_px = apply_homography(plane_homography(CAMERA, pose, 1.75), ground_xy)
    assert head_px[0, 1] > feet_px[0, 1]
    np.testing.assert_allclose(
        standing_height_px(CAMERA, pose, 1.75, feet_px), np.linalg.norm(head_px - feet_px, axis=-1)
    )


def test_no_one_stands_beyond_the_horizon():
    pose = np.array([0.0, 10.0, 1.0])
    above_px = [[320.0, horizon_row_px(pose) - 5.0]]
    assert np.isnan(standing_height_px(CAMERA, pose, 1.75, above_px)).all()


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
