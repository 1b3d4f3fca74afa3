"""Plain NumPy references for the information-gain rewards (paper equations 7, 8, 9 and 19).

The policies evaluate their rewards in compiled kernels, one (action, track)
or (action, sample, track) at a time. This module evaluates the same
estimators with whole arrays over every axis at once, from the camera model
(:mod:`ptztrack.geometry.ptz`) rather than from the kernels' scalar
algebra, and measures occlusion by cutting every box along the edges of all
the others. It is slow (tens of MB of arrays at 20 tracks x 462 actions x
100 samples) and made to be read: the tests check the kernels against it, and
``benchmarks/decision_speed.py`` checks that the kernels choose the actions
it chooses on recorded states.

What is shared with the package is what the kernels are not checked for
here: the homographies of :mod:`ptztrack.geometry.ptz`, the Gaussian
rectangle probability (tested against SciPy's numerical CDF), the recall
model, the joint draws of 'smpl' (the reference must use the same draws) and
the patrolling term.
"""

import numpy as np

from ptztrack.control.gaussian_rectangle import gaussian_rectangle_probability
from ptztrack.control.information_gain import joint_position_samples
from ptztrack.control.information_policy import InformationGainPolicy
from ptztrack.geometry.ptz import (
    apply_homography,
    ground_to_image,
    head_from_feet_homology,
    homography_jacobian,
    inside_image,
    look_at,
    project_people,
)
from ptztrack.types import Tracks


