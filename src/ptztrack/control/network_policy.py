"""Where the cameras of a network look: together, greedily, by expected information.

The objective. For a set of views ``S`` (one per camera) and a track of
prior covariance ``P``, camera ``k``'s view detects the person with
probability ``alpha_k`` and then measures it through ``C_k`` with noise
``V_k``; with ``Phi_k = C_k^T V_k^-1 C_k`` the expected information is

    F(S) = E_D [ 1/2 log det(I + P sum_{k in D} Phi_k) ],     D: the views that detect (each w.p. alpha_k),

summed over the tracks. For one camera this is the paper's reward,
``alpha 1/2 log(det Sigma_o / det V)`` (:mod:`ptztrack.control.information_gain`).
``F`` is monotone and submodular in ``S``: ``S -> 1/2 log det(I + P sum_{k
in D cap S} Phi_k)`` is, for every outcome ``D`` (the log-determinant of a
sum of positive semidefinite terms has diminishing returns), and so is a
mixture of such functions, whatever the joint law of ``D``.

The greedy choice. The PTZ cameras choose one after the other, each by its
own policy (:class:`~ptztrack.control.information_policy.InformationGainPolicy`)
on the tracks as the views already chosen are expected to leave them; the
fixed cameras' views are known and enter first. The expectation over which
earlier views detect is replaced by one Gaussian carrying the expected
information (the approximation):

    P_S^-1 = P^-1 + sum_{j in S} alpha_j Phi_j,
    i.e.  P_{S+j} = P_S - alpha_j P_S C_j^T (alpha_j C_j P_S C_j^T + V_j)^-1 C_j P_S,

a measurement with noise ``V_j / alpha_j``, so a view that surely detects
is a Kalman update and one that cannot leaves ``P``. ``alpha_j`` is the
closed form of equation 8 ('intg', no occlusion), ``C_j`` the Jacobian at
the predicted mean. Camera ``k`` then scores its views as alone, on
``P_S``. A person the earlier views see well is worth less to it.

What the greedy choice guarantees. One view per camera is a partition
matroid, for which greedy selection of a monotone submodular function is
within 1/2 of the best joint choice (Fisher, Nemhauser and Wolsey, 1978);
the 1 - 1/e bound is that of choosing any ``N`` views from one common set
(a cardinality constraint), which a network of PTZ cameras is not: camera 2
cannot take a view only camera 1 has. Beyond the bound's assumptions,
three things make the choice a heuristic: the expected-information
approximation above (by Jensen, ``P_S`` values a later view at most as much
as the exact mixture does: ``log det(Y + Phi) - log det Y`` is convex in the
information ``Y``); the linearisation at the predicted means; and
occlusion. With 'smpl', a camera's ``alpha`` counts the people its own
views would find hidden, while the conditioning above uses the closed form
without occlusion, so the cameras do not share one objective; and where a
view that localises an occluder changes whether another view can see the
person behind it (complementary views), the value of a set of views is no
longer a fixed mixture of diminishing returns at all, and no greedy bound holds.

Independent choice (``joint`` False): every PTZ camera chooses by its own
policy on the prior, as if alone.
"""

from dataclasses import dataclass, replace

import numpy as np

from ptztrack.control.information_gain import detection_weight_integral
from ptztrack.control.information_policy import InformationGainPolicy
from ptztrack.geometry.ptz import homography_jacobian
from ptztrack.types import DecisionContext, Tracks


@dataclass(frozen=True)
class NetworkCamera:
    """One camera as the network's policy knows it.

    policy : the camera's own policy: its camera model, grid, detector model and pixel noise, with which
        its views are scored and, for a PTZ camera, chosen.
    fixed_action : a fixed camera's one action (a flat index of its grid); None for a PTZ camera.
    """

    policy: InformationGainPolicy
    fixed_action: int | None = None


