"""The information-gain policies 'intg' and 'smpl' (paper equations 3, 8, 19 and 20).

Each step, among the actions the mechanics allow, pick

    argmax_a  sum_k alpha_k(a) 1/2 log(det Sigma_o,k(a) / det V)  +  beta I_p(a),

with ``alpha`` in closed form ('intg') or by sampling with occlusions
('smpl'). When no action is strictly better than staying (no tracks and no
exploration term), the camera stays.
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
from ptztrack.detect.simulated import RecallModel
from ptztrack.geometry.ptz import PTZCamera, look_at
from ptztrack.types import DecisionContext, Tracks


@dataclass
class InformationGainPolicy:
    """Greedy expected-information-gain control.

    recall : the detector model the policy plans with; V : (2, 2) px^2 the feet-pixel noise.
    person_height_m, person_width_m : the person the policy expects.
    method : 'intg' (equation 8, closed form) or 'smpl' (equation 19, ``samples`` draws).
    beta, exploration : the patrolling term's weight and map (None: no patrolling term).
    """

    camera: PTZCamera
    grid: ActionGrid
    recall: RecallModel
    V: np.ndarray
    person_height_m: float
    person_width_m: float
    method: Literal["intg", "smpl"]
    samples: int
    beta: float = 0.0
    exploration: ExplorationMap | None = None
    geometry: ActionGeometry = field(init=False, repr=False)

    def __post_init__(self):
        self.geometry = action_geometry(self.camera, self.grid.poses, self.person_height_m)

    def rewards(self, actions, tracks: Tracks, rng: np.random.Generator) -> np.ndarray:
        """Expected information (nats) of each of ``actions`` (flat indices) about ``tracks``; (len(actions),)."""
        reward = np.zeros(len(actions))
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
            reward += np.sum(alpha * information, axis=-1)
        if self.exploration is not None:
            reward += self.beta * self.exploration.information_nats(actions)
        return reward

    def choose(self, context: DecisionContext) -> int:
        reward = self.rewards(context.reachable, context.tracks, context.rng)
        best = int(np.argmax(reward))
        staying = np.flatnonzero(context.reachable == context.current_action)
        if len(staying) and reward[staying[0]] >= reward[best]:
            action = context.current_action
        else:
            action = int(context.reachable[best])
        if self.exploration is not None:
            self.exploration.advance(action)
        return action
