"""Calibration formats of recorded cameras: Tsai (PETS 2009 XML) and pinhole with OpenCV distortion (JSON).

Both map world points in millimetres (ground plane z = 0) to pixels of the
recorded image. A malformed file gets a :class:`CalibrationError` naming the
file and what is wrong.
"""

from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from ptztrack.files import InputError, read_json, read_xml_root, shown
from ptztrack.geometry.lens import UNDISTORT_CRITERIA

NEWTON_STEPS = 20
MAX_IMAGE_SIDE_PX = 8192
CALIBRATION_MAX_BYTES = 10_000_000
"""A calibration file's size limit: PETS's are 1-3 kB."""


class CalibrationError(InputError):
    """A calibration file that cannot be used; the message names the file and the problem."""


@dataclass(frozen=True)
class TsaiCalibration:
    """Tsai's camera model (R. Tsai 1987, as in R. Willson's reference implementation).

    image_size_px : (width, height).
    dpx_mm, dy_mm : effective pixel pitch along x and y on the sensor.
    focal_mm, kappa1 : focal length and first radial distortion coefficient (1/mm^2).
    centre_px : (Cx, Cy) image centre; sx : horizontal scale factor.
    rotation_xyz_rad : (Rx, Ry, Rz), the world-to-camera rotation R = Rz Ry Rx.
    translation_mm : (Tx, Ty, Tz), camera = R world + T.
    """

    image_size_px: tuple[int, int]
    dpx_mm: float
    dy_mm: float
    focal_mm: float
    kappa1: float
    centre_px: tuple[float, float]
    sx: float
    rotation_xyz_rad: tuple[float, float, float]
    translation_mm: tuple[float, float, float]

    @property
    def rotation(self) -> np.ndarray:
        rx, ry, rz = self.rotation_xyz_rad
        cx, sx, cy, sy, cz, sz = np.cos(rx), np.sin(rx), np.cos(ry), np.sin(ry), np.cos(rz), np.sin(rz)
        Rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
        Ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
        Rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
        return Rz @ Ry @ Rx


@dataclass(frozen=True)
class PinholeCalibration:
    """A pinhole camera with OpenCV's distortion model.

    K : (3, 3) intrinsics in pixels; dist : (5,) k1 k2 p1 p2 k3;
    R : (3, 3) world-to-camera rotation; t : (3,) translation in mm.
    """

    K: np.ndarray
    dist: np.ndarray
    R: np.ndarray
    t: np.ndarray


def camera_centre_m(calibration: PinholeCalibration) -> np.ndarray:
    """The camera's centre (3,) m in the world: -R^T t, t in mm."""
    return -calibration.R.T @ calibration.t / 1000.0


def aimed_pinhole(centre_m, target_m, focal_px: float, image_size_px) -> PinholeCalibration:
    """A distortion-free pinhole camera at ``centre_m`` (x, y, z) m whose optical axis points at
    ``target_m`` ((x, y) on the ground, or (x, y, z)) m, with no roll (the image's x axis level with
    the ground), focal length ``focal_px``, and its principal point at the centre of its image
    ``image_size_px`` (width, height). A camera looking straight down has the world's x axis as its
    image's x axis. t is in mm, as the calibration files have it."""
    centre_m = np.asarray(centre_m, dtype=float)
    target_m = np.asarray(target_m, dtype=float)
    if target_m.shape == (2,):
        target_m = np.append(target_m, 0.0)
    forward = target_m - centre_m
    if not np.linalg.norm(forward) > 0:
        raise ValueError(f"the camera at {centre_m.tolist()} m cannot look at its own centre")
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    if np.linalg.norm(right) < 1e-9:  # straight down (or up)
        right = np.array([1.0, 0.0, 0.0])
    right /= np.linalg.norm(right)
    R = np.stack([right, np.cross(forward, right), forward])
    width_px, height_px = image_size_px
    K = np.array([[focal_px, 0.0, width_px / 2], [0.0, focal_px, height_px / 2], [0.0, 0.0, 1.0]])
    return PinholeCalibration(K=K, dist=np.zeros(5), R=R, t=-R @ centre_m * 1000.0)


