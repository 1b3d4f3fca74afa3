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

import cv2
import numpy as np

from ptztrack.geometry.ptz import PTZCamera, intrinsics, rotation_world_to_camera

# OpenCV's iterative undistortion (cv2.undistortPointsIter): fixed-point steps until the undistorted
# point distorts back to within 1e-10 of the given one (pixels; normalised units without a camera
# matrix). A step shrinks the error by about 2 |k1| r^2 / (1 + k1 r^2): a few steps for the live
# views (|k1| r^2 < 0.03 at the PETS registered view's corner), a few dozen near k1 r^2 = -4/27, the
# barrel distortion's limit (see distortion_invertible).
UNDISTORT_CRITERIA = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-10)


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


def lens_intrinsics(camera: PTZCamera, pose, lens: Lens) -> np.ndarray:
    """(3, 3) intrinsic matrix of the view at ``pose`` with ``lens``'s principal point offset."""
    K = intrinsics(camera, pose[2])
    K[:2, 2] += lens.principal_offset_px
    return K


def distortion_coefficients(lens: Lens) -> np.ndarray:
    """OpenCV's distortion coefficients (k1, k2, p1, p2) of ``lens``: its first radial term alone."""
    return np.array([lens.k1, 0.0, 0.0, 0.0])


def project_directions(camera: PTZCamera, pose, lens: Lens, directions) -> np.ndarray:
    """Pixels (N, 2) of world directions (N, 3) in the view at ``pose`` through ``lens``
    (``cv2.projectPoints``); NaN behind it."""
    directions = np.asarray(directions, dtype=float).reshape(-1, 3)
    if len(directions) == 0:
        return np.zeros((0, 2))
    rotation = lens_rotation(pose, lens)
    pixels = cv2.projectPoints(
        directions.reshape(-1, 1, 3),
        cv2.Rodrigues(rotation)[0],
        np.zeros(3),
        lens_intrinsics(camera, pose, lens),
        distortion_coefficients(lens),
    )[0][:, 0, :]
    depth = _rotate(rotation, directions)[:, 2:]
    return np.where(depth > 0, pixels, np.nan)


def corner_radius2(camera: PTZCamera, zoom: float) -> float:
    """Squared normalised radius of the image corner at ``zoom`` (the pinhole's, without distortion)."""
    return float((camera.principal_point_px**2).sum() / (zoom * camera.f_min_px) ** 2)


def distortion_invertible(k1: float, radius2: float) -> bool:
    """Whether every distorted radius up to sqrt(``radius2``) comes from one undistorted radius:
    always for k1 >= 0; for barrel distortion while -k1 radius^2 <= 4/27, beyond which
    r (1 + k1 r^2) turns back (at r = 1 / sqrt(-3 k1)) before it reaches the radius."""
    return k1 >= 0 or -k1 * radius2 <= 4.0 / 27.0


def undistort_normalised(distorted, k1: float) -> np.ndarray:
    """Normalised coordinates (N, 2) whose distortion by ``k1`` gives ``distorted`` (N, 2)
    (``cv2.undistortPointsIter``); the distortion must stay monotonic over the radii asked for
    (see :func:`distortion_invertible`)."""
    distorted = np.asarray(distorted, dtype=float).reshape(-1, 2)
    return _undistort(distorted, np.eye(3), distortion_coefficients(Lens(k1=k1)))


def _undistort(pixels: np.ndarray, K: np.ndarray, coefficients: np.ndarray) -> np.ndarray:
    if len(pixels) == 0:
        return np.zeros((0, 2))
    return cv2.undistortPointsIter(pixels.reshape(-1, 1, 2), K, coefficients, None, None, UNDISTORT_CRITERIA)[:, 0, :]


def pixel_directions(camera: PTZCamera, pose, lens: Lens, pixels) -> np.ndarray:
    """World directions (N, 3) seen at pixels (N, 2) of the view at ``pose`` through ``lens``
    (not normalised; the inverse of :func:`project_directions`)."""
    pixels = np.asarray(pixels, dtype=float).reshape(-1, 2)
    normalised = _undistort(pixels, lens_intrinsics(camera, pose, lens), distortion_coefficients(lens))
    rays = np.c_[normalised, np.ones(len(normalised))]
    return _rotate(lens_rotation(pose, lens).T, rays)
