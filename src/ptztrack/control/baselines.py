"""The paper's comparison strategies: 'fix', 'patrol' and 'rnd', the random one (section 5)."""

from dataclasses import dataclass, field

import numpy as np

from ptztrack.camera.actions import ActionGrid
from ptztrack.geometry.area import bounds_m, grid_inside
from ptztrack.geometry.ptz import PTZCamera, person_in_view, project_people
from ptztrack.scene.parameters import PersonParameters
from ptztrack.types import DecisionContext


def area_samples_m(area_polygon_m, per_axis: int = 30) -> np.ndarray:
    """(M, 2) the cell centres of a per_axis x per_axis grid over the area's bounding box that lie in the area."""
    (x0, y0), (x1, y1) = bounds_m(area_polygon_m)
    xs = x0 + (np.arange(per_axis) + 0.5) / per_axis * (x1 - x0)
    ys = y0 + (np.arange(per_axis) + 0.5) / per_axis * (y1 - y0)
    return grid_inside(area_polygon_m, xs, ys)


def area_coverage(camera: PTZCamera, poses, area_polygon_m) -> np.ndarray:
    """Fraction of the area where a standing person has head and feet in the image; (*P,)."""
    people = project_people(camera, poses, area_samples_m(area_polygon_m), PersonParameters.height_m, 0.0)
    return person_in_view(camera, people).mean(axis=-1)


def widest_view_action(camera: PTZCamera, grid: ActionGrid, area_polygon_m) -> int:
    """The zoom-1 action that sees most of the area: where 'fix' looks, and where every run starts."""
    widest = np.flatnonzero(grid.axis_indices[:, 2] == 0)
    return int(widest[np.argmax(area_coverage(camera, grid.poses[widest], area_polygon_m))])


@dataclass
class FixPolicy:
    """Stay at the widest view aimed at the area."""

    action: int

    def choose(self, context: DecisionContext) -> int:
        return self.action


@dataclass
class RandomPolicy:
    """Uniform over the reachable actions."""

    def choose(self, context: DecisionContext) -> int:
        return int(context.rng.choice(context.reachable))


@dataclass
class PatrolPolicy:
    """Scan a preset route of waypoints, dwelling ``dwell_steps`` at each.

    The camera moves towards the next waypoint as fast as the mechanics allow.
    """

    grid: ActionGrid
    waypoints: np.ndarray
    dwell_steps: int = 2
    _next: int = field(default=0, init=False)
    _dwelt: int = field(default=0, init=False)

    def choose(self, context: DecisionContext) -> int:
        if context.current_action == self.waypoints[self._next]:
            self._dwelt += 1
            if self._dwelt >= self.dwell_steps:
                self._next = (self._next + 1) % len(self.waypoints)
                self._dwelt = 0
        return self.grid.step_towards(context.current_action, int(self.waypoints[self._next]))


def patrol_route(camera: PTZCamera, grid: ActionGrid, area_polygon_m, zoom_index: int | None = None) -> np.ndarray:
    """A boustrophedon over the pan x tilt grid at one zoom, covering the area.

    Along pan and tilt the waypoints are spread evenly from the first to the
    last grid value, at most as many grid steps apart as fit in the field of
    view at that zoom, so consecutive views touch; waypoints whose view does
    not meet the area are skipped (all kept if none meets it). ``zoom_index`` defaults to the lower
    middle of the zoom range (2x of 1-4x: 8 waypoints on the default grid,
    where 3x would need 19 and see each person about once in 50 steps).
    Returns the flat action indices in visiting order.
    """
    zoom_index = (len(grid.zoom) - 1) // 2 if zoom_index is None else zoom_index
    focal_px = grid.zoom[zoom_index] * camera.f_min_px
    fov_pan_deg = 2 * np.rad2deg(np.arctan(camera.image_width_px / 2 / focal_px))
    fov_tilt_deg = 2 * np.rad2deg(np.arctan(camera.image_height_px / 2 / focal_px))
    pan_stride = max(1, int(fov_pan_deg // np.min(np.diff(grid.pan_deg), initial=np.inf)))
    tilt_stride = max(1, int(fov_tilt_deg // np.min(np.diff(grid.tilt_deg), initial=np.inf)))
    pans = _spread_indices(len(grid.pan_deg), pan_stride)
    route = np.asarray(
        [
            grid.index(pan, tilt, zoom_index)
            for row, tilt in enumerate(_spread_indices(len(grid.tilt_deg), tilt_stride))
            for pan in (pans if row % 2 == 0 else pans[::-1])
        ]
    )
    sees_area = area_coverage(camera, grid.poses[route], area_polygon_m) > 0
    # Where no waypoint sees a whole standing person in the area (a tiny image, an area out of reach),
    # the route keeps every waypoint: patrolling something beats an empty route.
    return route[sees_area] if sees_area.any() else route


def _spread_indices(count: int, max_stride: int) -> np.ndarray:
    """Evenly spread indices from 0 to ``count - 1``, at most ``max_stride`` apart."""
    intervals = int(np.ceil((count - 1) / max_stride))
    return np.unique(np.round(np.linspace(0, count - 1, intervals + 1)).astype(int))
