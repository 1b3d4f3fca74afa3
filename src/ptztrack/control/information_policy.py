"""The information-gain policies 'intg' and 'smpl' (paper equations 3, 8, 19 and 20).

Each step, among the actions the mechanics allow, pick

    argmax_a  sum_k alpha_k(a) 1/2 log(det Sigma_o,k(a) / det V)  +  beta I_p(a),

with ``alpha`` in closed form ('intg') or by sampling with occlusions
('smpl'). When no action is strictly better than staying (no tracks and no
exploration term), the camera stays.

A camera whose moves take time (a live one) plans the same way: it is
given a new choice only once a picture taken at rest where its last move
took it is in the belief (:func:`ptztrack.loop.live.run_live_network`).
"""

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from ptztrack.camera.actions import ActionGrid
from ptztrack.control.exploration import ExplorationMap
from ptztrack.control.information_gain import (
    ActionGeometry,
    action_geometry,
    detection_weight_and_information_integral,
    detection_weight_sampled,
    information_if_detected_nats,
)
from ptztrack.control.parameters import ControlParameters
from ptztrack.detect.simulated import RecallCurve
from ptztrack.geometry.ptz import PTZCamera, look_at
from ptztrack.types import DecisionContext, Tracks

InformationMethod = Literal["intg", "smpl"]
"""The information-gain policy's two ways of computing the expected gain: 'intg' (equation 8, closed form)
or 'smpl' (equation 19, by sampling)."""


@dataclass(frozen=True)
class RewardTerms:
    """One decision's rewards (nats) term by term.

    actions : (R,) the flat indices scored; track_ids : (n,) the predicted tracks' ids;
    track_nats : (R, n) each track's expected information gain ``alpha_k(a) I_k(a)``;
    patrol_nats : (R,) the patrolling term ``beta I_p(a)`` (zeros without one).
    """

    actions: np.ndarray
    track_ids: np.ndarray
    track_nats: np.ndarray
    patrol_nats: np.ndarray

    @property
    def total_nats(self) -> np.ndarray:
        """(R,) the reward of each action, as the policy compares them."""
        return np.sum(self.track_nats, axis=-1) + self.patrol_nats


@dataclass
class InformationGainPolicy:
    """Greedy expected-information-gain control.

    recall : the detector model the policy plans with; V : (2, 2) px^2 the feet-pixel noise.
    person_height_m, person_width_m : the person the policy expects.
    method : 'intg' (equation 8, closed form) or 'smpl' (equation 19, ``samples`` draws).
    beta, exploration : the patrolling term's weight and map (None: no patrolling term).
    last_terms : the last choice's rewards term by term (for a live view of the decision; None before
        the first choice). Kept by reference: the arrays are the ones the choice was made from.
    """

    camera: PTZCamera
    grid: ActionGrid
    recall: RecallCurve
    V: np.ndarray
    person_height_m: float
    person_width_m: float
    method: InformationMethod
    samples: int = ControlParameters.samples
    beta: float = ControlParameters.beta
    exploration: ExplorationMap | None = None
    geometry: ActionGeometry = field(init=False, repr=False)
    last_terms: RewardTerms | None = field(default=None, init=False, repr=False)

    def __post_init__(self):
        self.geometry = action_geometry(self.camera, self.grid.poses, self.person_height_m)

    def rewards(self, actions, tracks: Tracks, rng: np.random.Generator) -> np.ndarray:
        """Expected information (nats) of each of ``actions`` (flat indices) about ``tracks``; (len(actions),)."""
        return self.reward_terms(actions, tracks, rng).total_nats

    def reward_terms(self, actions, tracks: Tracks, rng: np.random.Generator) -> RewardTerms:
        """The rewards of ``actions`` (flat indices) term by term: each track's, and the patrolling term."""
        actions = np.asarray(actions)
        track_nats = np.zeros((len(actions), len(tracks)))
        if len(tracks):
            mean_m = tracks.mean[:, :2]
            position_cov_m2 = tracks.covariance[:, :2, :2]
            if self.method == "intg":
                alpha, information = detection_weight_and_information_integral(
                    self.camera, self.geometry, self.recall, mean_m, position_cov_m2, self.V, actions
                )
            else:
                reference_pose = look_at(self.camera, mean_m.mean(axis=0), zoom=1.0)
                alpha = detection_weight_sampled(
                    self.camera,
                    self.geometry,
                    self.recall,
                    mean_m,
                    position_cov_m2,
                    self.person_height_m,
                    self.person_width_m,
                    reference_pose,
                    rng,
                    self.samples,
                    actions,
                )
                information = information_if_detected_nats(self.geometry, mean_m, position_cov_m2, self.V, actions)
            track_nats = alpha * information
        patrol_nats = np.zeros(len(actions))
        if self.exploration is not None:
            patrol_nats = self.beta * self.exploration.information_nats(actions)
        return RewardTerms(actions, tracks.ids, track_nats, patrol_nats)

    def choose(self, context: DecisionContext) -> int:
        # One reachable action (a live camera given its target while it moves) leaves nothing to weigh.
        action = int(context.reachable[0]) if len(context.reachable) == 1 else self.best_action(context)
        self.advance_exploration(action, context.dt_s)
        return action

    def best_action(self, context: DecisionContext) -> int:
        """The action of largest reward among ``context.reachable`` (staying where no other is strictly
        better), without moving the patrolling map on: what :meth:`choose` would pick."""
        self.last_terms = self.reward_terms(context.reachable, context.tracks, context.rng)
        reward = self.last_terms.total_nats
        best = int(np.argmax(reward))
        staying = np.flatnonzero(context.reachable == context.current_action)
        if len(staying) and reward[staying[0]] >= reward[best]:
            return context.current_action
        return int(context.reachable[best])

    def advance_exploration(self, action: int, dt_s: float | None = None) -> None:
        """The patrolling map one step on, the camera having looked with ``action`` (none: nothing)."""
        if self.exploration is not None:
            self.exploration.advance(action, dt_s)
