"""Expected information gain of camera actions about tracked people (paper sections 3.2-4.2).

For an action ``a`` and a track with prediction ``x-, P-``, the observation is
predicted as ``o ~ N(o-, Sigma_o)`` with ``o- = g(x-, a)`` and
``Sigma_o = C_x(a) P- C_x(a)^T + V`` (equation 9). The track is updated only
if it is detected, which happens with probability ``alpha(a)``; then

    I(a) = alpha(a) (H(P-) - H(P+(a))) = alpha(a) * 1/2 log(det Sigma_o / det V)   (equations 4, 7)

because ``det P+ / det P- = det V / det Sigma_o`` for the Kalman update (the
matrix determinant lemma), so no update need be computed. Everything is
vectorised over actions (L) x tracks (n), and for ``smpl`` x samples (M).
"""

import numpy as np
from scipy.stats import norm, qmc

from ptztrack.config import Detector
from ptztrack.control.gaussian_rectangle import gaussian_rectangle_probability
from ptztrack.detect.simulated import occluded_fraction, recall
from ptztrack.geometry.ptz import (
    PTZCamera,
    apply_homography,
    ground_to_image,
    head_from_feet_homology,
    homography_jacobian,
    person_in_view,
    project_people,
)


def predicted_observations(camera: PTZCamera, poses, mean_m, position_cov_m2, V):
    """Equation 9 for every action and track.

    poses : (L, 3); mean_m : (n, 2) predicted ground positions;
    position_cov_m2 : (n, 2, 2) their covariance; V : (2, 2) pixel noise.
    Returns o- (L, n, 2) px, Sigma_o (L, n, 2, 2) px^2, and in_front (L, n) bool.
    """
    H = ground_to_image(camera, poses)
    in_front = np.einsum("nj,lj->ln", mean_m, H[:, 2, :2]) + H[:, 2, 2, None] > 0
    feet_px = apply_homography(H, mean_m)
    J = homography_jacobian(H, mean_m)
    cov_px = J @ position_cov_m2 @ np.swapaxes(J, -1, -2) + V
    return feet_px, cov_px, in_front


def _log_det_2x2(cov):
    return np.log(cov[..., 0, 0] * cov[..., 1, 1] - cov[..., 0, 1] * cov[..., 1, 0])


def information_gain_nats(alpha, cov_px, V) -> np.ndarray:
    """Equation 7 for every action and track: ``alpha * 1/2 log(det Sigma_o / det V)`` in nats."""
    return alpha * 0.5 * (_log_det_2x2(cov_px) - _log_det_2x2(np.asarray(V)))