def occluded_fraction_by_cells(box_px, depth_m, valid) -> np.ndarray:
    """:func:`ptztrack.geometry.occlusion.occluded_fraction` with every box cut along the edges of all others.

    box_px : (..., N, 4); depth_m, valid : (..., N). Each target box is cut
    along the clipped edges of all N boxes (those that do not hide it
    collapse to a point) into (2N - 1)^2 cells, and a cell counts when its
    centre lies in a nearer, valid box: O(N^4) per frame.
    """
    box_px = np.asarray(box_px, dtype=float)
    depth_m = np.asarray(depth_m, dtype=float)
    valid = np.asarray(valid, dtype=bool)
    count = box_px.shape[-2]
    target = box_px[..., :, None, :]
    occluder = box_px[..., None, :, :]
    occludes = (
        valid[..., None, :]
        & valid[..., :, None]
        & (depth_m[..., None, :] < depth_m[..., :, None])
        & ~np.eye(count, dtype=bool)
    )
    low = np.maximum(occluder[..., :2], target[..., :2])
    high = np.minimum(occluder[..., 2:], target[..., 2:])
    high = np.where(occludes[..., None], np.maximum(high, low), low)

    def cells(axis):
        edges = np.sort(np.concatenate([low[..., axis], high[..., axis]], axis=-1), axis=-1)
        return 0.5 * (edges[..., 1:] + edges[..., :-1]), np.diff(edges, axis=-1)

    mid_x, width_x = cells(0)
    mid_y, width_y = cells(1)
    inside_x = (low[..., None, :, 0] <= mid_x[..., :, None]) & (mid_x[..., :, None] < high[..., None, :, 0])
    inside_y = (low[..., None, :, 1] <= mid_y[..., :, None]) & (mid_y[..., :, None] < high[..., None, :, 1])
    covered = np.any(inside_x[..., :, None, :] & inside_y[..., None, :, :], axis=-1)
    with np.errstate(invalid="ignore"):
        covered_area = np.einsum("...ab,...a,...b->...", covered, width_x, width_y)
    box_area = (box_px[..., 2] - box_px[..., 0]) * (box_px[..., 3] - box_px[..., 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        fraction = np.where(box_area > 0, np.clip(covered_area / box_area, 0.0, 1.0), 0.0)
    return np.where(valid, fraction, 0.0)


def _in_front(H, mean_m) -> np.ndarray:
    """Whether each track's predicted feet are in front of the camera at each action; (L, n)."""
    return np.einsum("lj,nj->ln", H[:, 2, :2], mean_m) + H[:, 2, 2, None] > 0


def information_if_detected(policy: InformationGainPolicy, poses, mean_m, position_cov_m2) -> np.ndarray:
    """Equations 7 and 9: ``1/2 log(det(C P C^T + V) / det V)``, 0 behind the camera; (L, n)."""
    H = ground_to_image(policy.camera, poses)
    C = homography_jacobian(H, np.broadcast_to(mean_m, (len(poses),) + mean_m.shape))
    sigma_o = C @ position_cov_m2 @ np.swapaxes(C, -1, -2) + policy.V
    in_front = _in_front(H, mean_m)
    drop = 0.5 * (np.linalg.slogdet(sigma_o)[1] - np.linalg.slogdet(policy.V)[1])
    return np.where(in_front, drop, 0.0)


def integral_detection_weight(policy: InformationGainPolicy, poses, mean_m, position_cov_m2) -> np.ndarray:
    """Equation 8 in closed form ('intg'): (L, n), read from the docstring of
    :func:`ptztrack.control.information_gain.detection_weight_integral`."""
    camera, recall = policy.camera, policy.recall
    width_px, height_px = float(camera.image_width_px), float(camera.image_height_px)
    H = ground_to_image(camera, poses)
    points = np.broadcast_to(mean_m, (len(poses),) + mean_m.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        feet = apply_homography(H, points)
        C = homography_jacobian(H, points)
        sigma_o = C @ position_cov_m2 @ np.swapaxes(C, -1, -2) + policy.V
        W = head_from_feet_homology(camera, poses, policy.person_height_m)
        head = apply_homography(W, feet)
        slope = homography_jacobian(W, feet)[..., 1, 1]
        slope = np.where(np.abs(slope) < 1e-9, 1e-9, slope)
        u, v = feet[..., 0], feet[..., 1]
        var_u, cov_uv, var_v = sigma_o[..., 0, 0], sigma_o[..., 0, 1], sigma_o[..., 1, 1]
        lean_u = head[..., 0] - u
        head_offset = head[..., 1] - slope * v  # v_head = slope v + head_offset
        edges = np.stack([-head_offset / slope, (height_px - head_offset) / slope])
        v_low = np.maximum(0.0, edges.min(axis=0))
        v_high = np.minimum(height_px, edges.max(axis=0))
        u_low, u_high = np.maximum(0.0, -lean_u), np.minimum(width_px, width_px - lean_u)
        # pixel height r = v - v_head = D v + d
        D, d = 1.0 - slope, -head_offset
        if not recall.perfect:
            v_at_r0 = (recall.r0_px - d) / D
            v_low = np.where(D > 0, np.maximum(v_low, v_at_r0), v_low)
            v_high = np.where(D > 0, v_high, np.minimum(v_high, v_at_r0))
        alpha = gaussian_rectangle_probability(u, v, var_u, cov_uv, var_v, u_low, u_high, v_low, v_high)
        if not recall.perfect:
            b_v = -recall.kd_per_px * D
            log_scale = -recall.kd_per_px * (d - recall.r0_px) + b_v * v + 0.5 * b_v**2 * var_v
            shifted = gaussian_rectangle_probability(
                u + cov_uv * b_v, v + var_v * b_v, var_u, cov_uv, var_v, u_low, u_high, v_low, v_high
            )
            # the scale alone can overflow where the shifted Gaussian is far outside the rectangle
            alpha = np.where((alpha > 0) & (shifted > 0), alpha - np.exp(log_scale + np.log(shifted)), alpha)
            alpha = recall.plateau * alpha
    return np.where(_in_front(H, mean_m), np.clip(alpha, 0.0, 1.0), 0.0)


def sampled_detection_weight(
    policy: InformationGainPolicy, poses, mean_m, position_cov_m2, rng: np.random.Generator
) -> np.ndarray:
    """Equation 19 ('smpl'): the mean over the joint draws of ``recall(r) (1 - c)`` where feet and
    head are in the image, with ``c`` measured at the zoom-1 view centred on the tracks; (L, n)."""
    camera = policy.camera
    ground_m = joint_position_samples(mean_m, position_cov_m2, rng, policy.samples)  # (M, n, 2)
    centred = look_at(camera, mean_m.mean(axis=0), zoom=1.0)
    at_reference = project_people(camera, centred, ground_m, policy.person_height_m, policy.person_width_m)
    visible = 1.0 - occluded_fraction_by_cells(at_reference.box_px, at_reference.range_m, at_reference.in_front)
    with np.errstate(divide="ignore", invalid="ignore"):
        seen = project_people(camera, poses[:, None, :], ground_m, policy.person_height_m, policy.person_width_m)
        in_view = seen.in_front & inside_image(camera, seen.feet_px) & inside_image(camera, seen.head_px)
        recall = policy.recall(seen.feet_px[..., 1] - seen.head_px[..., 1])  # (L, M, n)
    return np.mean(np.where(in_view, recall * visible, 0.0), axis=1)


def rewards(policy: InformationGainPolicy, actions, tracks: Tracks, rng: np.random.Generator) -> np.ndarray:
    """What :meth:`InformationGainPolicy.rewards` computes, by the references above; (len(actions),)."""
    actions = np.asarray(actions)
    reward = np.zeros(len(actions))
    if len(tracks):
        poses = policy.grid.poses[actions]
        mean_m, position_cov_m2 = tracks.mean[:, :2], tracks.covariance[:, :2, :2]
        if policy.method == "intg":
            alpha = integral_detection_weight(policy, poses, mean_m, position_cov_m2)
        else:
            alpha = sampled_detection_weight(policy, poses, mean_m, position_cov_m2, rng)
        reward += np.sum(alpha * information_if_detected(policy, poses, mean_m, position_cov_m2), axis=-1)
    if policy.exploration is not None:
        reward += policy.beta * policy.exploration.information_nats(actions)
    return reward
