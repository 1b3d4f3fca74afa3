"""A real view's departures from the pinhole model: roll, principal point offset, radial distortion."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ptztrack.geometry.lens import (
    Lens,
    distortion_invertible,
    pixel_directions,
    project_directions,
    undistort_normalised,
)
from ptztrack.geometry.ptz import PTZCamera, apply_homography, ground_to_image, rotation_world_to_camera

CAMERA = PTZCamera((0.0, 0.0, 8.0), 640, 480, 500.0)
CENTRE = np.array([320.0, 240.0])
POSE = np.array([10.0, 20.0, 2.0])

poses = st.tuples(st.floats(-40, 40), st.floats(5, 40), st.floats(1, 4)).map(np.array)
# Barrel distortion stays invertible up to the corner of this 65 deg wide view (radius 0.8 at zoom 1)
# while k1 r^2 > -4/27: k1 down to -0.23.
lenses = st.builds(
    Lens,
    roll_deg=st.floats(-5, 5),
    principal_offset_px=st.tuples(st.floats(-20, 20), st.floats(-20, 20)),
    k1=st.floats(-0.2, 0.3),
)


def camera_directions(pose, normalised):
    """World directions seen at normalised coordinates (N, 2) of the level pinhole at ``pose``."""
    rays = np.c_[normalised, np.ones(len(normalised))]
    return rays @ rotation_world_to_camera(pose[0], pose[1])


@settings(max_examples=50, deadline=None)
@given(pose=poses)
def test_without_departures_the_lens_is_the_pinhole_model(pose):
    ground_m = np.array([[2.0, 15.0], [-4.0, 30.0], [6.0, 22.0]])
    directions = np.c_[ground_m, np.zeros(3)] - CAMERA.centre_m
    expected = apply_homography(ground_to_image(CAMERA, pose), ground_m)
    np.testing.assert_allclose(project_directions(CAMERA, pose, Lens(), directions), expected, rtol=1e-9, atol=1e-6)


@settings(max_examples=100, deadline=None)
@given(pose=poses, lens=lenses)
def test_pixel_directions_and_projection_are_inverse(pose, lens):
    pixels = np.array([[0.0, 0.0], [640.0, 480.0], [320.0, 240.0], [100.0, 400.0]])
    back = project_directions(CAMERA, pose, lens, pixel_directions(CAMERA, pose, lens, pixels))
    np.testing.assert_allclose(back, pixels, atol=1e-7)


def test_a_rolled_view_turns_the_scene_about_the_principal_point():
    # A direction 100 px right of the level view's centre, rolled 30 deg: (100 cos 30, 100 sin 30) px off.
    focal_px = POSE[2] * CAMERA.f_min_px
    direction = camera_directions(POSE, [[100.0 / focal_px, 0.0]])
    pixel = project_directions(CAMERA, POSE, Lens(roll_deg=30.0), direction)[0]
    np.testing.assert_allclose(pixel, CENTRE + [100.0 * np.cos(np.pi / 6), 100.0 * np.sin(np.pi / 6)], atol=1e-9)
    # The optical axis stays at the principal point: pan and tilt are untouched by the roll.
    axis = camera_directions(POSE, [[0.0, 0.0]])
    np.testing.assert_allclose(project_directions(CAMERA, POSE, Lens(roll_deg=30.0), axis)[0], CENTRE, atol=1e-9)


def test_an_offset_principal_point_shifts_every_pixel_and_distortion_scales_the_radius():
    focal_px = POSE[2] * CAMERA.f_min_px
    normalised = np.array([[0.3, 0.4], [-0.1, 0.0]])
    directions = camera_directions(POSE, normalised)
    shifted = project_directions(CAMERA, POSE, Lens(principal_offset_px=(7.0, -3.0)), directions)
    np.testing.assert_allclose(shifted, CENTRE + focal_px * normalised + [7.0, -3.0], atol=1e-9)
    # Radius 0.5 with k1 -0.2: 0.5 (1 - 0.2 * 0.25) = 0.475; radius 0.1: 0.1 (1 - 0.002).
    distorted = project_directions(CAMERA, POSE, Lens(k1=-0.2), directions)
    np.testing.assert_allclose(distorted, CENTRE + focal_px * normalised * [[0.95], [0.998]], atol=1e-9)


@settings(max_examples=100, deadline=None)
@given(k1=st.floats(-0.3, 0.3), x=st.floats(-0.6, 0.6), y=st.floats(-0.6, 0.6))
def test_undistortion_inverts_the_distortion(k1, x, y):
    normalised = np.array([[x, y]])
    distorted = normalised * (1.0 + k1 * (x * x + y * y))
    np.testing.assert_allclose(undistort_normalised(distorted, k1), normalised, atol=1e-9)


def test_directions_behind_the_view_have_no_pixel():
    behind = -camera_directions(POSE, [[0.0, 0.0]])
    assert np.isnan(project_directions(CAMERA, POSE, Lens(k1=-0.1), behind)).all()
    assert project_directions(CAMERA, POSE, Lens(), np.zeros((0, 3))).shape == (0, 2)


@pytest.mark.parametrize("roll_deg", [-2.0, 2.0])
def test_the_roll_sign_follows_the_docstring(roll_deg):
    # Positive roll: the scene turns from the image's x axis towards its y axis (down on the screen).
    direction = camera_directions(POSE, [[0.1, 0.0]])
    pixel = project_directions(CAMERA, POSE, Lens(roll_deg=roll_deg), direction)[0]
    assert np.sign(pixel[1] - CENTRE[1]) == np.sign(roll_deg)


def test_barrel_distortion_is_invertible_only_while_it_reaches_the_corner():
    radius2 = 0.8**2
    limit = -4.0 / 27.0 / radius2
    assert distortion_invertible(0.9 * limit, radius2) and distortion_invertible(0.5, radius2)
    corner = np.array([[0.8, 0.0]])
    undistorted = undistort_normalised(corner, 0.9 * limit)
    np.testing.assert_allclose(undistorted * (1 + 0.9 * limit * (undistorted**2).sum()), corner, atol=1e-10)
    # A little more barrel than the limit and no radius reaches the corner: r (1 + k1 r^2) peaks below 0.8.
    assert not distortion_invertible(1.05 * limit, radius2)
    radii = np.linspace(0.0, 3.0, 3001)
    assert (radii * (1 + 1.05 * limit * radii**2)).max() < 0.8
