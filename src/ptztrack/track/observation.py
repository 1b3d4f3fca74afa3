"""The observation model: where a track's state puts the feet in the image at a pose, and back.

A track's state is ``(x, y, vx, vy)`` (m, m/s) on the ground plane. At a pose (pan deg, tilt deg, zoom
factor) the feet pixel is the ground-to-image homography ``H`` (:func:`~ptztrack.geometry.ptz.ground_to_image`)
applied to ``(x, y, 1)``; its Jacobian ``C`` (n, 2, 4) px/m (zero for the velocity) linearises it at the
predicted state. A pixel has a ground point only below the horizon (:func:`ground_points`), and a track's
gate is mapped into the image only where it lies wholly in front of the camera (:func:`gate_in_front`).
"""

import numpy as np
from scipy.stats import chi2

from ptztrack.geometry.ptz import PTZCamera, apply_homography, feet_jacobian, ground_to_image, image_to_ground


def observation_matrix(camera: PTZCamera, pose, mean) -> np.ndarray:
    """``C_x(a)``: (n, 2, 4) Jacobian of the feet pixel w.r.t. the state, at the states ``mean``."""
    position_block = feet_jacobian(camera, pose, mean[:, :2])
    return np.concatenate([position_block, np.zeros_like(position_block)], axis=-1)


def predicted_feet_px(camera: PTZCamera, pose, mean) -> tuple[np.ndarray, np.ndarray]:
    """Where the states ``mean`` (n, 4) put the feet in the image at ``pose``.

    Returns the pixels (n, 2) and whether each point is in front of the camera (n,).
    """
    H = ground_to_image(camera, pose)
    in_front = (mean[:, :2] @ H[2, :2] + H[2, 2]) > 0
    return apply_homography(H, mean[:, :2]), in_front


def gate_in_front(camera: PTZCamera, pose, mean, covariance, gate_probability: float) -> np.ndarray:
    """Whether each track's gate on the ground lies wholly in front of the camera at ``pose``; (n,) bool.

    The gate is the ellipse ``(x - m)^T P^-1 (x - m) <= g`` of the predicted position (``mean`` (n, 4),
    ``covariance`` (n, 4, 4); ``g`` the chi-square quantile ``gate_probability``, 2 degrees of freedom). A
    ground point's depth along the optical axis is ``w = h . (x, y, 1)``, ``h`` the ground-to-image
    homography's last row, and over the ellipse it is at least ``w(m) - sqrt(g h^T P h)``, so the gate lies
    in front where that is positive. Only there is the feet pixel a smooth function of the position
    over the gate: an ellipse that reaches the camera's principal plane (``w = 0``) projects to pixels
    without bound, and its linearised innovation covariance, huge as well, would gate in any detection.
    """
    h = ground_to_image(camera, pose)[2]
    depth = mean[:, :2] @ h[:2] + h[2]
    depth_variance = np.einsum("i,nij,j->n", h[:2], covariance[:, :2, :2], h[:2])
    return depth > np.sqrt(chi2.ppf(gate_probability, df=2) * depth_variance)


def ground_points(feet_px, camera: PTZCamera, pose) -> tuple[np.ndarray, np.ndarray]:
    """The ground points (K, 2) m of feet pixels (K, 2) at ``pose``, and which lie in front of the
    camera (K,): a pixel at or above the horizon has no ground point (its row is then meaningless)."""
    G = image_to_ground(camera, pose)
    # G (u, v, 1) = (x, y, 1) / depth, so its last entry is positive only for
    # pixels whose ray meets the ground in front of the camera.
    homogeneous = np.asarray(feet_px, dtype=float).reshape(-1, 2) @ G[:, :2].T + G[:, 2]
    ok = homogeneous[:, 2] > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        return homogeneous[:, :2] / homogeneous[:, 2:], ok
