"""Ground truth of people walking on a grid of diagonal roads (multi-target PTZ paper, section 4).

The paper's scene: "targets walking on a grid of intersecting diagonal roads",
with random speeds, entrance times and places, and a random chance that
meeting targets walk on together. Here the roads are the lines x - y = k s
and x + y = k s (s = ``road_spacing_m``) clipped to the square [0, A]^2
(A = ``area_m``). In the lattice coordinates w = ((x + y) / s, (x - y) / s)
the roads are the lines of integer w1 or w2 and the intersections are the
integer points, so walking is axis-aligned and exact.

- Each person enters at a random time where a road meets the border and walks
  inwards at its own constant speed; at each intersection inside the area it
  turns onto the crossing road with ``turn_probability`` (left or right
  alike), and it is gone once it crosses the border.
- A unit (a solo walker or a group) meets another when it reaches an
  intersection while the other is at most ``meet_radius_m`` from it and
  heading there, or when it overtakes another on the same road. They join
  with ``join_probability``: at an intersection the first one stops and waits
  for the other, and the group leaves the intersection in a direction that
  neither came from. Members of a group share one position and walk at the
  speed of its slowest member.
- After ``group_duration_s`` the group splits at the next intersection; its
  members leave in distinct directions (as far as three directions go) at
  their own speeds and may not rejoin one another for ``refractory_s``.

Simplifications: an overtake in a step in which either unit passes an
intersection goes unnoticed, and a meeting takes one partner at a time
(groups of three or more form by later meetings).
"""

from dataclasses import dataclass

import numpy as np

from ptztrack.facecapture.parameters import RoadSceneParameters

_EPS = 1e-9
# Direction codes 0-3 walk along +w1, +w2, -w1, -w2: axis = code % 2, back = (code + 2) % 4.
_HEADINGS = np.array([[1.0, 1.0], [1.0, -1.0], [-1.0, -1.0], [-1.0, 1.0]]) / np.sqrt(2)


@dataclass(frozen=True)
class RoadScene:
    """Who is where on the road grid, step by step.

    positions_m : (T, N, 2) ground positions in metres, NaN while absent.
    group_id : (T, N) int, -1 while walking alone or absent, else the group
        episode; every join makes a fresh id, so an id changes exactly at joins and splits.
    heading : (T, N, 2) unit walking direction (kept while waiting), NaN while absent.
    speed_m_s : (N,) each person's own walking speed in m/s.
    frame_rate_hz : steps per second; area_m : side of the square area [0, area_m]^2;
    road_spacing_m : the roads are x - y = k road_spacing_m and x + y = k road_spacing_m.
    """

    positions_m: np.ndarray
    group_id: np.ndarray
    heading: np.ndarray
    speed_m_s: np.ndarray
    frame_rate_hz: float
    area_m: float
    road_spacing_m: float

    @property
    def present(self) -> np.ndarray:
        """(T, N) bool: the person is in the scene at that step."""
        return ~np.isnan(self.positions_m[..., 0])

    @property
    def nj_s(self) -> int:
        """N_j/s, the paper's ambiguity of the scene: the sum of :func:`joins_and_splits`."""
        return int(joins_and_splits(self).sum())


def joins_and_splits(scene: RoadScene) -> np.ndarray:
    """n_j/s per person, (N,) int: how often it joins a group and later splits off to walk alone.

    Everybody enters alone, so each step from a group to walking alone (while
    present) closes one join; a group that leaves the scene together never splits.
    """
    present, alone = scene.present, scene.group_id < 0
    return (present[:-1] & present[1:] & ~alone[:-1] & alone[1:]).sum(axis=0)


def walk_roads(config: RoadSceneParameters, rng: np.random.Generator) -> RoadScene:
    """Simulate ``config.people`` walkers for ``config.duration_s``; the same rng state gives the same scene."""
    return _Walk(config, rng).run()


def _road_ends(bound: float) -> tuple[np.ndarray, np.ndarray]:
    """Where the roads meet the border, (E, 2) in lattice coordinates, and their inward direction codes (E,).

    The area is 0 <= w1 + w2 <= bound and 0 <= w1 - w2 <= bound; roads that only touch a corner are left out.
    """
    starts: list[tuple[float, float]] = []
    directions: list[int] = []
    for k in range(-int(bound), int(bound) + 1):
        if abs(k) < bound / 2:  # road w2 = k runs over w1 in [|k|, bound - |k|]
            starts += [(abs(k), k), (bound - abs(k), k)]
            directions += [0, 2]
        if 0 < k < bound:  # road w1 = k runs over w2 in [max(-k, k - bound), min(k, bound - k)]
            starts += [(k, max(-k, k - bound)), (k, min(k, bound - k))]
            directions += [1, 3]
    return np.array(starts, dtype=float), np.array(directions)


