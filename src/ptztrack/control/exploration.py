"""The patrolling term ``I_p(b | a)`` of equation 20: information about people not yet tracked.

The paper cites this term without defining it; here it is derived.

The ground is cut into C cells. Let ``b_c`` be the event "cell c holds a person
the tracker does not know yet", with belief ``p_c``. At the start, ``N0``
people nobody has seen yet are expected somewhere on the area, ``p_c = N0 / C``;
new people arrive as a Poisson process of ``lambda`` people per second over
the whole area, each in any cell alike, so between two steps (``dt``) a cell gains

    p_c <- 1 - (1 - p_c) exp(-lambda dt / C).

Both are totals over the area, not densities: the area is what the camera can
see, which may reach far beyond where anybody walks, and a density would make
the number of unseen people grow with the camera's reach.

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

from ptztrack.detect.simulated import RecallCurve
from ptztrack.geometry.area import bounds_m, grid_inside
from ptztrack.geometry.ptz import PTZCamera, person_in_view, project_people


def binary_entropy_nats(p) -> np.ndarray:
    p = np.clip(np.asarray(p, dtype=float), 1e-15, 1 - 1e-15)
    return -(p * np.log(p) + (1 - p) * np.log1p(-p))


@dataclass
class ExplorationMap:
    """Beliefs that cells hold people not yet tracked, and how each action would observe them.

    height_px : (L, C) the height of a person standing at each cell's centre in each action's view;
    in_view : (L, C) whether that person stands fully in view.
    recall : the detector model, read at every decision (a learned model changes as the camera runs).
    occupancy : (C,) current beliefs ``p_c``.
    arrival_rate_per_s : (C,) the rate at which people arrive in each cell; step_s : a step's seconds.
    """

    height_px: np.ndarray = field(repr=False)
    in_view: np.ndarray = field(repr=False)
    recall: RecallCurve
    occupancy: np.ndarray
    arrival_rate_per_s: np.ndarray = field(repr=False)
    step_s: float

    def detection_probability(self, actions) -> np.ndarray:
        """``q_c(a)`` (len(actions), C) for flat action indices ``actions`` (a scalar index: (C,))."""
        return np.where(self.in_view[actions], self.recall(self.height_px[actions]), 0.0)

    def information_nats(self, actions) -> np.ndarray:
        """``I_p(a)`` for the given flat action indices; (len(actions),)."""
        return self.detection_probability(actions) @ binary_entropy_nats(self.occupancy)

    def advance(self, action: int, dt_s: float | None = None) -> None:
        """One step of ``dt_s`` seconds (None: ``step_s``): people may arrive anywhere, each cell's with
        probability ``1 - exp(-rate dt)``, then the camera looks with ``action``.

        A look ``dt`` after the last counts as ``w = min(1, dt / step_s)`` of one, as a tracker counts a
        picture (:class:`ptztrack.track.tracker.EkfTracker`): a miss multiplies a cell's odds by
        ``(1 - q_c)^w``, so that the ``1 / w`` decisions a live camera makes in a step clear a cell as the
        one look of a step does."""
        dt_s = self.step_s if dt_s is None else dt_s
        arrival_probability = -np.expm1(-self.arrival_rate_per_s * dt_s)
        self.occupancy = 1.0 - (1.0 - self.occupancy) * (1.0 - arrival_probability)
        q = self.detection_probability(action)
        weight = dt_s / self.step_s
        if weight < 1.0:
            q = 1.0 - (1.0 - q) ** weight
        self.occupancy = self.occupancy * (1.0 - q) / (1.0 - self.occupancy * q)


def exploration_map(
    camera: PTZCamera,
    poses,
    area_polygon_m,
    recall: RecallCurve,
    person_height_m: float,
    cell_m: float,
    prior_untracked_people: float,
    arrival_rate_per_s: float,
    dt_s: float,
) -> ExplorationMap:
    """A fresh map over the area (a polygon (K, 2)) with square cells ``cell_m`` wide: ``N0 =
    prior_untracked_people`` expected somewhere on it (``p_c = min(N0 / C, 1/2)``), people arriving at
    ``arrival_rate_per_s`` over the whole area, steps of ``dt_s``."""
    (x0, y0), (x1, y1) = bounds_m(area_polygon_m)
    centres = grid_inside(
        area_polygon_m, np.arange(x0 + cell_m / 2, x1, cell_m), np.arange(y0 + cell_m / 2, y1, cell_m)
    )
    cells = max(len(centres), 1)
    people = project_people(camera, poses, centres, person_height_m, 0.0)
    return ExplorationMap(
        height_px=people.height_px,
        in_view=person_in_view(camera, people),
        recall=recall,
        occupancy=np.full(len(centres), min(prior_untracked_people / cells, 0.5)),
        arrival_rate_per_s=np.full(len(centres), arrival_rate_per_s / cells),
        step_s=dt_s,
    )
