"""A PTZ camera's geometry from its own pictures, no pattern (Sinha and Pollefeys, "Pan-tilt-zoom camera
calibration and high-resolution mosaic generation", CVIU 2006).

* **The widest focal length, from rotations.** A camera turning about its optical centre maps the
  pixels of one view onto another by ``H = K R K^-1`` with ``K = [[f, 0, c_x], [0, f, c_y], [0, 0, 1]]``
  (the principal point at the image centre). A PTZ head's turns by normalised steps are rotations of
  four numbers (:func:`fit_head`): ``f``, the pan's and the tilt's degrees per step, and the view's
  depression. Only the perspective part of ``H`` tells ``f`` from a turn's angle (a point at ``x``
  from the centre moves by ``f tan(atan(x / f) + theta) - x``, ``theta (f + x^2 / f)`` to second
  order), so the turns are made a good fraction of the view wide. The standard deviations are the
  Gauss-Newton ones, ``sigma^2 (J^T J)^-1`` at the optimum.
* **The focal length at every zoom, from homologies.** At a fixed pan and tilt a zoom maps view ``a``
  onto view ``b`` by ``p_b - c = s (p_a - c) + t`` (``s = f_b / f_a``; ``t`` the lens's axis drifting
  with the zoom), fitted by least squares on RANSAC's inliers; from the widest view's, the focal
  lengths follow from the scales between neighbouring steps and between steps two apart by weighted
  least squares in ``log f``.
* **The ground, from four points or more.** Pixels of ground points of known (x, y) metres in one view
  of known focal length give the camera's rotation and centre by planar PnP (OpenCV's IPPE, both of its
  solutions tried, the one that puts the camera above the ground and the points in front, refined by
  Levenberg-Marquardt): the centre ``-R^T t`` is the camera's position and height, the optical axis its
  pan (bearing from +y towards +x) and tilt (depression), and what is left of ``R`` its roll, the mount's
  lean. The model's mount is level, so the position, pan and tilt are then fitted again without roll
  (five parameters, least squares of the reprojection error), which a few noisy points pin better.

Pixels are in the model's convention: the picture's top left corner at (0, 0), pixel (row, col)'s
centre at (col + 0.5, row + 0.5).
"""

import itertools
from dataclasses import dataclass

import cv2
import numpy as np
from scipy.optimize import least_squares

from ptztrack.geometry.ptz import rotation_world_to_camera
from ptztrack.geometry.registration import (
    MIN_INLIERS,
    RANSAC_THRESHOLD_PX,
    pose_from_rotation,
    ratio_matches,
    sift_features,
)

# Features per picture for matching two views of the calibration.
CALIBRATION_FEATURES = 2000
# A pair of views whose matches the fitted head carries no nearer than this (median, px) was matched
# wrongly: it is left out of the fit.
OUTLYING_PAIR_PX = 2.0
# Ground points whose spread across their second direction is below this fraction of the first lie on
# one line: the ground's pose is then not pinned.
COLLINEAR_RATIO = 0.05
# ECC's zoom scale: at most this many iterations; kept where the warped views correlate at least this
# well (a uniform picture does not correlate at all); its standard deviation, a fraction of the scale:
# about ECC's largest error between views of a still recording at long zooms (docs: decisions).
ECC_ITERATIONS, ECC_MIN_CORRELATION, ECC_RATIO_SD = 200, 0.9, 0.003


@dataclass(frozen=True)
class GroundPose:
    """The camera's pose on the ground: position_m (3,) its optical centre (x, y, height), pan_deg,
    tilt_deg (the model's, on a level mount), roll_deg (the roll about the optical axis that the points
    show when it is let free), residuals_px (N,) each ground point's reprojection error on the level mount,
    focal_px the focal length of the fit (the one given, or refined by the points)."""

    position_m: np.ndarray
    pan_deg: float
    tilt_deg: float
    roll_deg: float
    residuals_px: np.ndarray
    focal_px: float

    @property
    def rms_px(self) -> float:
        return float(np.sqrt(np.mean(self.residuals_px**2)))