class _Walk:
    """The simulation state, in lattice coordinates w (N, 2) and lattice units per second.

    A unit is known by its leader, its lowest-indexed member. Every member carries
    the unit's state (position, direction, speed), so walking everybody walks the groups.
    """

    def __init__(self, config: RoadSceneParameters, rng: np.random.Generator):
        self.c, self.rng, n = config, rng, config.people
        self.idx, self.dt = np.arange(n), 1.0 / config.frame_rate_hz
        self.bound = 2 * config.area_m / config.road_spacing_m
        self.metres_per_unit = config.road_spacing_m / np.sqrt(2)
        self.speed_m_s = rng.uniform(*config.speed_m_s, size=n)
        self.entry_frame = np.floor(rng.uniform(*config.entry_window_s, size=n) * config.frame_rate_hz).astype(int)
        stay_s = rng.uniform(*config.stay_s, size=n) if config.stay_s is not None else np.zeros(n)
        self.leave_s = self.entry_frame / config.frame_rate_hz + stay_s
        starts, directions = _road_ends(self.bound)
        end = rng.integers(len(starts), size=n)
        self.w, self.direction = starts[end], directions[end]
        self.axis, self.sign = self.direction % 2, 1 - 2 * (self.direction // 2)
        self.next_node = self.sign * (np.floor(self.sign * self.w[self.idx, self.axis] + _EPS) + 1)
        self.own = self.speed_m_s / self.metres_per_unit
        self.speed = self.own.copy()
        self.leader, self.group, self.next_group = self.idx.copy(), np.full(n, -1), 0
        self.split_s = np.full(n, np.inf)
        self.active = np.zeros(n, dtype=bool)
        self.waiting_for, self.reserved = np.full(n, -1), np.zeros(n, dtype=bool)
        self.no_join_until_s = np.full((n, n), -np.inf)

    def run(self) -> RoadScene:
        c, n = self.c, self.c.people
        steps = int(round(c.duration_s * c.frame_rate_hz))
        w = np.full((steps, n, 2), np.nan)
        direction, group_id = np.zeros((steps, n), dtype=int), np.full((steps, n), -1)
        for t in range(steps):
            self.active |= self.entry_frame == t
            w[t, self.active] = self.w[self.active]
            direction[t], group_id[t] = self.direction, np.where(self.active, self.group, -1)
            if t < steps - 1:
                self._step(t * self.dt)
        positions_m = c.road_spacing_m / 2 * np.stack([w[..., 0] + w[..., 1], w[..., 0] - w[..., 1]], -1)
        heading = np.where(np.isnan(w), np.nan, _HEADINGS[direction])
        return RoadScene(positions_m, group_id, heading, self.speed_m_s, c.frame_rate_hz, c.area_m, c.road_spacing_m)

    def _step(self, t_s: float):
        """Advance everybody by the step that starts at t_s: walk, meet at intersections, overtake, leave."""
        travel = self.speed * self.dt
        self.ahead = (self.next_node - self.w[self.idx, self.axis]) * self.sign
        self.moving = self.active & (self.waiting_for[self.leader] < 0)
        self.arriving = self.moving & (self.ahead <= travel)
        self.handled = np.zeros(self.c.people, dtype=bool)
        reached = np.flatnonzero(self.arriving)
        if reached.size:
            self.node = self.w.copy()
            self.node[self.idx, self.axis] = self.next_node
            self.arriving[reached] = self._inside(self.node[reached], -_EPS)  # walking through the border is an exit
        start = self.w.copy()
        walk = np.flatnonzero(self.moving & ~self.arriving)
        self.w[walk, self.axis[walk]] += self.sign[walk] * travel[walk]
        leaders = np.flatnonzero(self.arriving & (self.leader == self.idx))
        for u in leaders[np.argsort(self.ahead[leaders] / travel[leaders], kind="stable")]:
            if not self.handled[u]:
                self.handled[u] = True
                self._arrive(u, self.node[u], t_s, self.ahead[u] / self.speed[u])
        self._overtake(walk[(self.leader[walk] == walk) & ~self.reserved[walk]], start, t_s + self.dt)
        self.active &= self._inside(self.w, _EPS)

    def _overtake(self, free: np.ndarray, start: np.ndarray, t_s: float):
        """Units that walked without events join those they drew level with, on the same road the same way."""
        axis, sign = self.axis[free], self.sign[free]
        road = self.direction[free] + 4 * self.w[free, 1 - axis]
        before, after = start[free, axis] * sign, self.w[free, axis] * sign
        for i, j in np.argwhere((road[:, None] == road) & (before[:, None] < before) & (after[:, None] >= after)):
            back, front = free[i], free[j]
            if not (self.handled[back] or self.handled[front]) and self._joins(back, front, t_s):
                self.handled[[back, front]] = True
                self._merge(back, front, t_s)

    def _inside(self, w: np.ndarray, margin: float) -> np.ndarray:
        """(M,) bool: lattice points (M, 2) inside the area grown by margin (lattice units)."""
        s, d = w[:, 0] + w[:, 1], w[:, 0] - w[:, 1]
        return (s >= -margin) & (s <= self.bound + margin) & (d >= -margin) & (d <= self.bound + margin)

    def _members(self, u: int) -> np.ndarray:
        return np.flatnonzero(self.leader == u)

    def _joins(self, a: int, b: int, t_s: float) -> bool:
        """Whether units a and b, meeting at t_s, walk on together (never within refractory_s of a split)."""
        if (self.no_join_until_s[np.ix_(self._members(a), self._members(b))] > t_s).any():
            return False
        return self.rng.random() < self.c.join_probability

    def _arrive(self, u: int, node: np.ndarray, t_s: float, delay_s: float):
        """Unit u reaches the intersection node (2,) delay_s into the step that starts at t_s."""
        waiter = np.flatnonzero(self.waiting_for == u)
        if waiter.size:
            self.waiting_for[waiter], self.reserved[u] = -1, False
            return self._merge(waiter[0], u, t_s, node, delay_s)
        if self.group[u] >= 0 and t_s + delay_s >= self.split_s[u]:
            return self._split(u, node, t_s, delay_s)
        near = self.ahead * self.metres_per_unit <= self.c.meet_radius_m
        coming = (self.node == node).all(axis=1) & self.moving & ~self.handled & ~self.reserved
        others = np.flatnonzero(near & coming & (self.leader == self.idx))
        for v in others[np.argsort(self.ahead[others], kind="stable")]:
            if self._joins(u, v, t_s + delay_s):
                if self.arriving[v]:  # both reach the intersection within this step
                    return self._merge(u, v, t_s, node, self.ahead[v] / self.speed[v])
                self.w[self._members(u)] = node
                self.waiting_for[u], self.reserved[v] = v, True
                return
        direction = self.direction[u]
        if self.rng.random() < self.c.turn_probability:
            direction = (direction + self.rng.choice([1, 3])) % 4
        if t_s < self.leave_s[u] and not self._leads_inside(node, direction):
            inward = [d for d in range(4) if d != (self.direction[u] + 2) % 4 and self._leads_inside(node, d)]
            direction = self.rng.choice(inward) if inward else (self.direction[u] + 2) % 4
        self._depart(self._members(u), node, direction, delay_s)

    def _leads_inside(self, node: np.ndarray, direction: int) -> bool:
        """Whether the next intersection from node (2,) in direction lies strictly inside the area."""
        following = node.copy()
        following[direction % 2] += 1 - 2 * (direction // 2)
        return bool(self._inside(following[None], -_EPS)[0])

    def _depart(self, members: np.ndarray, node: np.ndarray, direction, delay_s: float):
        """Members leave the intersection node in direction (scalar or per member) delay_s into the step."""
        self.handled[members] = True  # their start-of-step state is stale now
        direction = np.broadcast_to(direction, members.shape)
        axis, sign = direction % 2, 1 - 2 * (direction // 2)
        self.w[members] = node
        self.w[members, axis] += sign * self.speed[members] * (self.dt - delay_s)
        self.direction[members], self.axis[members], self.sign[members] = direction, axis, sign
        self.next_node[members] = node[axis] + sign

    def _merge(self, a: int, b: int, t_s: float, node: np.ndarray | None = None, delay_s: float = 0.0):
        """Units a and b become a new group: at the intersection node, or on b's road where a caught up."""
        members = np.flatnonzero((self.leader == a) | (self.leader == b))
        back = {(self.direction[a] + 2) % 4, (self.direction[b] + 2) % 4}
        self.leader[members] = members[0]
        self.speed[members] = self.own[members].min()
        self.group[members] = self.next_group
        self.next_group += 1
        self.split_s[members[0]] = t_s + delay_s + self.rng.uniform(*self.c.group_duration_s)
        if node is None:
            self.w[members] = self.w[b].copy()
            self.next_node[members] = self.next_node[b]
        else:
            self._depart(members, node, self.rng.choice([d for d in range(4) if d not in back]), delay_s)

    def _split(self, u: int, node: np.ndarray, t_s: float, delay_s: float):
        """Group u splits at the intersection node; members take distinct ways on (round robin beyond three)."""
        members = self._members(u)
        ways = self.rng.permutation([d for d in range(4) if d != (self.direction[u] + 2) % 4])
        self.leader[members], self.group[members], self.speed[members] = members, -1, self.own[members]
        self.no_join_until_s[np.ix_(members, members)] = t_s + delay_s + self.c.refractory_s
        self._depart(members, node, ways[np.arange(members.size) % 3], delay_s)
