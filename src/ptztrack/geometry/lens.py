"""A real PTZ view's departures from the pinhole model: roll, principal point offset, radial distortion.

The one camera model (:mod:`ptztrack.geometry.ptz`) is a level pinhole whose
principal point is the image centre. A real head's view is rolled about its
optical axis (a mount that is not quite level), its principal point is off
the centre (the lens is not centred on the sensor, and drifts as it zooms),
and its lens bends rays radially (barrel distortion at the wide end). A
:class:`Lens` holds these three for one view; with all three zero it is the
pinhole model exactly.

A world direction ``d`` (from the optical centre) is seen at the camera
direction ``c = R_roll R(pan, tilt) d``, at normalised coordinates
``x = (c_x, c_y) / c_z``, distorted to ``x (1 + k1 |x|^2)`` (OpenCV's first
radial term), at pixel ``f x_d + centre + offset``. ``R_roll`` turns the
camera about its optical axis: with a positive roll the scene turns in the
image by ``roll_deg`` from the x axis towards the y axis (clockwise on the
screen, whose y axis points down). The roll leaves the optical axis, and so
pan and tilt, as they are.
"""

from dataclasses import dataclass

import numpy as np

from ptztrack.geometry.ptz import PTZCamera, rotation_world_to_camera

# Newton steps that invert the radial distortion: from the distorted radius as the first guess, the
# error falls quadratically, below 1e-15 of the radius in 4 steps for distortions of a few percent.
UNDISTORT_STEPS = 8


@dataclass(frozen=True)
class Lens:
    """One view's departures from the pinhole model.

    roll_deg : turn of the image axes about the optical axis.
    principal_offset_px : (dx, dy) of the principal point from the image centre, in the view's pixels.
    k1 : radial distortion of normalised coordinates (negative: barrel).
    """

    roll_deg: float = 0.0
    principal_offset_px: tuple[float, float] = (0.0, 0.0)
    k1: float = 0.0


def roll_rotation(roll_deg: float) -> np.ndarray:
    """(3, 3) rotation of the camera frame about its optical axis (z) by ``roll_deg``."""
    angle = np.deg2rad(roll_deg)
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def lens_rotation(pose, lens: Lens) -> np.ndarray:
    """(3, 3) world-to-camera rotation of a view at ``pose`` (pan_deg, tilt_deg, zoom) with ``lens``'s roll."""
    return roll_rotation(lens.roll_deg) @ rotation_world_to_camera(pose[0], pose[1])


def _rotate(M: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """``vectors @ M.T`` for (N, 3) vectors, summed per vector: a matrix product over all vectors at
    once can round each row differently depending on how many there are."""
    return (vectors[:, None, :] * M[None, :, :]).sum(axis=-1)


def project_directions(camera: PTZCamera, pose, lens: Lens, directions) -> np.ndarray:
    """Pixels (N, 2) of world directions (N, 3) in the view at ``pose`` through ``lens``; NaN behind it."""
    directions = np.asarray(directions, dtype=float).reshape(-1, 3)
    seen = _rotate(lens_rotation(pose, lens), directions)
    with np.errstate(divide="ignore", invalid="ignore"):
        normalised = seen[:, :2] / seen[:, 2:]
    radius2 = (normalised**2).sum(axis=1, keepdims=True)
    focal_px = pose[2] * camera.f_min_px
    pixels = focal_px * normalised * (1.0 + lens.k1 * radius2) + camera.principal_point_px + lens.principal_offset_px
    return np.where(seen[:, 2:] > 0, pixels, np.nan)


def corner_radius2(camera: PTZCamera, zoom: float) -> float:
    """Squared normalised radius of the image corner at ``zoom`` (the pinhole's, without distortion)."""
    return float((camera.principal_point_px**2).sum() / (zoom * camera.f_min_px) ** 2)


def distortion_invertible(k1: float, radius2: float) -> bool:
    """Whether every distorted radius up to sqrt(``radius2``) comes from one undistorted radius:
    always for k1 >= 0; for barrel distortion while -k1 radius^2 <= 4/27, beyond which
    r (1 + k1 r^2) turns back (at r = 1 / sqrt(-3 k1)) before it reaches the radius."""
    return k1 >= 0 or -k1 * radius2 <= 4.0 / 27.0


def undistort_normalised(distorted, k1: float) -> np.ndarray:
    """Normalised coordinates (N, 2) whose distortion by ``k1`` gives ``distorted`` (N, 2).

    Newton's method on the radius r of r (1 + k1 r^2) = r_d; the distortion must stay monotonic over
    the radii asked for (1 + 3 k1 r^2 > 0).
    """
    distorted = np.asarray(distorted, dtype=float)
    radius_d = np.linalg.norm(distorted, axis=1)
    radius = radius_d.copy()
    for _ in range(UNDISTORT_STEPS):
        radius -= (radius * (1.0 + k1 * radius**2) - radius_d) / (1.0 + 3.0 * k1 * radius**2)
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where(radius_d > 0, radius / radius_d, 1.0)
    return distorted * scale[:, None]


def pixel_directions(camera: PTZCamera, pose, lens: Lens, pixels) -> np.ndarray:
    """World directions (N, 3) seen at pixels (N, 2) of the view at ``pose`` through ``lens``
    (not normalised; the inverse of :func:`project_directions`)."""
    pixels = np.asarray(pixels, dtype=float).reshape(-1, 2)
    focal_px = pose[2] * camera.f_min_px
    distorted = (pixels - camera.principal_point_px - lens.principal_offset_px) / focal_px
    normalised = undistort_normalised(distorted, lens.k1)
    rays = np.c_[normalised, np.ones(len(normalised))]
    return _rotate(lens_rotation(pose, lens).T, rays)
