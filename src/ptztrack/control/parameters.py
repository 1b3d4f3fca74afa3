"""The information-gain policies' parameters and their defaults, plain data that the configuration
maps onto (:mod:`ptztrack.config` takes its defaults from here)."""

from dataclasses import dataclass

from ptztrack.scene.parameters import PersonParameters


@dataclass(frozen=True)
class ControlParameters:
    """What the information-gain policies (:mod:`ptztrack.control.information_policy`) are given.

    samples : draws per track of 'smpl' (the paper's equation 19); beta : the patrolling term's weight
    (0: none); person_height_m : the person the policies expect (m); exploration_cell_m : the side of
    the patrolling map's square cells (m); prior_untracked_people : people expected on the walkable
    area before any is seen; arrival_rate_per_s : people arriving on it per second
    (:func:`ptztrack.control.exploration.exploration_map`).
    """

    samples: int = 100
    beta: float = 0.0
    person_height_m: float = PersonParameters.height_m
    exploration_cell_m: float = 1.0
    prior_untracked_people: float = 1.0
    arrival_rate_per_s: float = 0.1
