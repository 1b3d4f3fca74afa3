"""A tracklet tracker for face capture (MSG paper, sections 3.1 and 4): the MSG from what the camera saw.

It reads nothing but its observations, step by step (:class:`Observation`,
made by a sensor such as :mod:`ptztrack.facecapture.road_camera`), and keeps the
Multi-Strand Tracking Graph (:mod:`ptztrack.facecapture.msg`):

- zoomed out, the camera sees every unit (a walker alone or a group walking
  together; everyone looks alike at low resolution) and follows it from
  step to step while it keeps its members, as the paper's zoomed-out tracker
  does; a unit that keeps its members extends its tracklet, entries start
  source vertices, joins and splits start new vertices with the tracklets
  they came from as parents;
- zoomed in, it sees only the unit it follows; every other tracklet is lost.
  When the camera zooms out again, each unit it had not been following gets
  as candidates the lost tracklets whose constant-velocity prediction it
  lies within a gate of (``gate_margin_m`` plus the distance the tracklet
  walks in the gap at its own speed): the truth may be missed (a walker who
  turns early at speed, or who was waiting and walks on) and others may be
  in (X ambiguities). A unit with one candidate that nobody else claims,
  of its size, continues that tracklet; any other unit starts a vertex with
  an edge from each candidate (none: someone new);
- a captured face labels the tracklet of the unit it was captured on, which
  matches and untangles the graph (:func:`ptztrack.facecapture.msg.label`).

Its predictions for the scheduler extrapolate each unit at constant
velocity: its heading times the speed it walked over the last step (or
``prior_speed_m_s`` when it was not seen then). From them: when it will
leave the area, whether it will meet another unit (closest approach within
``meeting_distance_m``) within a horizon, and E_s, whether a face capture is
expected to succeed: walking alone, still in the area and facing the camera
at the capture, meeting nobody before it.
"""

import math
from collections import Counter
from dataclasses import dataclass, field

import networkx as nx
import numpy as np

from ptztrack.facecapture import msg
from ptztrack.facecapture.parameters import TrackletTrackerParameters


@dataclass(frozen=True)
class UnitSighting:
    """One unit as the camera sees it at one step.

    blob : the sensor's id for the unit, kept while the unit is seen step after step with the same members.
    count : people in the unit. position_m : (2,) ground position, metres. heading : (2,) unit vector, the
        way it walks (and faces).
    came_from : the blobs seen at the previous step that share people with this one: its tracklets' parents
        at a join or a split. Empty for a unit that enters or comes back into view (and for an old blob).
    """

    blob: int
    count: int
    position_m: tuple[float, float]
    heading: tuple[float, float]
    came_from: tuple[int, ...] = ()


@dataclass(frozen=True)
class FaceCapture:
    """A face captured at this step: the identity ``face`` (face recognition is exact), on the unit ``blob``."""

    blob: int
    face: int


@dataclass(frozen=True)
class Observation:
    """What the camera reported at ``step``: the units in view (all of them zoomed out, the followed one
    zoomed in) and the face it captured, if any."""

    step: int
    zoomed_in: bool
    units: tuple[UnitSighting, ...]
    capture: FaceCapture | None = None


@dataclass(frozen=True)
class Track:
    """A unit's state when last seen: at ``step``, position_m (2,), velocity_m_s (2,), heading (2,), count."""

    step: int
    position_m: np.ndarray
    velocity_m_s: np.ndarray
    heading: np.ndarray
    count: int