def project_tsai(calibration: TsaiCalibration, points_mm) -> np.ndarray:
    """World points (N, 3) mm to distorted image pixels (N, 2).

    The undistorted sensor radius ``r_u`` relates to the distorted one by
    ``r_u = r_d (1 + kappa1 r_d^2)``; going from world to image means solving
    that cubic for ``r_d``, done by Newton's method from ``r_d = r_u``.
    """
    camera_mm = np.asarray(points_mm, dtype=float) @ calibration.rotation.T + np.asarray(calibration.translation_mm)
    undistorted = calibration.focal_mm * camera_mm[:, :2] / camera_mm[:, 2:]
    radius_u = np.linalg.norm(undistorted, axis=1)
    radius_d = radius_u.copy()
    for _ in range(NEWTON_STEPS):
        radius_d -= (calibration.kappa1 * radius_d**3 + radius_d - radius_u) / (
            3 * calibration.kappa1 * radius_d**2 + 1
        )
    scale = np.divide(radius_d, radius_u, out=np.ones_like(radius_u), where=radius_u > 0)
    distorted = undistorted * scale[:, None]
    u = calibration.sx * distorted[:, 0] / calibration.dpx_mm + calibration.centre_px[0]
    v = distorted[:, 1] / calibration.dy_mm + calibration.centre_px[1]
    return np.stack([u, v], axis=-1)


def project_pinhole(calibration: PinholeCalibration, points_mm) -> np.ndarray:
    """World points (N, 3) mm to distorted image pixels (N, 2), with ``cv2.projectPoints``."""
    if len(np.asarray(points_mm).reshape(-1, 3)) == 0:
        return np.zeros((0, 2))  # cv2.projectPoints gives None for no points
    rotation_vector, _ = cv2.Rodrigues(calibration.R)
    pixels, _ = cv2.projectPoints(
        np.asarray(points_mm, dtype=float).reshape(-1, 1, 3),
        rotation_vector,
        calibration.t,
        calibration.K,
        calibration.dist,
    )
    return pixels[:, 0, :]


def pixel_rays(calibration: PinholeCalibration, pixels_px) -> tuple[np.ndarray, np.ndarray]:
    """The rays through pixels: the camera centre (3,) and unit directions (N, 3), in metres.

    pixels_px : (N, 2) distorted image coordinates (the centre of pixel (i, j) at (i + 0.5, j + 0.5),
    as the calibrations map world points). ``cv2.undistortPointsIter`` inverts the distortion, iterated
    until the point distorts back to within 1e-10 px or for at most 100 steps
    (:data:`~ptztrack.geometry.lens.UNDISTORT_CRITERIA`); the calibration's millimetres become
    ptztrack's metres.
    """
    # Not cv2.undistortPoints: its fixed 5 steps leave a strong distortion (PETS View_007's) far
    # from converged.
    pixels = np.asarray(pixels_px, dtype=float).reshape(-1, 1, 2)
    if len(pixels):
        normalised = cv2.undistortPointsIter(pixels, calibration.K, calibration.dist, None, None, UNDISTORT_CRITERIA)[
            :, 0, :
        ]
    else:
        normalised = np.zeros((0, 2))
    in_camera = np.concatenate([normalised, np.ones((len(normalised), 1))], axis=-1)
    direction = in_camera @ calibration.R  # R^T d for each row d
    return camera_centre_m(calibration), direction / np.linalg.norm(direction, axis=-1, keepdims=True)


def imaged_radius(calibration: PinholeCalibration) -> float:
    """The largest normalised undistorted radius that the calibration's distortion maps outwards.

    A point at (x, y, z) in the camera frame has the radius r = |(x, y)| / z; OpenCV's radial
    distortion moves it to r (1 + k1 r^2 + k2 r^4 + k3 r^6). That grows with r up to the smallest
    r > 0 where its derivative 1 + 3 k1 r^2 + 5 k2 r^4 + 7 k3 r^6 vanishes (a cubic in r^2), and
    folds back beyond it, where a point far outside the field of view would be projected into
    the image. Returns that r (dimensionless), infinite where the polynomial never folds (no
    distortion). The tangential terms are ignored (zero in Tsai's model and the room's).
    """
    k1, k2, _, _, k3 = np.asarray(calibration.dist, dtype=float)
    # np.roots drops leading zero coefficients: a lower-degree polynomial, or none at all.
    squares = np.roots([7 * k3, 5 * k2, 3 * k1, 1.0])
    real = squares.real[(np.abs(squares.imag) < 1e-12) & (squares.real > 0)]
    return float(np.sqrt(real.min())) if len(real) else float("inf")