def detection_weight_integral(
    camera: PTZCamera, poses, detector: Detector, feet_px, cov_px, in_front, person_height_m: float
) -> np.ndarray:
    """``alpha(a)`` of equation 8 in closed form: 'intg'.

    The visibility domain (equation 10) asks feet and head inside the image.
    The head row follows the feet row through the homology linearised at
    ``o-`` (equations 11-12): ``v_head = v_head(o-) + s (v - v-)``, with
    ``s = dW_v / dv``. The paper drops the head's horizontal offset; a tilted
    camera makes people lean in the image (30 px and more at steep tilts),
    so we keep it at its predicted value ``lean = u_head(o-) - u-``, which
    still leaves a rectangle: ``max(0, -lean) <= u <= min(w, w - lean)`` by
    ``v_low <= v <= v_high``.
    The pixel height ``r = v - v_head = D v + d`` is linear in ``v`` (equation
    13); recall is zero below ``r0``, which only moves ``v_low``, and above it

        alpha = P_rect(N(mu, S)) - exp(-Kd (d - r0) + b.mu + b.S.b / 2) P_rect(N(mu + S b, S)),

    with ``b = (0, -Kd D)``: an exponential times a Gaussian is a scaled
    Gaussian. The ideal detector has recall 1 and ``alpha = P_rect(N(mu, S))``.

    feet_px, cov_px, in_front : from :func:`predicted_observations` for ``poses`` (L, 3).
    Returns alpha (L, n) in [0, 1].
    """
    W = head_from_feet_homology(camera, poses, person_height_m)
    head_px = apply_homography(W, feet_px)
    lean_u = head_px[..., 0] - feet_px[..., 0]
    head_v = head_px[..., 1]
    slope = homography_jacobian(W, feet_px)[..., 1, 1]
    slope = np.where(np.abs(slope) < 1e-9, 1e-9, slope)
    mean_v = feet_px[..., 1]
    head_offset = head_v - slope * mean_v
    edge_a = -head_offset / slope
    edge_b = (camera.image_height_px - head_offset) / slope
    v_low = np.maximum(0.0, np.minimum(edge_a, edge_b))
    v_high = np.minimum(float(camera.image_height_px), np.maximum(edge_a, edge_b))
    height_slope, height_offset = 1.0 - slope, -head_offset
    if detector.kind == "realistic":
        v_at_r0 = (detector.recall_r0_px - height_offset) / height_slope
        v_low = np.where(height_slope > 0, np.maximum(v_low, v_at_r0), v_low)
        v_high = np.where(height_slope > 0, v_high, np.minimum(v_high, v_at_r0))
    low = np.stack([np.maximum(0.0, -lean_u), v_low], axis=-1)
    high = np.stack([np.minimum(camera.image_width_px, camera.image_width_px - lean_u), v_high], axis=-1)
    alpha = gaussian_rectangle_probability(feet_px, cov_px, low, high)
    if detector.kind == "realistic":
        kd = detector.recall_kd
        b_v = -kd * height_slope
        cov_vv = cov_px[..., 1, 1]
        shifted = feet_px + cov_px[..., :, 1] * b_v[..., None]
        log_scale = -kd * (height_offset - detector.recall_r0_px) + b_v * mean_v + 0.5 * b_v**2 * cov_vv
        shifted_probability = gaussian_rectangle_probability(shifted, cov_px, low, high)
        with np.errstate(divide="ignore", over="ignore"):
            missed = np.where(shifted_probability > 0, np.exp(log_scale + np.log(shifted_probability)), 0.0)
        alpha = alpha - missed
    return np.where(in_front, np.clip(alpha, 0.0, 1.0), 0.0)


def detection_weight_sampled(
    camera: PTZCamera,
    poses,
    detector: Detector,
    mean_m,
    position_cov_m2,
    person_height_m: float,
    person_width_m: float,
    reference_pose,
    rng: np.random.Generator,
    samples: int,
) -> np.ndarray:
    """``alpha(a)`` of equation 19 by Monte Carlo over joint positions: 'smpl'.

    Draws ``samples`` joint configurations of all tracks' predicted ground
    positions, stratified by Latin hypercube sampling: the same estimator as
    plain Monte Carlo with about half its error at M = 100, which matters
    because the best of many noisy rewards is biased towards overestimated
    actions. In each configuration, every person is detected with probability
    ``recall(r) (1 - c)`` when head and feet are in the image, as the
    simulated detector does, and alpha is the mean over samples.

    The occluded fraction ``c`` comes from exact box overlaps in depth order.
    It is computed once per sample, at ``reference_pose``, not once per action:
    who hides whom is decided by the rays through the optical centre, which
    turning and zooming the camera does not change (zoom scales every box
    about the principal point, leaving overlap fractions exactly equal).
    Only the boxes' slight perspective distortion varies with pan and tilt.

    mean_m : (n, 2); position_cov_m2 : (n, 2, 2). Returns alpha (L, n).
    """
    mean_m = np.asarray(mean_m, dtype=float)
    chol = np.linalg.cholesky(position_cov_m2 + 1e-12 * np.eye(2))
    uniform = qmc.LatinHypercube(d=mean_m.size, rng=rng).random(samples)
    standard = norm.ppf(uniform).reshape((samples,) + mean_m.shape)
    ground_m = mean_m + np.einsum("nij,mnj->mni", chol, standard)
    at_reference = project_people(camera, reference_pose, ground_m, person_height_m, person_width_m)
    hidden = occluded_fraction(at_reference.box_px, at_reference.depth_m, at_reference.depth_m > 0)
    people = project_people(camera, np.asarray(poses)[:, None, :], ground_m, person_height_m, person_width_m)
    detected = np.where(person_in_view(camera, people), recall(people.height_px, detector) * (1.0 - hidden), 0.0)
    return detected.mean(axis=1)
