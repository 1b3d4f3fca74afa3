import numpy as np

from ptztrack.builders.episode import run_episode
from ptztrack.builders.world import action_grid, ptz_camera
from ptztrack.config import Scenario
from ptztrack.control.baselines import area_coverage, area_samples_m, patrol_route, widest_view_action
from ptztrack.geometry.area import rectangle_m
from ptztrack.geometry.ptz import person_in_view, project_people

SCENARIO = Scenario()
CAMERA, GRID = ptz_camera(SCENARIO), action_grid(SCENARIO)
AREA_M = rectangle_m(*SCENARIO.area_m)


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


def test_every_policy_moves_within_the_mechanical_limits():
    for policy in ("fix", "patrol", "random"):
        actions = run_episode(SCENARIO, policy, seed=2).actions
        steps = np.abs(np.diff(GRID.axis_indices[actions], axis=0))
        assert np.all(steps <= np.array(GRID.max_steps)), policy
        start = widest_view_action(CAMERA, GRID, AREA_M)
        assert GRID.reachable_mask(start)[actions[0]]


def test_fix_never_moves_and_random_explores():
    assert len(set(run_episode(SCENARIO, "fix", seed=1).actions)) == 1
    assert len(set(run_episode(SCENARIO, "random", seed=1).actions)) > 20
