"""The camera, Hypothesis strategies and helpers shared by the PTZ camera model's property tests.

``CAMERA`` stands at (7.5, -4, 7) m with a 640 x 480 px image and a 400 px focal length at zoom 1;
``CENTRE`` (2,) px is its principal point. Poses are (pan deg, tilt deg, zoom): ``poses`` draws pan -80
to 80, tilt 5 to 80 (down) and zoom 1 to 10, and ``pose_and_ground_points`` a pose with ground points
(m) it sees and their pixels.
"""

import numpy as np
from hypothesis import assume, settings
from hypothesis import strategies as st

from ptztrack.geometry.ptz import PTZCamera, apply_homography, camera_depth_m, image_to_ground

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