def in_image(calibration: PinholeCalibration, image_size_px, points_mm) -> np.ndarray:
    """Whether the camera sees world points (N, 3) mm: (N,) bool.

    Seen means in front of the camera (depth above 0), within the radius the distortion maps
    outwards (:func:`imaged_radius`) and projected into the image [0, width) x [0, height) px,
    image_size_px being (width, height).
    """
    points_mm = np.asarray(points_mm, dtype=float).reshape(-1, 3)
    camera_mm = points_mm @ calibration.R.T + calibration.t
    depth_mm = camera_mm[:, 2]
    ahead = depth_mm > 0
    radius = np.hypot(camera_mm[:, 0], camera_mm[:, 1]) / np.where(ahead, depth_mm, 1.0)
    seen = ahead & (radius < imaged_radius(calibration))
    pixels = np.full((len(points_mm), 2), -1.0)
    if np.any(seen):
        pixels[seen] = project_pinhole(calibration, points_mm[seen])
    width_px, height_px = image_size_px
    inside = (pixels[:, 0] >= 0) & (pixels[:, 0] < width_px) & (pixels[:, 1] >= 0) & (pixels[:, 1] < height_px)
    return seen & inside


def standing_height_px(calibration: PinholeCalibration, feet_px, height_m: float) -> np.ndarray:
    """The image height (N,) px of a person ``height_m`` tall standing on feet pixels (N, 2) of the
    calibrated (distorted) image: the feet's ray meets the ground, the head above it is projected back.
    NaN where the ray does not reach the ground ahead of the camera."""
    centre_m, directions = pixel_rays(calibration, feet_px)
    with np.errstate(divide="ignore", invalid="ignore"):
        distance_m = -centre_m[2] / directions[:, 2]
    ahead = distance_m > 0
    feet_m = centre_m + np.where(ahead, distance_m, 1.0)[:, None] * directions
    head_m = feet_m + [0.0, 0.0, height_m]
    head_px = project_pinhole(calibration, 1000.0 * head_m)
    height_px = np.linalg.norm(np.asarray(feet_px, dtype=float) - head_px, axis=-1)
    return np.where(ahead, height_px, np.nan)


def pinhole_from_tsai(calibration: TsaiCalibration) -> PinholeCalibration:
    """The pinhole camera with OpenCV distortion that projects like a Tsai camera.

    Tsai scales the undistorted sensor point by ``s(r) = r_d / r_u``, the
    same factor in x and y, so OpenCV's radial polynomial
    ``1 + k1 r^2 + k2 r^4 + k3 r^6`` of the normalised undistorted radius
    ``r = r_u / f`` can represent it; the three coefficients are fitted by
    linear least squares out to the image corners (tangential terms zero).
    """
    K = np.array(
        [
            [calibration.focal_mm * calibration.sx / calibration.dpx_mm, 0.0, calibration.centre_px[0]],
            [0.0, calibration.focal_mm / calibration.dy_mm, calibration.centre_px[1]],
            [0.0, 0.0, 1.0],
        ]
    )
    width, height = calibration.image_size_px
    corners_px = np.array([[0, 0], [width, 0], [0, height], [width, height]], dtype=float) - calibration.centre_px
    corner_radius_d_mm = np.hypot(
        corners_px[:, 0] * calibration.dpx_mm / calibration.sx, corners_px[:, 1] * calibration.dy_mm
    )
    radius_d_mm = np.linspace(0.0, corner_radius_d_mm.max(), 200)[1:]
    radius_u_mm = radius_d_mm * (1 + calibration.kappa1 * radius_d_mm**2)
    normalised_radius = radius_u_mm / calibration.focal_mm
    powers = np.stack([normalised_radius**2, normalised_radius**4, normalised_radius**6], axis=-1)
    (k1, k2, k3), *_ = np.linalg.lstsq(powers, radius_d_mm / radius_u_mm - 1.0, rcond=None)
    return PinholeCalibration(
        K=K,
        dist=np.array([k1, k2, 0.0, 0.0, k3]),
        R=calibration.rotation,
        t=np.asarray(calibration.translation_mm, dtype=float),
    )


def load_calibration(path: str | Path, view: str | None = None) -> PinholeCalibration:
    """A recording's calibration as a pinhole camera: a Tsai XML (``.xml``) or one view of a pinhole JSON
    (``view``; None: its only view)."""
    if Path(path).suffix.lower() == ".xml":
        return pinhole_from_tsai(load_tsai(path))
    return load_pinhole(path, view)


def _attributes(root, tag: str, names: tuple[str, ...], path: Path) -> dict[str, float]:
    element = root.find(tag)
    if element is None:
        raise CalibrationError(f"{path}: no <{tag}> element")
    values = {}
    for name in names:
        text = element.get(name)
        if text is None:
            raise CalibrationError(f"{path}: <{tag}> has no attribute {name!r}")
        try:
            values[name] = float(text)
        except ValueError:
            values[name] = float("nan")
        if not np.isfinite(values[name]):
            raise CalibrationError(f"{path}: <{tag} {name}={shown(text)}> is not a finite number")
    return values


