"""Property tests of the PTZ camera model in ptztrack.geometry.ptz: people in the image (the head/feet
homology, their boxes from project_people and their standing height in pixels)."""

import numpy as np
from hypothesis import assume, given
from hypothesis import strategies as st

from ptz_strategies import (
    CAMERA,
    CENTRE,
    PROPERTY,
    horizon_row_px,
    pose_and_ground_points,
    with_z,
)
from ptztrack.geometry.ptz import (
    apply_homography,
    camera_depth_m,
    ground_to_image,
    head_from_feet_homology,
    image_to_ground,
    look_at,
    plane_homography,
    project_people,
    standing_height_px,
)

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
