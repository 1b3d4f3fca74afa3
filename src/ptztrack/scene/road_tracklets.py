"""The tracklet oracle of the face-capture simulation: what the MSG paper assumes a tracker provides,
read off the simulated truth.

It is not a tracker: it reads the true walkers of the road grid
(:mod:`ptztrack.scene.roads`), their groups and their future, and from them
and the camera's mode it maintains the tracklet graph (:mod:`ptztrack.track.msg`):

- zoomed out, it sees every *unit* (a walker alone, or a group walking
  together, indistinguishable as everyone looks alike at low resolution);
  a unit that keeps its members extends its tracklet, entries start source
  vertices, joins and splits start new vertices with the old ones as parents;
- zoomed in on one person, it sees only that person; the others' tracklets
  end, and when the camera zooms out every unit seen again gets a new vertex
  with an edge from each lost tracklet that could have walked there in the
  time (a blind gap: X-type ambiguities). A unit with a single candidate that
  has no other candidate simply continues it.

It also gives the predictions the scheduler needs, as a tracker would:
whether a face capture would succeed E_s (walking alone towards the camera,
not leaving or meeting anyone during the zoom), whether a walker is about
to join others, and when it is expected to leave (straight-line
extrapolation to the border). Face matching is exact, so vertices carry
their true targets, which only the matcher and the scoring read.
"""

from dataclasses import dataclass, field

import networkx as nx
import numpy as np

from ptztrack.track import msg


@dataclass(frozen=True)
class TrackletOracleConfig:
    """zoom_steps : how long a face capture keeps the camera zoomed in.
    camera_m : (x, y) of the camera, which sees the faces of people walking towards it; None: the
        area's centre (everyone faces it while walking in, nobody while walking out).
    join_horizon_s : how far ahead the tracker foresees a join.
    gate_margin_m : how far from where a lost walker could have walked a unit may reappear and
        still be a candidate for it.
    """

    zoom_steps: int = 10
    camera_m: tuple[float, float] | None = None
    join_horizon_s: float = 8.0
    gate_margin_m: float = 1.0


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