def view_features(image_bgr: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A calibration view's SIFT keypoints (K, 2) px and descriptors (K, 128), extracted once per view."""
    return sift_features(image_bgr, CALIBRATION_FEATURES)


def matched_points(features_a, features_b) -> tuple[np.ndarray, np.ndarray]:
    """Correspondences (M, 2) and (M, 2) of two views given their :func:`view_features`: Lowe's ratio test
    and a RANSAC homography's inliers (within ``RANSAC_THRESHOLD_PX``); empty (0, 2) arrays when fewer than
    ``MIN_INLIERS`` agree."""
    (keypoints_a, descriptors_a), (keypoints_b, descriptors_b) = features_a, features_b
    pairs = ratio_matches(descriptors_a, descriptors_b)
    empty = np.zeros((0, 2)), np.zeros((0, 2))
    if len(pairs) < MIN_INLIERS:
        return empty
    points_a, points_b = keypoints_a[pairs[:, 0]], keypoints_b[pairs[:, 1]]
    _, inliers = cv2.findHomography(points_a, points_b, cv2.RANSAC, RANSAC_THRESHOLD_PX)
    if inliers is None or inliers.sum() < MIN_INLIERS:
        return empty
    keep = inliers.ravel().astype(bool)
    return points_a[keep], points_b[keep]


@dataclass(frozen=True)
class HeadFit:
    """The widest focal length and the head's mapping, from turns by known normalised steps.

    focal_px, focal_sd_px : the focal length and its standard deviation; pan_deg_per_unit,
    tilt_deg_per_unit : the model's pan and tilt (depression) degrees per unit of the normalised
    translation (signed); tilt_deg : the view's depression; rms_px : the residuals' root mean square;
    pairs : the pairs of views fitted (those left out as outlying not counted).
    """

    focal_px: float
    focal_sd_px: float
    pan_deg_per_unit: float
    tilt_deg_per_unit: float
    tilt_deg: float
    rms_px: float
    pairs: int


def fit_head(
    matches: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]],
    image_size_px: tuple[int, int],
    initial_deg_per_unit: tuple[float, float],
    focal_guess_px: float,
) -> HeadFit:
    """The focal length and the head's mapping that carry every match best: ``matches`` of
    (step_a (2,), step_b (2,), points_a (M, 2), points_b (M, 2)) between views at the normalised steps
    step_a and step_b (pan, tilt) from one view.

    A PTZ head pans about the vertical and tilts about the camera's horizontal axis, each by degrees
    proportional to the normalised step (``pan = a dx``, ``tilt = b dy``). The view at step (dx, dy) is
    the model's rotation ``R(a dx, t + b dy)`` (:func:`ptztrack.geometry.ptz.rotation_world_to_camera`;
    the first view's pan taken as 0, its depression ``t``), and views a and b map pixels by
    ``K R_b R_a^T K^-1``. So four numbers, ``f``, ``a``, ``b`` and ``t``, explain every match (soft L1 of
    the reprojection error, 1 px; the search starts from depressions of -30, 0, 30 and 60 deg and focal
    lengths of 0.7 to 2 times the guess, the best kept), where a free rotation per pair would need three
    more each: the focal length, which shows only in the turns' perspective, is pinned several times
    better.
    """
    steps_a = np.array([match[0] for match in matches], dtype=float).reshape(-1, 2)
    steps_b = np.array([match[1] for match in matches], dtype=float).reshape(-1, 2)
    centre = np.array(image_size_px, dtype=float) / 2.0
    centred = [(match[2] - centre, match[3] - centre) for match in matches]

    def residuals(parameters: np.ndarray) -> np.ndarray:
        focal_px, pan_per_unit, tilt_per_unit, tilt_deg = np.exp(parameters[0]), *parameters[1:]
        views_a, views_b = (
            rotation_world_to_camera(pan_per_unit * steps[:, 0], tilt_deg + tilt_per_unit * steps[:, 1])
            for steps in (steps_a, steps_b)
        )
        parts = []
        for rotation, (a, b) in zip(views_b @ np.swapaxes(views_a, -1, -2), centred, strict=True):
            rays = np.c_[a / focal_px, np.ones(len(a))] @ rotation.T
            parts.append((focal_px * rays[:, :2] / rays[:, 2:] - b).ravel())
        return np.concatenate(parts)

    best = None
    for tilt_deg, focal_scale in itertools.product((-30.0, 0.0, 30.0, 60.0), (0.7, 1.0, 1.4, 2.0)):
        # A focal length and turns' angles that trade against each other: the guess's angles scaled to match.
        per_unit = np.asarray(initial_deg_per_unit) / focal_scale
        start = np.r_[np.log(focal_scale * focal_guess_px), per_unit, tilt_deg]
        result = least_squares(residuals, start, loss="soft_l1", f_scale=1.0, x_scale=[0.1, 1.0, 1.0, 1.0])
        if best is None or result.cost < best.cost:
            best = result
    assert best is not None
    # A pair whose views RANSAC matched wrongly (repeated texture, a crowd) fits no head: left out, refitted.
    sizes = [len(match[2]) for match in matches]
    errors_px = np.linalg.norm(best.fun.reshape(-1, 2), axis=1)
    pair_errors_px = np.array([np.median(part) for part in np.split(errors_px, np.cumsum(sizes)[:-1])])
    if np.any(pair_errors_px > OUTLYING_PAIR_PX) and np.any(pair_errors_px <= OUTLYING_PAIR_PX):
        kept = [match for match, error in zip(matches, pair_errors_px, strict=True) if error <= OUTLYING_PAIR_PX]
        return fit_head(kept, image_size_px, initial_deg_per_unit, focal_guess_px)
    dof = max(len(best.fun) - len(best.x), 1)
    covariance = float(np.sum(best.fun**2) / dof) * np.linalg.pinv(best.jac.T @ best.jac)
    focal_px = float(np.exp(best.x[0]))
    return HeadFit(
        focal_px=focal_px,
        focal_sd_px=focal_px * float(np.sqrt(max(covariance[0, 0], 0.0))),
        pan_deg_per_unit=float(best.x[1]),
        tilt_deg_per_unit=float(best.x[2]),
        tilt_deg=float(best.x[3]),
        rms_px=float(np.sqrt(np.mean(best.fun**2))),
        pairs=len(matches),
    )


