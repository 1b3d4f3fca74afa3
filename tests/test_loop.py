import numpy as np
import pytest

from ptztrack.builders.episode import episode_world, make_policy, run_episode
from ptztrack.builders.recording import pets_scenario
from ptztrack.config import scenario_from_dict
from ptztrack.control.baselines import widest_view_action
from ptztrack.evaluate.metrics import episode_metrics
from synthetic_scene import AREA_M, CAMERA, GRID

SEEDS = range(6)


def mean_metrics(detector, policy):
    scenario = scenario_from_dict({"detector": {"kind": detector}})
    rows = [episode_metrics(run_episode(scenario, policy, seed)) for seed in SEEDS]
    return {key: np.mean([row[key] for row in rows]) for key in rows[0]}


@pytest.mark.slow
def test_fix_tracks_well_with_the_ideal_detector_and_worse_with_the_realistic_one():
    """The paper's Tables 1 and 2: fix is at 94.6 % MOTA with the ideal
    detector and 56.6 % with the realistic one, because people are small at zoom 1."""
    ideal = mean_metrics("ideal", "fix")
    realistic = mean_metrics("realistic", "fix")
    assert ideal["mota"] > 0.65
    assert realistic["mota"] < ideal["mota"] - 0.15
    assert realistic["detections"] < 0.5 * ideal["detections"]
    assert realistic["motp_m"] > ideal["motp_m"]
    assert ideal["zoom"] == realistic["zoom"] == 1.0


@pytest.mark.slow
def test_zooming_policies_see_people_larger_than_fix():
    fix = mean_metrics("ideal", "fix")
    for policy in ("patrol", "random"):
        zooming = mean_metrics("ideal", policy)
        assert zooming["zoom"] > 1.5
        assert zooming["height_px"] > fix["height_px"]


def test_same_seed_same_episode_other_seed_other_episode():
    scenario = scenario_from_dict({})
    first, again, other = (run_episode(scenario, "random", seed) for seed in (11, 11, 12))
    np.testing.assert_array_equal(first.actions, again.actions)
    for a, b in zip(first.tracks, again.tracks, strict=True):
        np.testing.assert_array_equal(a.mean, b.mean)
    assert episode_metrics(first) == episode_metrics(again)
    assert not np.array_equal(first.truth.positions_m, other.truth.positions_m)


def test_policies_meet_the_same_people_under_the_same_seed():
    scenario = scenario_from_dict({})
    fix, patrol = run_episode(scenario, "fix", 5), run_episode(scenario, "patrol", 5)
    np.testing.assert_array_equal(fix.truth.positions_m, patrol.truth.positions_m)


def test_an_observer_sees_every_step_and_changes_nothing_and_intg_exposes_its_reward_terms():
    scenario = scenario_from_dict({"frames": 12})
    world = episode_world(scenario, 3)
    policy = make_policy("intg", scenario, world)
    seen = []

    def observer(step, context, record):
        terms = policy.last_terms
        np.testing.assert_array_equal(terms.actions, context.reachable)
        np.testing.assert_array_equal(terms.track_ids, context.tracks.ids)
        assert terms.track_nats.shape == (len(context.reachable), len(context.tracks))
        assert np.all(terms.track_nats >= 0) and np.all(np.isfinite(terms.patrol_nats))
        # The action taken is the best by the terms' total (or the current one where it ties)
        total = terms.total_nats
        assert total[context.reachable == record["actions"]][0] == total.max()
        seen.append(step)

    observed = run_episode(scenario, policy, 3, world, observer=observer)
    plain = run_episode(scenario, "intg", 3)
    assert seen == list(range(12))
    np.testing.assert_array_equal(observed.actions, plain.actions)
    np.testing.assert_array_equal(observed.poses, plain.poses)


def test_every_baseline_policy_moves_within_the_mechanical_limits():
    for policy in ("fix", "patrol", "random"):
        actions = run_episode(scenario_from_dict({}), policy, seed=2).actions
        steps = np.abs(np.diff(GRID.axis_indices[actions], axis=0))
        assert np.all(steps <= np.array(GRID.max_steps)), policy
        start = widest_view_action(CAMERA, GRID, AREA_M)
        assert GRID.reachable_mask(start)[actions[0]]


def test_fix_never_moves_and_random_explores():
    assert len(set(run_episode(scenario_from_dict({}), "fix", seed=1).actions)) == 1
    assert len(set(run_episode(scenario_from_dict({}), "random", seed=1).actions)) > 20


@pytest.mark.slow
def test_between_detector_steps_the_closed_loop_measures_people_by_their_templates():
    # The templates are cut at the person width the two-fold protocol fits (0.61-0.63 m); at the
    # a-priori 0.72 m they take in background and MOTA falls to 0.29 here.
    scenario = pets_scenario(
        "ideal",
        frames=40,
        tracker={"measurement_source": "spatiogram", "detector_every_steps": 5},
        people={"width_m": 0.61},
    )
    episode = run_episode(scenario, "fix", 0)
    between = [detections for step, detections in enumerate(episode.detections) if step % 5]
    # The ideal detector names the person it saw; template matches know only their track.
    assert all(np.all(detections.person_index == -1) for detections in between)
    assert np.mean([len(detections.feet_px) for detections in between]) >= 2
    assert episode_metrics(episode)["mota"] > 0.3
