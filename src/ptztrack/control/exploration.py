"""The patrolling term ``I_p(b | a)`` of equation 20: information about people not yet tracked.

The paper cites this term without defining it; here it is derived.

The ground is cut into cells. Let ``b_c`` be the event "cell c holds a person
the tracker does not know yet", with belief ``p_c``. New people arrive as a
Poisson process of rate ``lambda`` per m^2 per second, so between two steps
(``dt``) a cell of area ``A`` gains

    p_c <- 1 - (1 - p_c) exp(-lambda A dt).

Looking with action ``a``, a person in cell c is detected with probability
``q_c(a) = recall(r_c(a))`` if it stands fully in view (head and feet in the
image), 0 otherwise. The reward models the look as the paper's equation 7
models a track's observation: with probability ``q_c(a)`` the camera learns
the cell's state (entropy ``H_b(p_c)`` removed), otherwise it learns nothing
(an erasure channel). The mutual information between ``b_c`` and the
observation is then

    I_c(a) = q_c(a) H_b(p_c),

with ``H_b`` the binary entropy in nats, and cells are independent, so
``I_p(a) = sum_c q_c(a) H_b(p_c)``: one matrix-vector product over all
actions. (The exact information of our detector, which cannot report a
person who is not there, is ``H_b(p) - (1 - p q) H_b(p (1 - q) / (1 - p q))``;
it agrees at q = 0 and q = 1 and lies within 20 % in between for small p,
but is not linear in q and cost ten times the rest of a decision.)
It is zero for a cell the camera cannot see and for a cell it has just
cleared (``p_c`` near 0), and it grows the longer a cell goes unobserved:
the camera is drawn back to places it has not looked at for a while, and
more to views where it would actually detect (larger people, so zoom
matters as well). After the camera looks, each cell's belief takes the exact
Bayes posterior of no detection, ``p_c' = p_c (1 - q_c) / (1 - p_c q_c)``
(a detection becomes a track, so it does not stay in the map).
"""

from dataclasses import dataclass, field

import numpy as np

from ptztrack.detect.simulated import RecallModel
from ptztrack.geometry.area import bounds_m, grid_inside
from ptztrack.geometry.ptz import PTZCamera, person_in_view, project_people


def binary_entropy_nats(p) -> np.ndarray:
    p = np.clip(np.asarray(p, dtype=float), 1e-15, 1 - 1e-15)
    return -(p * np.log(p) + (1 - p) * np.log1p(-p))


def cell_detection_probability(
    camera: PTZCamera, poses, cell_centres_m, recall: RecallModel, person_height_m: float
) -> np.ndarray:
    """``q_c(a)``: (L, C) probability of detecting an unoccluded person standing at each cell."""
    people = project_people(camera, poses, cell_centres_m, person_height_m, 0.0)
    return np.where(person_in_view(camera, people), recall(people.height_px), 0.0)


@dataclass
class ExplorationMap:
    """Beliefs that cells hold people not yet tracked, and how each action would observe them.

    detection_probability : (L, C) ``q_c(a)`` for every action of the grid.
    occupancy : (C,) current beliefs ``p_c``.
    arrival_probability : (C,) chance that a person arrives in a cell during one step.
    """

    detection_probability: np.ndarray
    occupancy: np.ndarray
    arrival_probability: np.ndarray = field(repr=False)

    def information_nats(self, actions) -> np.ndarray:
        """``I_p(a)`` for the given flat action indices; (len(actions),)."""
        return self.detection_probability[actions] @ binary_entropy_nats(self.occupancy)

    def advance(self, action: int) -> None:
        """One step: people may arrive anywhere, then the camera looks with ``action``."""
        self.occupancy = 1.0 - (1.0 - self.occupancy) * (1.0 - self.arrival_probability)
        q = self.detection_probability[action]
        self.occupancy = self.occupancy * (1.0 - q) / (1.0 - self.occupancy * q)


def exploration_map(
    camera: PTZCamera,
    poses,
    area_polygon_m,
    recall: RecallModel,
    person_height_m: float,
    cell_m: float,
    prior_occupancy: float,
    arrival_rate_per_m2_s: float,
    dt_s: float,
) -> ExplorationMap:
    """A fresh map over the area (a polygon (K, 2)) with square cells ``cell_m`` wide, every cell
    believed occupied with ``prior_occupancy``, people arriving at ``arrival_rate_per_m2_s``, steps of ``dt_s``."""
    (x0, y0), (x1, y1) = bounds_m(area_polygon_m)
    centres = grid_inside(
        area_polygon_m, np.arange(x0 + cell_m / 2, x1, cell_m), np.arange(y0 + cell_m / 2, y1, cell_m)
    )
    arrival = -np.expm1(-arrival_rate_per_m2_s * cell_m**2 * dt_s)
    return ExplorationMap(
        detection_probability=cell_detection_probability(camera, poses, centres, recall, person_height_m),
        occupancy=np.full(len(centres), prior_occupancy),
        arrival_probability=np.full(len(centres), arrival),
    )
