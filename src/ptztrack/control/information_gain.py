"""Expected information gain of camera actions about tracked people (paper sections 3.2-4.2).

For an action ``a`` and a track with prediction ``x-, P-``, the observation is
predicted as ``o ~ N(o-, Sigma_o)`` with ``o- = g(x-, a)`` and
``Sigma_o = C_x(a) P- C_x(a)^T + V`` (equation 9). The track is updated only
if it is detected, which happens with probability ``alpha(a)``; then

    I(a) = alpha(a) (H(P-) - H(P+(a))) = alpha(a) * 1/2 log(det Sigma_o / det V)   (equations 4, 7)

because ``det P+ / det P- = det V / det Sigma_o`` for the Kalman update (the
matrix determinant lemma), so no update need be computed.

The rewards are evaluated for every action (L) x track (n), and for ``smpl``
x sample (M), in Numba kernels: each pair costs some sixty scalar operations,
and as NumPy array operations their per-call overhead, not their arithmetic,
kept decisions ten times slower than a PTZ head moves. The kernels share one
camera model: they take the per-action homographies of
:mod:`ptztrack.geometry.ptz`, computed once per grid, and read them at the
indices of the actions asked for. For 'intg', one pass gives both alpha and
the information, from one prediction per (action, track).
"""

import math
from dataclasses import dataclass

import numba
import numpy as np
from scipy.stats import norm, qmc

from ptztrack.control.gaussian_rectangle import rectangle_probability_scalar
from ptztrack.detect.simulated import RecallCurve, realistic_recall
from ptztrack.geometry.occlusion import occluded_fraction
from ptztrack.geometry.ptz import (
    PTZCamera,
    ground_to_image,
    head_from_feet_homology,
    look_at,
    plane_homography,
    project_people,
)


@dataclass(frozen=True)
class ActionGeometry:
    """The per-action matrices the rewards need, computed once per grid.

    ground_to_image : (L, 3, 3) ground-plane homographies.
    head_to_image : (L, 3, 3) homographies of the plane at the assumed head height.
    head_from_feet : (L, 3, 3) the homologies ``W`` for that height.
    """

    ground_to_image: np.ndarray
    head_to_image: np.ndarray
    head_from_feet: np.ndarray

    def indices(self, actions) -> np.ndarray:
        """``actions`` as the flat int64 indices the kernels read the matrices at (None: all of them)."""
        if actions is None:
            return np.arange(len(self.ground_to_image))
        return np.asarray(actions, dtype=np.int64)


def action_geometry(camera: PTZCamera, poses, person_height_m: float) -> ActionGeometry:
    return ActionGeometry(
        ground_to_image(camera, poses),
        plane_homography(camera, poses, person_height_m),
        head_from_feet_homology(camera, poses, person_height_m),
    )


@numba.njit
def _predict(H, mean_m, cov_m2, track, V):
    """Equation 9 for one action and track: (u, v, var_u, cov_uv, var_v, w), w > 0 in front.

    H : (3, 3) ground-to-image; mean_m : (n, 2); cov_m2 : (n, 2, 2). ``C_x(a)`` is
    the homography's Jacobian at the prediction (zero for the velocity). The
    track comes as an index, not as views ``mean_m[track]``: a view per pair
    cost Numba a reference count each, a third of the kernels' time.
    """
    x_m, y_m = mean_m[track, 0], mean_m[track, 1]
    var_x, cov_xy, var_y = cov_m2[track, 0, 0], cov_m2[track, 0, 1], cov_m2[track, 1, 1]
    X = H[0, 0] * x_m + H[0, 1] * y_m + H[0, 2]
    Y = H[1, 0] * x_m + H[1, 1] * y_m + H[1, 2]
    w = H[2, 0] * x_m + H[2, 1] * y_m + H[2, 2]
    inverse_w = 1.0 / w
    u, v = X * inverse_w, Y * inverse_w
    a, b = (H[0, 0] - u * H[2, 0]) * inverse_w, (H[0, 1] - u * H[2, 1]) * inverse_w
    c, d = (H[1, 0] - v * H[2, 0]) * inverse_w, (H[1, 1] - v * H[2, 1]) * inverse_w
    var_u = a * a * var_x + 2 * a * b * cov_xy + b * b * var_y + V[0, 0]
    cov_uv = a * c * var_x + (a * d + b * c) * cov_xy + b * d * var_y + V[0, 1]
    var_v = c * c * var_x + 2 * c * d * cov_xy + d * d * var_y + V[1, 1]
    return u, v, var_u, cov_uv, var_v, w


