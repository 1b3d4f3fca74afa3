"""Where the cameras of a network look: together, greedily and then by best responses, by expected information.

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

Best responses. In the greedy order the first camera takes what is worth
most to it, though a later camera may see it better and have little else
to see (two cameras facing each other across the area, each nearer some of
the people). So after the greedy pass each PTZ camera in turn chooses
again, on the tracks as every other camera's chosen view is expected to
leave them,

    P_-k = (P^-1 + sum_{j != k} alpha_j Phi_j)^-1,

``alpha_j`` and ``C_j`` at the prior (so that the order of the others does
not matter), in rounds until a round changes no choice, at most
``best_response_rounds``. A response raises the responding camera's own
reward given the others, not ``F`` itself (a camera scores a view as
``alpha I`` on ``P_-k``, and ``F``'s marginal gain under the approximation
is ``1/2 log det(I + alpha P_-k Phi)``), so no bound is claimed for it and
the cap stops any cycle.

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
    alpha, seen, C = _view_measurement(tracks, policy, action)
    return expected_update(tracks, seen, alpha[seen], C, policy.V)


def _view_measurement(tracks: Tracks, policy: InformationGainPolicy, action: int):
    """The view's detection probabilities alpha (n,), the tracks it may detect ``seen`` (k,) and their
    ``C = [dg/dx 0]`` (k, 2, 4): the feet pixel's Jacobian at the predicted means, zero for the velocity."""
    alpha = view_detection_probability(tracks, policy, action)
    seen = np.flatnonzero(alpha > 0)
    position_block = homography_jacobian(policy.geometry.ground_to_image[action], tracks.mean[seen, :2])
    return alpha, seen, np.concatenate([position_block, np.zeros_like(position_block)], axis=-1)


def view_detection_probability(tracks: Tracks, policy: InformationGainPolicy, action: int) -> np.ndarray:
    """The closed-form probability (n,) that the view of ``policy``'s grid action ``action`` detects each
    track, were its person there (equation 8, no occlusion)."""
    return detection_weight_integral(
        policy.camera,
        policy.geometry,
        policy.recall,
        tracks.mean[:, :2],
        tracks.covariance[:, :2, :2],
        policy.V,
        actions=[action],
    )[0]


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


def view_information(tracks: Tracks, policy: InformationGainPolicy, action: int) -> np.ndarray:
    """(n, 4, 4) the expected information ``alpha C^T V^-1 C`` the view of ``policy``'s grid action
    ``action`` adds to each track's information matrix ``P^-1`` (the module's approximation), alpha and
    ``C = [dg/dx 0]`` at the tracks as given."""
    information = np.zeros((len(tracks), 4, 4))
    if len(tracks) == 0:
        return information
    alpha, seen, C = _view_measurement(tracks, policy, action)
    information[seen] = alpha[seen, None, None] * (np.swapaxes(C, -1, -2) @ np.linalg.solve(policy.V, C))
    return information


@dataclass
class NetworkInformationPolicy:
    """Every camera's next action (:class:`ptztrack.roles.NetworkPolicy`): fixed cameras keep theirs; PTZ
    cameras choose by expected information, jointly (``joint``: greedily in the network's order, each on
    the tracks the views before it are expected to leave, then at most ``best_response_rounds`` rounds of
    best responses; see the module's docstring) or each alone on the prior. Each camera's patrolling map
    moves on once a step, by its final view."""

    cameras: tuple[NetworkCamera, ...]
    joint: bool = True
    best_response_rounds: int = 3

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
                choices[k] = camera.policy.best_action(_with_tracks(context, tracks))
            # PTZ cameras come last: every camera but the last has one after it that will read the tracks.
            if self.joint and ptz and position < len(order) - 1:
                tracks = expected_posterior(tracks, camera.policy, choices[k])
        if self.joint and len(ptz) > 1 and self.best_response_rounds > 0:
            self._respond(contexts, choices, ptz)
        for k in ptz:
            self.cameras[k].policy.advance_exploration(choices[k], contexts[k].dt_s)
        return [choices[k] for k in range(len(self.cameras))]

    def _respond(self, contexts, choices: dict[int, int], ptz: list[int]) -> None:
        """Rounds of best responses after the greedy pass: each PTZ camera in turn chooses again on the
        tracks as every other camera's chosen view is expected to leave them, ``P_-k = (P^-1 + sum_{j != k}
        alpha_j Phi_j)^-1`` (alpha and the Jacobians at the prior); until a round changes no choice, at
        most ``best_response_rounds`` rounds. ``choices`` is updated in place."""
        prior: Tracks = contexts[0].tracks
        if len(prior) == 0:
            return
        added = {k: view_information(prior, self.cameras[k].policy, choices[k]) for k in choices}
        total = np.linalg.inv(prior.covariance) + sum(added.values())
        for _ in range(self.best_response_rounds):
            changed = False
            for k in ptz:
                others = replace(prior, covariance=_symmetric(np.linalg.inv(total - added[k])))
                action = self.cameras[k].policy.best_action(_with_tracks(contexts[k], others))
                if action != choices[k]:
                    choices[k], changed = action, True
                    total = total - added[k]
                    added[k] = view_information(prior, self.cameras[k].policy, action)
                    total = total + added[k]
            if not changed:
                return


def _symmetric(matrices: np.ndarray) -> np.ndarray:
    return 0.5 * (matrices + np.swapaxes(matrices, -1, -2))


def _with_tracks(context: DecisionContext, tracks: Tracks) -> DecisionContext:
    return context if tracks is context.tracks else replace(context, tracks=tracks)