def zoom_ratio(points_a: np.ndarray, points_b: np.ndarray, image_size_px: tuple[int, int]) -> tuple[float, float]:
    """The homology's scale ``s = f_b / f_a`` between two views at one pan and tilt, and its standard
    deviation: least squares of ``p_b - c = s (p_a - c) + t`` over the matches (M, 2), (M, 2)."""
    centre = np.array(image_size_px, dtype=float) / 2.0
    a, b = points_a - centre, points_b - centre
    design = np.zeros((2 * len(a), 3))
    design[0::2, 0], design[1::2, 0] = a[:, 0], a[:, 1]
    design[0::2, 1], design[1::2, 2] = 1.0, 1.0
    solution, *_ = np.linalg.lstsq(design, b.ravel(), rcond=None)
    fitted = design @ solution - b.ravel()
    sigma2 = float(fitted @ fitted / max(len(fitted) - 3, 1))
    covariance = sigma2 * np.linalg.inv(design.T @ design)
    return float(solution[0]), float(np.sqrt(covariance[0, 0]))


def ecc_zoom_ratio(image_a: np.ndarray, image_b: np.ndarray, predicted: float) -> float | None:
    """The zoom's scale ``s = f_b / f_a`` between two views (h, w, 3) at one pan and tilt from their
    intensities (``cv2.findTransformECC``, an affine warp from ``b``'s pixels to ``a``'s started at the
    homology ``p_a - c = (p_b - c) / predicted``): ``1 / sqrt(|det A|)`` of the warp's linear part; None
    where ECC does not converge or its correlation is below ``ECC_MIN_CORRELATION``. For views whose
    features SIFT cannot match (a long zoom's blur, a stream's compression)."""
    gray_a, gray_b = (cv2.cvtColor(image, cv2.COLOR_BGR2GRAY).astype(np.float32) for image in (image_a, image_b))
    centre = np.array(gray_a.shape[::-1], dtype=float) / 2.0 - 0.5  # OpenCV's pixel centres are integers
    inverse = 1.0 / predicted
    warp = np.array([[inverse, 0.0, 0.0], [0.0, inverse, 0.0]], dtype=np.float32)
    warp[:, 2] = centre * (1.0 - inverse)
    criteria = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, ECC_ITERATIONS, 1e-7)
    try:
        correlation, warp = cv2.findTransformECC(gray_b, gray_a, warp, cv2.MOTION_AFFINE, criteria, None, 5)
    except cv2.error:
        return None
    if not correlation >= ECC_MIN_CORRELATION:
        return None
    return float(1.0 / np.sqrt(abs(np.linalg.det(warp[:, :2]))))