def expected_posterior(tracks: Tracks, policy: InformationGainPolicy, action: int) -> Tracks:
    """``tracks`` with each covariance replaced by its expected posterior after the view of ``policy``'s
    grid action ``action`` (a flat index): ``P+ = P - alpha P C^T (alpha C P C^T + V)^-1 C P`` (the
    module's approximation), alpha (n,) the closed-form probability of detecting each track there.

    The view's homographies are the policy's, computed once for its grid
    (:attr:`InformationGainPolicy.geometry`), not recomputed for the one pose.
    """
    if len(tracks) == 0:
        return tracks
    geometry = policy.geometry
    mean_m, position_cov_m2 = tracks.mean[:, :2], tracks.covariance[:, :2, :2]
    alpha = detection_weight_integral(
        policy.camera, geometry, policy.recall, mean_m, position_cov_m2, policy.V, actions=[action]
    )[0]
    seen = np.flatnonzero(alpha > 0)
    # C = [dg/dx 0]: (k, 2, 4), the feet pixel's Jacobian at the predicted means, zero for the velocity.
    position_block = homography_jacobian(geometry.ground_to_image[action], mean_m[seen])
    C = np.concatenate([position_block, np.zeros_like(position_block)], axis=-1)
    return expected_update(tracks, seen, alpha[seen], C, policy.V)


def expected_update(tracks: Tracks, seen, alpha, C, V) -> Tracks:
    """``tracks`` with the covariances of tracks ``seen`` (k,) updated by a measurement of noise ``V / alpha``:
    ``P+ = P - alpha P C^T (alpha C P C^T + V)^-1 C P``, alpha (k,) the detection probabilities, C (k, 2, 4)
    the measurement Jacobians, V (2, 2) px^2 the pixel noise."""
    P = tracks.covariance[seen]
    weight = np.asarray(alpha)[:, None, None]
    S = weight * (C @ P @ np.swapaxes(C, -1, -2)) + V
    PCt = P @ np.swapaxes(C, -1, -2)
    drop = weight * PCt @ np.linalg.solve(S, np.swapaxes(PCt, -1, -2))
    covariance = tracks.covariance.copy()
    # The drop is symmetric in exact arithmetic; symmetrise what rounding leaves.
    covariance[seen] = P - 0.5 * (drop + np.swapaxes(drop, -1, -2))
    return replace(tracks, covariance=covariance)


@dataclass
class NetworkInformationPolicy:
    """Every camera's next action (:class:`ptztrack.roles.NetworkPolicy`): fixed cameras keep theirs; PTZ
    cameras choose by expected information, jointly (``joint``: greedily in the network's order, each on
    the tracks the views before it are expected to leave; see the module's docstring) or each alone on
    the prior."""

    cameras: tuple[NetworkCamera, ...]
    joint: bool = True

    def choose(self, contexts) -> list[int | np.ndarray]:
        if len(contexts) != len(self.cameras):
            raise ValueError(f"{len(contexts)} decision contexts for a network of {len(self.cameras)} cameras")
        fixed = [k for k, camera in enumerate(self.cameras) if camera.fixed_action is not None]
        ptz = [k for k, camera in enumerate(self.cameras) if camera.fixed_action is None]
        order = fixed + ptz
        choices: dict[int, int] = {}
        tracks: Tracks = contexts[0].tracks
        for position, k in enumerate(order):
            camera, context = self.cameras[k], contexts[k]
            if camera.fixed_action is not None:
                choices[k] = camera.fixed_action
            else:
                choices[k] = camera.policy.choose(_with_tracks(context, tracks))
            # PTZ cameras come last: every camera but the last has one after it that will read the tracks.
            if self.joint and ptz and position < len(order) - 1:
                tracks = expected_posterior(tracks, camera.policy, choices[k])
        return [choices[k] for k in range(len(self.cameras))]


def _with_tracks(context: DecisionContext, tracks: Tracks) -> DecisionContext:
    return context if tracks is context.tracks else replace(context, tracks=tracks)