@dataclass
class TrackletOracle:
    """The tracklet graph and which vertex each visible unit's tracklet is, step by step.

    positions_m : (T, N, 2) NaN absent; group_id : (T, N) -1 when alone; heading : (T, N, 2).
    """

    positions_m: np.ndarray
    group_id: np.ndarray
    heading: np.ndarray
    area_m: float
    frame_rate_hz: float
    max_speed_m_s: float
    road_spacing_m: float
    config: TrackletOracleConfig = TrackletOracleConfig()
    graph: nx.DiGraph = field(default_factory=msg.new_graph)
    unit_vertex: dict = field(default_factory=dict)
    lost: dict = field(default_factory=dict)

    def present(self, step: int) -> np.ndarray:
        return ~np.isnan(self.positions_m[step, :, 0])

    def observe(self, step: int, zoomed_unit: frozenset | None = None) -> None:
        """Step ``step``: everything in view zoomed out, or only ``zoomed_unit`` zoomed in."""
        units = units_at(self.group_id[step], self.present(step))
        if zoomed_unit is not None:
            for unit in [u for u in self.unit_vertex if u != zoomed_unit]:
                person = next(iter(unit))
                self.lost[self.unit_vertex.pop(unit)] = (self.centre_m(step - 1, unit), self.heading[step - 1, person])
            units = [u for u in units if u == zoomed_unit]
        elif self.lost:
            self._reappear(step, units)
        events = [
            (unit, {v for previous, v in self.unit_vertex.items() if previous & unit})
            for unit in units
            if unit not in self.unit_vertex
        ]
        seen = set(units)
        for unit in [u for u in self.unit_vertex if u not in seen]:
            vertex = self.unit_vertex.pop(unit)
            if not any(vertex in parents for _, parents in events):
                self.graph.nodes[vertex]["active"] = False
        self._start(step, events)
        for unit in units:
            msg.extend(self.graph, self.unit_vertex[unit], step)

    def _reappear(self, step: int, units: list[frozenset]) -> None:
        """After a blind gap, give every unit seen again its tracklet: a lost one it continues
        unambiguously, or a new vertex with an edge from every lost tracklet that could have walked there."""
        gap_steps = step - 1 - max(self.graph.nodes[v]["last_step"] for v in self.lost)
        walk_m = self.max_speed_m_s * (gap_steps + 1) / self.frame_rate_hz
        # The paper assumes a tracker whose candidates include the truth: the true predecessors always are,
        # and the gate adds every other lost tracklet that could have walked there. Someone who entered
        # during the gap is recognised as new.
        candidates = {
            unit: {
                v
                for v, (last_m, heading) in self.lost.items()
                if self.graph.nodes[v]["targets"] & unit
                or self._within_walk(last_m, heading, walk_m, self.centre_m(step, unit))
            }
            for unit in units
            if unit not in self.unit_vertex and any(self.graph.nodes[v]["targets"] & unit for v in self.lost)
        }
        events = []
        for unit, parents in candidates.items():
            only = next(iter(parents)) if len(parents) == 1 else None
            claimed = sum(only in others for others in candidates.values())
            if only is not None and claimed == 1 and self.graph.nodes[only]["count"] == len(unit):
                self.unit_vertex[unit] = only
            else:
                events.append((unit, parents))
        continued = set(self.unit_vertex.values())
        for vertex in set(self.lost) - continued - {v for _, parents in events for v in parents}:
            self.graph.nodes[vertex]["active"] = False
        self.lost = {}
        self._start(step, events)

    def _within_walk(self, start_m, heading, walk_m: float, point_m) -> bool:
        """Whether a walker at ``start_m`` heading along its road could be at ``point_m`` after walking at most
        ``walk_m``: ahead on its road, or round the corner at the next intersection (one at most: a block is
        longer than a gap's walk), within ``gate_margin_m``."""
        margin_m = self.config.gate_margin_m
        across = np.array([-heading[1], heading[0]])
        along_m, aside_m = (np.asarray(point_m) - start_m) @ heading, (np.asarray(point_m) - start_m) @ across
        if abs(aside_m) <= margin_m and -margin_m <= along_m <= walk_m + margin_m:
            return True
        # Intersections are where the coordinate along the heading is a whole number of blocks.
        block_m = self.road_spacing_m / np.sqrt(2)
        position_blocks = (np.asarray(start_m) @ heading) / block_m
        corner_m = (np.ceil(position_blocks - 1e-9) - position_blocks) * block_m
        return (
            corner_m <= walk_m and abs(along_m - corner_m) <= margin_m and abs(aside_m) <= walk_m - corner_m + margin_m
        )

    def _start(self, step: int, events: list) -> None:
        created = msg.add_tracklets(self.graph, [(frozenset(unit), parents) for unit, parents in events], step)
        self.unit_vertex.update((unit, vertex) for (unit, _), vertex in zip(events, created, strict=True))

    def centre_m(self, step: int, unit: frozenset) -> np.ndarray:
        return np.nanmean(self.positions_m[step, sorted(unit)], axis=0)

    def relabel(self, merged_into: dict) -> None:
        """Follow vertices that untangling merged into others."""
        self.unit_vertex = {unit: merged_into.get(v, v) for unit, v in self.unit_vertex.items()}

    # Predictions a tracker makes for the scheduler.

    def steps_to_exit(self, step: int, person: int) -> float:
        """Straight-line extrapolation of the walker's last displacement to the border, in steps."""
        position = self.positions_m[step, person]
        velocity = position - self.positions_m[max(step - 1, 0), person]
        if step == 0 or np.isnan(velocity[0]):
            return np.inf
        with np.errstate(divide="ignore", invalid="ignore"):
            to_low = np.where(velocity < 0, -position / velocity, np.inf)
            to_high = np.where(velocity > 0, (self.area_m - position) / velocity, np.inf)
        return float(np.min(np.minimum(to_low, to_high)))

    def joins_within(self, step: int, person: int, steps: int) -> bool:
        """The tracker foresees the walker joining others within ``steps``."""
        ahead = self.group_id[step : step + steps + 1, person]
        return bool(np.any(ahead >= 0))

    def capture_succeeds(self, step: int, person: int) -> bool:
        """E_s: alone, facing the camera, and neither leaving nor meeting anyone during the zoom."""
        zoom = self.config.zoom_steps
        if step + zoom >= len(self.positions_m) or np.isnan(self.positions_m[step + zoom, person, 0]):
            return False
        camera_m = self.config.camera_m if self.config.camera_m is not None else (self.area_m / 2, self.area_m / 2)
        towards_camera = np.asarray(camera_m) - self.positions_m[step, person]
        return bool(self.heading[step, person] @ towards_camera > 0) and not self.joins_within(step, person, zoom)