def focals_from_ratios(
    widest_px: float, widest_sd_px: float, steps: int, ratios: list[tuple[int, int, float, float]]
) -> tuple[np.ndarray, np.ndarray]:
    """The focal lengths (steps + 1,) of zoom steps 0 (the widest) to ``steps`` from homology scales
    ``(i, j, s_ij, sd_ij)`` between steps i < j, and their standard deviations: weighted least squares of
    ``log f_j - log f_i = log s_ij`` (each of weight ``(s_ij / sd_ij)^2``) with ``log f_0 = log widest_px``;
    the widest's relative variance adds to every step's. Scales over two steps as well as one keep the
    chain's small biases from adding up step after step."""
    design = np.zeros((len(ratios), steps))
    observed, weights = np.zeros(len(ratios)), np.zeros(len(ratios))
    for row, (i, j, ratio, ratio_sd) in enumerate(ratios):
        if i > 0:
            design[row, i - 1] = -1.0
        design[row, j - 1] = 1.0
        observed[row], weights[row] = np.log(ratio), (ratio / max(ratio_sd, 1e-6)) ** 2
    normal = design.T @ (weights[:, None] * design)
    log_ratios = np.linalg.solve(normal, design.T @ (weights * observed))
    covariance = np.linalg.inv(normal)
    focals = widest_px * np.exp(np.r_[0.0, log_ratios])
    relative_variance = (widest_sd_px / widest_px) ** 2 + np.r_[0.0, np.diag(covariance)]
    return focals, focals * np.sqrt(relative_variance)


def ground_points_problem(pixels_px, ground_m, image_size_px: tuple[int, int] | None) -> str | None:
    """What makes ground points (N, 2) px and (N, 2) m unusable to place a camera, in a few words (fewer
    than four, not finite, a pixel outside an ``image_size_px`` (width, height) picture where given, two
    at one place, on one line); None if nothing."""
    pixels_px, ground_m = np.asarray(pixels_px, dtype=float), np.asarray(ground_m, dtype=float)
    if pixels_px.shape != ground_m.shape or pixels_px.ndim != 2 or pixels_px.shape[1:] != (2,):
        return "expected as many pixel (u, v) as ground (x, y) points"
    if len(pixels_px) < 4:
        return f"{len(pixels_px)} ground points: at least 4 are needed"
    if not (np.all(np.isfinite(pixels_px)) and np.all(np.isfinite(ground_m))):
        return "a ground point is not finite"
    width_px, height_px = (np.inf, np.inf) if image_size_px is None else image_size_px
    outside = np.flatnonzero(
        (pixels_px[:, 0] < 0) | (pixels_px[:, 0] > width_px) | (pixels_px[:, 1] < 0) | (pixels_px[:, 1] > height_px)
    )
    if len(outside) and image_size_px is None:
        return f"point {outside[0] + 1}'s pixel is negative: pixels count from the picture's top left corner"
    if len(outside):
        u, v = pixels_px[outside[0]]
        return f"point {outside[0] + 1}'s pixel ({u:g}, {v:g}) is outside the {width_px}x{height_px} px picture"
    for name, points in (("ground", ground_m), ("pixel", pixels_px)):
        distances = np.linalg.norm(points[:, None] - points[None, :], axis=-1)[np.triu_indices(len(points), 1)]
        if distances.min() == 0:
            return f"two points share their {name} position"
        spread = np.linalg.svd(points - points.mean(axis=0), compute_uv=False)
        if spread[1] < COLLINEAR_RATIO * spread[0]:
            return f"the points' {name} positions lie on one line: spread them over the ground"
    return None


