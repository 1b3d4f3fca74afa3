"""One camera as a network of it alone: its policy and its tracker in the network's roles, so that the
one-camera loops are the network loops with one camera."""

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ptztrack.roles import Policy, Tracker, Updater
from ptztrack.types import DecisionContext, Tracks


@dataclass(frozen=True)
class AlonePolicy:
    """One camera's policy as the policy of a network of it alone (:class:`ptztrack.roles.NetworkPolicy`)."""

    policy: Policy

    def choose(self, contexts: Sequence[DecisionContext]) -> list[int | np.ndarray]:
        return [self.policy.choose(contexts[0])]


@dataclass(frozen=True)
class AloneTracker:
    """One camera's tracker as the belief of a network of it alone (:class:`ptztrack.roles.NetworkTracker`)."""

    tracker: Tracker

    def predict(self, dt_s: float | None = None) -> Tracks:
        return self.tracker.predict(dt_s)

    def updater(self, camera: int) -> Updater:
        return self.tracker

    def reported(self) -> Tracks:
        return self.tracker.reported()
