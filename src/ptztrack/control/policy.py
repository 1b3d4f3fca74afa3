"""The interface every camera policy implements."""

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ptztrack.track.tracker import Tracks


@dataclass(frozen=True)
class DecisionContext:
    """What a policy knows when it picks the next pose.

    step : time step being decided (0-based).
    current_action : flat index of the pose the camera is at now.
    reachable : flat indices of the actions the mechanics allow next.
    tracks : the tracks predicted to this step (``x-``, ``P-``), before observing.
    rng : the run's random generator; policies draw only from it.
    """

    step: int
    current_action: int
    reachable: np.ndarray
    tracks: Tracks
    rng: np.random.Generator


class Policy(Protocol):
    """Chooses the next action; may keep state across the steps of one episode."""

    def choose(self, context: DecisionContext) -> int: ...