def ground_pose(
    pixels_px,
    ground_m,
    focal_px: float,
    image_size_px: tuple[int, int],
    focal_sd_px: float = 0.0,
    pixel_sd_px: float = 1.0,
) -> GroundPose:
    """The camera's pose from ground points (the module's third part): pixels (N, 2) of ground points
    (N, 2) m (on z = 0) in a view of focal length ``focal_px``, the principal point at the centre of an
    ``image_size_px`` (width, height) picture. With ``focal_sd_px`` the level fit frees the focal length
    too, under its measurement as a prior: residuals ``(p - pi(X)) / pixel_sd_px`` and
    ``(log f - log focal_px) / (focal_sd_px / focal_px)``, so that the points' perspective, which also
    tells the focal length, refines it. Raises ValueError when no solution puts the camera above the
    ground with the points in front of it."""
    pixels_px, ground_m = np.asarray(pixels_px, dtype=float), np.asarray(ground_m, dtype=float)
    K = np.array([[focal_px, 0, image_size_px[0] / 2.0], [0, focal_px, image_size_px[1] / 2.0], [0, 0, 1.0]])
    object_points = np.c_[ground_m, np.zeros(len(ground_m))]
    # K's principal point is in the model's pixel convention, as are the points: OpenCV's is not needed.
    image_points = np.ascontiguousarray(pixels_px).reshape(-1, 1, 2)
    count, rotations, translations, _ = cv2.solvePnPGeneric(
        object_points, image_points, K, None, flags=cv2.SOLVEPNP_IPPE
    )
    best = None
    for rvec, tvec in zip(rotations[:count], translations[:count], strict=True):
        rvec, tvec = cv2.solvePnPRefineLM(object_points, image_points, K, None, rvec.copy(), tvec.copy())
        R = cv2.Rodrigues(rvec)[0]
        centre_m = -R.T @ tvec.ravel()
        in_front = np.all((object_points @ R.T + tvec.ravel())[:, 2] > 0)
        projected, _ = cv2.projectPoints(object_points, rvec, tvec, K, None)
        errors_px = np.linalg.norm(projected[:, 0, :] - image_points[:, 0, :], axis=1)
        if centre_m[2] > 0 and in_front and (best is None or errors_px.mean() < best[2].mean()):
            best = (R, centre_m, errors_px)
    if best is None:
        raise ValueError("no camera pose puts the camera above the ground with every point in front of it")
    R, centre_m, _ = best
    pan_deg, tilt_deg = pose_from_rotation(R)
    rolled = R @ rotation_world_to_camera(pan_deg, tilt_deg).T
    roll_deg = float(np.rad2deg(np.arctan2(rolled[1, 0], rolled[0, 0])))

    def reprojected(level: np.ndarray) -> np.ndarray:
        camera_points = (object_points - level[:3]) @ rotation_world_to_camera(level[3], level[4]).T
        projected = np.exp(level[5]) * camera_points[:, :2] / camera_points[:, 2:] + K[:2, 2]
        return (projected - image_points[:, 0, :]).ravel()

    def level_residuals(level: np.ndarray) -> np.ndarray:
        prior = (level[5] - np.log(focal_px)) * focal_px / focal_sd_px if focal_sd_px > 0 else 0.0
        return np.r_[reprojected(level) / pixel_sd_px, prior]

    start = np.r_[centre_m, pan_deg, tilt_deg, np.log(focal_px)]
    if focal_sd_px > 0:
        level = least_squares(level_residuals, start, xtol=1e-12, ftol=1e-12, gtol=1e-12).x
    else:
        fixed = least_squares(
            lambda free: reprojected(np.r_[free, start[5]]), start[:5], xtol=1e-12, ftol=1e-12, gtol=1e-12
        )
        level = np.r_[fixed.x, start[5]]
    errors = np.linalg.norm(reprojected(level).reshape(-1, 2), axis=1)
    return GroundPose(level[:3], float(level[3]), float(level[4]), roll_deg, errors, float(np.exp(level[5])))
