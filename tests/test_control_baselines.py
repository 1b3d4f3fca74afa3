import numpy as np

from ptztrack.control.baselines import area_coverage, area_samples_m, patrol_route, widest_view_action
from ptztrack.geometry.ptz import person_in_view, project_people
from synthetic_scene import AREA_M, CAMERA, GRID


def test_fix_looks_at_the_area_at_the_widest_zoom():
    action = widest_view_action(CAMERA, GRID, AREA_M)
    assert GRID.poses[action][2] == 1.0
    coverage = area_coverage(CAMERA, GRID.poses, AREA_M)
    assert coverage[action] == coverage[GRID.axis_indices[:, 2] == 0].max()
    assert coverage[action] > 0.9


def test_patrol_route_covers_the_area_at_one_zoom():
    route = patrol_route(CAMERA, GRID, AREA_M)
    assert len(set(GRID.poses[route][:, 2])) == 1
    assert np.all(area_coverage(CAMERA, GRID.poses[route], AREA_M) > 0)
    samples = area_samples_m(AREA_M)
    seen = person_in_view(CAMERA, project_people(CAMERA, GRID.poses[route][:, None, :], samples, 1.75, 0.0))
    assert seen.any(axis=0).mean() > 0.95
