"""What a PTZ camera watching the road grid observes, step by step (MSG paper, section 4).

A sensor over the simulated truth (:mod:`ptztrack.facecapture.roads`) that reads
only the step it observes, and reports it as a tracker sees it
(:class:`ptztrack.facecapture.tracklets.Observation`):

- zoomed out, every unit in the area: a walker alone or a group walking
  together, its size, position and heading, and a blob id the camera keeps
  while it sees the unit step after step with the same members (a
  zoomed-out tracker following units at 5 Hz, exact as in the paper); a new
  blob lists the blobs of the step before that shared people with it (a
  join or a split);
- zoomed in (:class:`Zoom`), only the unit of the person it zoomed in on,
  whom the camera follows; at the zoom's capture step it captures that
  person's face, or fails to: the person must still be in the area, walk
  alone and face the camera, and the capture succeeds with probability
  exp(-(e / h)^2 / 2), where e is how far the person is from where the
  camera was aimed (the tracker's prediction) and h the half-width of the
  zoomed view on the ground. The draws come from the generator the camera
  is made with, one per (step, person), so every scheduler that tries the
  same capture meets the same luck.

The camera keeps what each blob was (its people and the steps it was seen),
which only the scoring reads.
"""

from dataclasses import dataclass

import numpy as np

from ptztrack.facecapture.parameters import RoadCameraParameters
from ptztrack.facecapture.roads import RoadScene
from ptztrack.facecapture.tracklets import FaceCapture, Observation, UnitSighting


@dataclass(frozen=True)
class Zoom:
    """A face capture under way: follow the person of the (solo) unit ``blob``; at ``capture_step`` capture
    their face with the camera aimed at ``aim_m`` (2,), where the tracker predicted them."""

    blob: int
    aim_m: tuple[float, float]
    capture_step: int


@dataclass(frozen=True)
class Blob:
    """A unit the camera saw continuously with the same members: who (person indices) and when (steps)."""

    members: frozenset
    first_step: int
    last_step: int

    @property
    def steps(self) -> int:
        return self.last_step - self.first_step + 1


def units_at(group_id_row: np.ndarray, present_row: np.ndarray) -> list[frozenset]:
    """The units of one step: sets of person indices walking alone or together."""
    groups: dict[int, set] = {}
    units = []
    for person in np.flatnonzero(present_row):
        gid = group_id_row[person]
        if gid < 0:
            units.append(frozenset({int(person)}))
        else:
            groups.setdefault(int(gid), set()).add(int(person))
    return units + [frozenset(members) for members in groups.values()]


class RoadCamera:
    """The camera's observations of ``scene``, one step after the other (``observe`` from step 0 on).

    camera_m : (2,) where the camera stands. zoomed_half_width_m : h of the capture model.
    rng : draws the capture outcomes, a (T, N) array of uniforms drawn at once.
    """

    def __init__(
        self,
        scene: RoadScene,
        camera_m: tuple[float, float],
        rng: np.random.Generator,
        zoomed_half_width_m: float = RoadCameraParameters.zoomed_half_width_m,
    ):
        self.scene, self.camera_m, self.zoomed_half_width_m = scene, np.asarray(camera_m, float), zoomed_half_width_m
        self.capture_draws = rng.random(scene.group_id.shape)
        self.blobs: dict[int, Blob] = {}
        self._in_view: dict[frozenset, int] = {}  # members -> blob, as seen at the last step
        self._next_step = 0

    def observe(self, step: int, zoom: Zoom | None = None) -> Observation:
        """The observation at ``step`` (the step after the last one observed), zoomed in if ``zoom``."""
        if step != self._next_step:
            raise ValueError(f"the camera observes step by step: expected step {self._next_step}, got {step}")
        self._next_step += 1
        present, group_id = ~np.isnan(self.scene.positions_m[step, :, 0]), self.scene.group_id[step]
        units = units_at(group_id, present)
        if zoom is not None:
            (person,) = self.blobs[zoom.blob].members
            units = [members for members in units if person in members]
        sightings, in_view = [], {}
        for members in units:
            blob = self._in_view.get(members)
            came_from: tuple[int, ...] = ()
            if blob is None:
                blob = len(self.blobs)
                came_from = tuple(sorted(b for seen, b in self._in_view.items() if seen & members))
                self.blobs[blob] = Blob(members, step, step)
            else:
                self.blobs[blob] = Blob(members, self.blobs[blob].first_step, step)
            in_view[members] = blob
            first = min(members)
            position_m, heading = self.scene.positions_m[step, first], self.scene.heading[step, first]
            position = (float(position_m[0]), float(position_m[1]))
            sightings.append(
                UnitSighting(blob, len(members), position, (float(heading[0]), float(heading[1])), came_from)
            )
        self._in_view = in_view
        capture = None
        if zoom is not None and step == zoom.capture_step and self._captured(step, person, zoom.aim_m):
            capture = FaceCapture(in_view[frozenset({person})], person)
        return Observation(step, zoom is not None, tuple(sightings), capture)

    def _captured(self, step: int, person: int, aim_m) -> bool:
        """Whether the face of ``person`` is captured at ``step`` with the camera aimed at ``aim_m``."""
        position_m, heading = self.scene.positions_m[step, person], self.scene.heading[step, person]
        if np.isnan(position_m[0]) or self.scene.group_id[step, person] >= 0:
            return False
        if heading @ (self.camera_m - position_m) <= 0:
            return False
        error_m = float(np.linalg.norm(position_m - np.asarray(aim_m)))
        return bool(self.capture_draws[step, person] < np.exp(-0.5 * (error_m / self.zoomed_half_width_m) ** 2))