@numba.njit
def _log_det(V):
    return math.log(V[0, 0] * V[1, 1] - V[0, 1] * V[1, 0])


@numba.njit
def _information(var_u, cov_uv, var_v, log_det_V):
    """``1/2 log(det Sigma_o / det V)`` (nats) of equation 7 for one action and track."""
    return 0.5 * (math.log(var_u * var_v - cov_uv * cov_uv) - log_det_V)


@numba.njit
def _information_if_detected(ground_to_image, actions, mean_m, position_cov_m2, V):
    L, n = actions.shape[0], mean_m.shape[0]
    log_det_V = _log_det(V)
    gain = np.zeros((L, n))
    for row in range(L):
        H = ground_to_image[actions[row]]
        for track in range(n):
            _, _, var_u, cov_uv, var_v, w = _predict(H, mean_m, position_cov_m2, track, V)
            if w > 0:
                gain[row, track] = _information(var_u, cov_uv, var_v, log_det_V)
    return gain


def information_if_detected_nats(geometry: ActionGeometry, mean_m, position_cov_m2, V, actions=None) -> np.ndarray:
    """``H(P-) - H(P+(a)) = 1/2 log(det Sigma_o / det V)`` (nats) for every action and track; (L, n).

    0 for a track behind the camera. mean_m : (n, 2); position_cov_m2 : (n, 2, 2); V : (2, 2).
    actions : the flat indices of the actions of ``geometry`` to evaluate (L of them; None: all).
    """
    return _information_if_detected(
        geometry.ground_to_image,
        geometry.indices(actions),
        np.asarray(mean_m, float),
        np.asarray(position_cov_m2, float),
        np.asarray(V, float),
    )


@numba.njit
def _alpha_closed_form(W, u, v, var_u, cov_uv, var_v, width_px, height_px, realistic, kd, r0_px, plateau):
    """Equation 8 in closed form for one action and track (see :func:`detection_weight_integral`).

    W : (3, 3) the action's head-from-feet homology; the rest is :func:`_predict`'s prediction.
    """
    head_w = W[2, 0] * u + W[2, 1] * v + W[2, 2]
    head_u = (W[0, 0] * u + W[0, 1] * v + W[0, 2]) / head_w
    head_v = (W[1, 0] * u + W[1, 1] * v + W[1, 2]) / head_w
    slope = (W[1, 1] - head_v * W[2, 1]) / head_w
    if abs(slope) < 1e-9:
        slope = 1e-9
    lean_u = head_u - u
    head_offset = head_v - slope * v
    edge_a = -head_offset / slope
    edge_b = (height_px - head_offset) / slope
    v_low = max(0.0, min(edge_a, edge_b))
    v_high = min(height_px, max(edge_a, edge_b))
    u_low = max(0.0, -lean_u)
    u_high = min(width_px, width_px - lean_u)
    height_slope, height_offset = 1.0 - slope, -head_offset
    if realistic:
        v_at_r0 = (r0_px - height_offset) / height_slope
        if height_slope > 0:
            v_low = max(v_low, v_at_r0)
        else:
            v_high = min(v_high, v_at_r0)
    value = rectangle_probability_scalar(u, v, var_u, cov_uv, var_v, u_low, u_high, v_low, v_high)
    if realistic and value > 0:
        b_v = -kd * height_slope
        log_scale = -kd * (height_offset - r0_px) + b_v * v + 0.5 * b_v * b_v * var_v
        shifted = rectangle_probability_scalar(
            u + cov_uv * b_v, v + var_v * b_v, var_u, cov_uv, var_v, u_low, u_high, v_low, v_high
        )
        if shifted > 0:
            value -= math.exp(log_scale + math.log(shifted))
    # A height-independent recall (not realistic) is the plateau at every height: 1 for the ideal detector.
    value *= plateau
    return min(max(value, 0.0), 1.0)


@numba.njit
def _integral_terms(
    ground_to_image,
    head_from_feet,
    actions,
    mean_m,
    position_cov_m2,
    V,
    width_px,
    height_px,
    realistic,
    kd,
    r0_px,
    plateau,
):
    L, n = actions.shape[0], mean_m.shape[0]
    log_det_V = _log_det(V)
    alpha = np.zeros((L, n))
    gain = np.zeros((L, n))
    for row in range(L):
        H, W = ground_to_image[actions[row]], head_from_feet[actions[row]]
        for track in range(n):
            u, v, var_u, cov_uv, var_v, w = _predict(H, mean_m, position_cov_m2, track, V)
            if w <= 0:
                continue
            gain[row, track] = _information(var_u, cov_uv, var_v, log_det_V)
            alpha[row, track] = _alpha_closed_form(
                W, u, v, var_u, cov_uv, var_v, width_px, height_px, realistic, kd, r0_px, plateau
            )
    return alpha, gain