def load_tsai(path: str | Path) -> TsaiCalibration:
    """Read a PETS 2009 Tsai calibration XML (``<Geometry>``, ``<Intrinsic>``, ``<Extrinsic>``)."""
    path = Path(path)
    root = read_xml_root(path, "calibration", CALIBRATION_MAX_BYTES, CalibrationError)
    geometry = _attributes(root, "Geometry", ("width", "height", "dy", "dpx"), path)
    intrinsic = _attributes(root, "Intrinsic", ("focal", "kappa1", "cx", "cy", "sx"), path)
    extrinsic = _attributes(root, "Extrinsic", ("tx", "ty", "tz", "rx", "ry", "rz"), path)
    for tag, values, positive in (
        ("Geometry", geometry, ("width", "height", "dy", "dpx")),
        ("Intrinsic", intrinsic, ("focal", "sx")),
    ):
        for name in positive:
            if values[name] <= 0:
                raise CalibrationError(f"{path}: <{tag} {name}={values[name]:g}> must be positive")
    for name in ("width", "height"):
        if geometry[name] != round(geometry[name]) or geometry[name] > MAX_IMAGE_SIDE_PX:
            raise CalibrationError(
                f"{path}: <Geometry {name}={geometry[name]:g}> must be a whole number of pixels, at most "
                f"{MAX_IMAGE_SIDE_PX}"
            )
    return TsaiCalibration(
        image_size_px=(int(geometry["width"]), int(geometry["height"])),
        dpx_mm=geometry["dpx"],
        dy_mm=geometry["dy"],
        focal_mm=intrinsic["focal"],
        kappa1=intrinsic["kappa1"],
        centre_px=(intrinsic["cx"], intrinsic["cy"]),
        sx=intrinsic["sx"],
        rotation_xyz_rad=(extrinsic["rx"], extrinsic["ry"], extrinsic["rz"]),
        translation_mm=(extrinsic["tx"], extrinsic["ty"], extrinsic["tz"]),
    )


def pinhole_document(calibration: PinholeCalibration) -> dict:
    """One view of a pinhole calibration JSON (``{view: {K, dist, R, t}}``, :func:`load_pinhole` reads
    it): {K, dist, R, t [mm]} as lists."""
    return {name: np.asarray(getattr(calibration, name), dtype=float).tolist() for name in ("K", "dist", "R", "t")}


def load_pinhole(path: str | Path, view: str | None = None) -> PinholeCalibration:
    """Read one view of a pinhole calibration JSON (``{view: {K, dist, R, t}}``; None: its only view)."""
    path = Path(path)
    views = read_json(path, "calibration", CALIBRATION_MAX_BYTES, CalibrationError)
    if isinstance(views, dict) and view is None:
        if len(views) != 1:
            raise CalibrationError(
                f"{path}: {len(views)} views ({', '.join(map(str, list(views)[:8]))}); name the one to use"
            )
        view = next(iter(views))
    if not isinstance(views, dict) or view not in views:
        raise CalibrationError(f"{path}: no view {shown(view)}")
    shapes = {"K": (3, 3), "dist": (5,), "R": (3, 3), "t": (3,)}
    arrays = {}
    for name, shape in shapes.items():
        try:
            arrays[name] = np.asarray(views[view][name], dtype=float)
        except (KeyError, TypeError, ValueError):
            raise CalibrationError(f"{path}: {view}.{name} is missing or not numeric") from None
        if arrays[name].shape != shape:
            raise CalibrationError(f"{path}: {view}.{name} has shape {arrays[name].shape}, expected {shape}")
        if not np.all(np.isfinite(arrays[name])):
            raise CalibrationError(f"{path}: {view}.{name} has a NaN or infinite entry, expected finite numbers")
    K, R = arrays["K"], arrays["R"]
    if K[0, 0] <= 0 or K[1, 1] <= 0 or not np.allclose(K[2], [0, 0, 1]):
        raise CalibrationError(f"{path}: {view}.K must have positive focal lengths and a last row [0, 0, 1]")
    if not np.allclose(R @ R.T, np.eye(3), atol=1e-4) or np.linalg.det(R) < 0:
        raise CalibrationError(f"{path}: {view}.R is not a rotation matrix (orthonormal, determinant 1)")
    return PinholeCalibration(**arrays)