@dataclass
class TrackletTracker:
    """The MSG and the tracklet (vertex) of every unit in view, from observations only.

    area_m : side of the square area [0, area_m]^2 people walk in. frame_rate_hz : steps per second.
    camera_m : (2,) where the camera stands: a face is seen by walking towards it.
    untangling : whether captured faces untangle the graph (section 3.2).
    """

    area_m: float
    frame_rate_hz: float
    camera_m: tuple[float, float]
    config: TrackletTrackerParameters = TrackletTrackerParameters()
    untangling: bool = True
    graph: nx.DiGraph = field(default_factory=msg.new_graph)
    vertex_of: dict[int, int] = field(default_factory=dict)  # blob in view -> its tracklet
    tracks: dict[int, Track] = field(default_factory=dict)  # blob in view -> its state
    lost: dict[int, Track] = field(default_factory=dict)  # tracklet out of view in a zoom -> its last state

    def update(self, observation: Observation) -> None:
        """Take in one step's observation: grow the graph, and label it if a face was captured."""
        step, seen = observation.step, {unit.blob: unit for unit in observation.units}
        parents = {unit.blob: [self.vertex_of[b] for b in unit.came_from] for unit in observation.units}
        ending = {v for vertices in parents.values() for v in vertices}
        for blob in [b for b in self.vertex_of if b not in seen]:
            vertex = self.vertex_of.pop(blob)
            if vertex in ending:
                continue
            if observation.zoomed_in:
                self.lost[vertex] = self.tracks[blob]
            else:
                self.graph.nodes[vertex]["active"] = False  # it left the area
        fresh = [unit for unit in observation.units if unit.blob not in self.vertex_of]
        if self.lost and not observation.zoomed_in:
            events = self._reassociate(step, [unit for unit in fresh if not unit.came_from])
            events += [(unit, parents[unit.blob]) for unit in fresh if unit.came_from]
        else:
            events = [(unit, parents[unit.blob]) for unit in fresh]
        created = msg.add_tracklets(self.graph, [(unit.count, [unit.blob], vs) for unit, vs in events], step)
        self.vertex_of.update((unit.blob, vertex) for (unit, _), vertex in zip(events, created, strict=True))
        previous, self.tracks = self.tracks, {}
        for unit in observation.units:
            msg.extend(self.graph, self.vertex_of[unit.blob], step)
            self.tracks[unit.blob] = self._track(step, unit, previous)
        capture = observation.capture
        if capture is not None and not self.graph.nodes[self.vertex_of[capture.blob]]["labeled"]:
            vertex = self.vertex_of[capture.blob]
            msg.refresh(self.graph, vertex)
            merged_into = msg.label(self.graph, vertex, capture.face, self.untangling)
            self.vertex_of = {blob: merged_into.get(v, v) for blob, v in self.vertex_of.items()}
            self.lost = {merged_into.get(v, v): track for v, track in self.lost.items()}

    def _track(self, step: int, unit: UnitSighting, previous: dict[int, Track]) -> Track:
        """The unit's state: its velocity along its heading at the speed it walked since the step before
        (at the speed it walked before a blind gap if it resumes a tracklet, else at the prior speed)."""
        position_m, heading = np.asarray(unit.position_m, float), np.asarray(unit.heading, float)
        before = [previous[b] for b in (unit.blob, *unit.came_from) if b in previous]
        if before and before[0].step == step - 1:
            speed_m_s = math.dist(position_m, before[0].position_m) * self.frame_rate_hz
        elif before:
            speed_m_s = float(np.linalg.norm(before[0].velocity_m_s))
        else:
            speed_m_s = self.config.prior_speed_m_s
        return Track(step, position_m, heading * speed_m_s, heading, unit.count)

    def _reassociate(self, step: int, units: list[UnitSighting]) -> list[tuple[UnitSighting, list[int]]]:
        """After a blind gap: units in ``units`` that continue a lost tracklet take it over (and its last
        state); the others are returned with their candidate parents. Lost tracklets nobody could be are over."""
        lost = list(self.lost)
        gated = self._gated(step, units) if units else np.zeros((0, len(lost)), dtype=bool)
        candidates = {unit.blob: [lost[j] for j in np.flatnonzero(row)] for unit, row in zip(units, gated, strict=True)}
        claims = Counter(v for vertices in candidates.values() for v in vertices)
        events = []
        for unit in units:
            parents = candidates[unit.blob]
            only = parents[0] if len(parents) == 1 else None
            if only is not None and claims[only] == 1 and self.graph.nodes[only]["count"] == unit.count:
                self.vertex_of[unit.blob] = only
                self.tracks[unit.blob] = self.lost[only]
                self.graph.nodes[only]["blobs"] |= {unit.blob}
            else:
                events.append((unit, parents))
        for vertex in set(self.lost) - set(claims):
            self.graph.nodes[vertex]["active"] = False
        self.lost = {}
        return events

    def _gated(self, step: int, units: list[UnitSighting]) -> np.ndarray:
        """(units, lost) bool: the unit lies within the gate of the lost tracklet's prediction at ``step``."""
        tracks = list(self.lost.values())
        gap_s = (step - np.array([track.step for track in tracks])) / self.frame_rate_hz  # (L,)
        velocity_m_s = np.array([track.velocity_m_s for track in tracks])  # (L, 2)
        predicted_m = np.array([track.position_m for track in tracks]) + velocity_m_s * gap_s[:, None]
        radius_m = self.config.gate_margin_m + np.linalg.norm(velocity_m_s, axis=1) * gap_s
        positions_m = np.array([unit.position_m for unit in units])  # (U, 2)
        return np.linalg.norm(positions_m[:, None] - predicted_m[None], axis=2) <= radius_m

    # Predictions for the scheduler, for a unit in view (by blob), at constant velocity.

    def predicted_position_m(self, blob: int, steps: int) -> np.ndarray:
        """(2,) where the unit will be ``steps`` steps after it was last seen."""
        track = self.tracks[blob]
        return track.position_m + track.velocity_m_s * steps / self.frame_rate_hz

    def steps_to_exit(self, blob: int) -> float:
        """Steps until the unit walks out of the area (inf if it stands still)."""
        track = self.tracks[blob]
        velocity = track.velocity_m_s / self.frame_rate_hz
        with np.errstate(divide="ignore", invalid="ignore"):
            to_low = np.where(velocity < 0, -track.position_m / velocity, np.inf)
            to_high = np.where(velocity > 0, (self.area_m - track.position_m) / velocity, np.inf)
        return float(np.min(np.minimum(to_low, to_high)))

    def meets_within(self, blob: int, steps: int) -> bool:
        """Whether the unit comes within ``meeting_distance_m`` of another unit in view within ``steps``."""
        track = self.tracks[blob]
        others = [t for b, t in self.tracks.items() if b != blob]
        if not others:
            return False
        offset_m = np.array([t.position_m for t in others]) - track.position_m  # (K, 2)
        closing_m_s = np.array([t.velocity_m_s for t in others]) - track.velocity_m_s
        speed2 = np.einsum("ij,ij->i", closing_m_s, closing_m_s)
        with np.errstate(divide="ignore", invalid="ignore"):
            when_s = np.where(speed2 > 0, -np.einsum("ij,ij->i", offset_m, closing_m_s) / speed2, 0.0)
        when_s = np.clip(when_s, 0.0, steps / self.frame_rate_hz)
        closest_m = np.linalg.norm(offset_m + closing_m_s * when_s[:, None], axis=1)
        return bool(np.any(closest_m <= self.config.meeting_distance_m))

    def capture_expected(self, blob: int) -> bool:
        """E_s: a face capture on this unit started now would succeed (alone, in the area and facing the camera
        when captured, zoom_steps from now, meeting nobody before)."""
        track, zoom = self.tracks[blob], self.config.zoom_steps
        at_capture_m = self.predicted_position_m(blob, zoom)
        inside = bool(np.all((at_capture_m >= 0) & (at_capture_m <= self.area_m)))
        facing = float(track.heading @ (np.asarray(self.camera_m) - at_capture_m)) > 0
        return track.count == 1 and inside and facing and not self.meets_within(blob, zoom)