def detection_weight_and_information_integral(
    camera: PTZCamera, geometry: ActionGeometry, recall: RecallCurve, mean_m, position_cov_m2, V, actions=None
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`detection_weight_integral` and :func:`information_if_detected_nats` in one pass: (L, n) each.

    Both read the same prediction ``o-, Sigma_o`` (equation 9), computed once per action and track.
    """
    return _integral_terms(
        geometry.ground_to_image,
        geometry.head_from_feet,
        geometry.indices(actions),
        np.asarray(mean_m, float),
        np.asarray(position_cov_m2, float),
        np.asarray(V, float),
        float(camera.image_width_px),
        float(camera.image_height_px),
        not recall.perfect,
        recall.kd_per_px,
        recall.r0_px,
        recall.plateau,
    )


def detection_weight_integral(
    camera: PTZCamera, geometry: ActionGeometry, recall: RecallCurve, mean_m, position_cov_m2, V, actions=None
) -> np.ndarray:
    """``alpha(a)`` of equation 8 in closed form: 'intg'.

    The prediction is ``o ~ N(o-, Sigma_o)`` (equation 9). The visibility
    domain (equation 10) asks feet and head inside the image. The head row
    follows the feet row through the homology linearised at ``o-`` (equations
    11-12): ``v_head = v_head(o-) + s (v - v-)``, with ``s = dW_v / dv``. The
    paper drops the head's horizontal offset; a tilted camera makes people
    lean in the image (30 px and more at steep tilts), so we keep it at its
    predicted value ``lean = u_head(o-) - u-``, which still leaves a
    rectangle: ``max(0, -lean) <= u <= min(w, w - lean)`` by
    ``v_low <= v <= v_high``.
    The pixel height ``r = v - v_head = D v + d`` is linear in ``v`` (equation
    13); recall is zero below ``r0``, which only moves ``v_low``, and above it

        alpha = plateau [P_rect(N(mu, S)) - exp(-Kd (d - r0) + b.mu + b.S.b / 2) P_rect(N(mu + S b, S))],

    with ``b = (0, -Kd D)``: an exponential times a Gaussian is a scaled
    Gaussian. A recall that does not depend on the height (the ideal detector's 1, or a constant one)
    gives ``alpha = plateau P_rect(N(mu, S))``.

    mean_m : (n, 2) predicted ground positions; position_cov_m2 : (n, 2, 2);
    V : (2, 2) pixel noise; actions : flat indices into ``geometry`` (L of them; None: all).
    Returns alpha (L, n) in [0, 1], 0 behind the camera.
    """
    return detection_weight_and_information_integral(camera, geometry, recall, mean_m, position_cov_m2, V, actions)[0]


@numba.njit
def _detection_weight_sampled(
    ground_to_image,
    head_to_image,
    actions,
    ground_m,
    visible_fraction,
    width_px,
    height_px,
    realistic,
    kd,
    r0_px,
    plateau,
):
    L, (M, n) = actions.shape[0], ground_m.shape[:2]
    alpha = np.zeros((L, n))
    for row in range(L):
        G, E = ground_to_image[actions[row]], head_to_image[actions[row]]
        for sample in range(M):
            for track in range(n):
                x, y = ground_m[sample, track, 0], ground_m[sample, track, 1]
                feet_w = G[2, 0] * x + G[2, 1] * y + G[2, 2]
                head_w = E[2, 0] * x + E[2, 1] * y + E[2, 2]
                if feet_w <= 0 or head_w <= 0:
                    continue
                feet_u = (G[0, 0] * x + G[0, 1] * y + G[0, 2]) / feet_w
                feet_v = (G[1, 0] * x + G[1, 1] * y + G[1, 2]) / feet_w
                head_u = (E[0, 0] * x + E[0, 1] * y + E[0, 2]) / head_w
                head_v = (E[1, 0] * x + E[1, 1] * y + E[1, 2]) / head_w
                if not (0 <= feet_u <= width_px and 0 <= head_u <= width_px):
                    continue
                if not (0 <= feet_v <= height_px and 0 <= head_v <= height_px):
                    continue
                p = plateau * realistic_recall(feet_v - head_v, kd, r0_px) if realistic else plateau
                alpha[row, track] += p * visible_fraction[sample, track]
    return alpha / M


def expected_detection_probability(
    camera: PTZCamera,
    recall: RecallCurve,
    V,
    person_height_m: float,
    person_width_m: float,
    mean_m,
    position_cov_m2,
    pose,
) -> np.ndarray:
    """The probability (n,) that the detector finds each predicted person at ``pose``, were it there.

    ``alpha`` of equation 8 at the pose (feet and head in the image, recall at the person's size,
    over the prediction's uncertainty), times the fraction of the person not hidden by the other
    tracked people at their predicted positions (seen from the view centred on them, as 'smpl'
    does). The tracker's existence update reads it (:mod:`ptztrack.track.tracker`).
    mean_m : (n, 2); position_cov_m2 : (n, 2, 2); V : (2, 2) px^2.
    """
    mean_m = np.asarray(mean_m, dtype=float)
    if len(mean_m) == 0:
        return np.zeros(0)
    geometry = action_geometry(camera, np.asarray(pose, dtype=float)[None], person_height_m)
    alpha = detection_weight_integral(camera, geometry, recall, mean_m, position_cov_m2, V)[0]
    centred = project_people(camera, look_at(camera, mean_m.mean(axis=0), 1.0), mean_m, person_height_m, person_width_m)
    return alpha * (1.0 - occluded_fraction(centred.box_px, centred.range_m, centred.in_front))


def joint_position_samples(mean_m, position_cov_m2, rng: np.random.Generator, samples: int) -> np.ndarray:
    """``samples`` joint draws (M, n, 2) of the tracks' ground positions, by Latin hypercube sampling.

    mean_m : (n, 2); position_cov_m2 : (n, 2, 2). Each track's draws are ``N(mean, cov)``; the
    M x 2n uniforms are one Latin hypercube, mapped through the normal quantile and the Cholesky factor.
    """
    mean_m = np.asarray(mean_m, dtype=float)
    chol = np.linalg.cholesky(position_cov_m2 + 1e-12 * np.eye(2))
    uniform = qmc.LatinHypercube(d=mean_m.size, rng=rng).random(samples)
    standard = norm.ppf(uniform).reshape((samples,) + mean_m.shape)
    return mean_m + np.einsum("nij,mnj->mni", chol, standard)


def detection_weight_sampled(
    camera: PTZCamera,
    geometry: ActionGeometry,
    recall: RecallCurve,
    mean_m,
    position_cov_m2,
    person_height_m: float,
    person_width_m: float,
    reference_pose,
    rng: np.random.Generator,
    samples: int,
    actions=None,
) -> np.ndarray:
    """``alpha(a)`` of equation 19 by Monte Carlo over joint positions: 'smpl'.

    Draws ``samples`` joint configurations of all tracks' predicted ground
    positions, stratified by Latin hypercube sampling: the same estimator as
    plain Monte Carlo with about half its error at M = 100, which matters
    because the best of many noisy rewards is biased towards overestimated
    actions. In each configuration, every person is detected with probability
    ``recall(r) (1 - c)`` when head and feet are in the image, as the
    simulated detector does, and alpha is the mean over samples.

    The occluded fraction ``c`` comes from exact box overlaps, nearer people
    (by distance from the optical centre) hiding farther ones. It is computed
    once per sample, at ``reference_pose`` (the policy uses the zoom-1 view
    centred on the tracks), not once per action: who hides whom is decided by
    the rays through the optical centre, which turning and zooming the camera
    does not change (zoom scales every box about the principal point,
    leaving overlap fractions exactly equal). The simulated detector measures
    each person in the view centred on that person instead; the two differ
    only through the boxes' perspective distortion (a mean of about 0.01).

    mean_m : (n, 2); position_cov_m2 : (n, 2, 2); actions : flat indices into
    ``geometry`` (L of them; None: all). Returns alpha (L, n).
    """
    ground_m = joint_position_samples(mean_m, position_cov_m2, rng, samples)
    at_reference = project_people(camera, reference_pose, ground_m, person_height_m, person_width_m)
    hidden = occluded_fraction(at_reference.box_px, at_reference.range_m, at_reference.in_front)
    return _detection_weight_sampled(
        geometry.ground_to_image,
        geometry.head_to_image,
        geometry.indices(actions),
        ground_m,
        1.0 - hidden,
        float(camera.image_width_px),
        float(camera.image_height_px),
        not recall.perfect,
        recall.kd_per_px,
        recall.r0_px,
        recall.plateau,
    )
