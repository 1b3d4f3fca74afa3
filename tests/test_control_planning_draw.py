"""The information-gain policies plan with the learned detector model's draw (Thompson sampling).

An :class:`~ptztrack.detect.detector_model.OnlineDetectorModel` keeps two curves: its posterior mode, which
the tracker reads, and after every step a curve fitted to a draw from the posterior, which the policies
plan with (the module's docstring: without the draw a prior that says small people are never found would
confirm itself). The draw comes from the model's own generator.
"""

from dataclasses import replace

import numpy as np
import pytest

from ptztrack.builders.episode import episode_world, make_policy
from ptztrack.config import scenario_from_dict
from ptztrack.control.information_policy import InformationGainPolicy
from ptztrack.detect.detector_model import OnlineDetectorModel
from ptztrack.detect.parameters import DetectorPriorParameters
from ptztrack.detect.simulated import RecallModel
from ptztrack.geometry.ptz import look_at
from ptztrack.types import TrackerEvidence, Tracks
from synthetic_scene import CAMERA, GRID

HEIGHT_M, WIDTH_M = 1.75, 0.5
PRIOR = RecallModel(DetectorPriorParameters.recall_kd, DetectorPriorParameters.recall_r0_px)
V = 4.0 * np.eye(2)
HEIGHTS_PX = np.geomspace(5.0, 250.0, 40)


def learned_model(seed: int, steps: int = 30) -> OnlineDetectorModel:
    """A model whose generator is seeded with ``seed``, told of ``steps`` steps of a camera at zoom 1 and 2
    on three people 10 m ahead, the middle one never found (the same evidence whatever the seed)."""
    model = OnlineDetectorModel(CAMERA, HEIGHT_M, WIDTH_M, PRIOR, rng=np.random.default_rng(seed))
    people_m = np.array([[5.5, 4.0], [7.5, 4.0], [9.5, 4.0]])
    for step in range(steps):
        pose = look_at(CAMERA, [7.5, 4.0], 1.0 + step % 2)
        model.observe(
            TrackerEvidence(
                pose=pose,
                mean_m=people_m,
                position_sigma_m=np.full(3, 0.1),
                existence=np.ones(3),
                hits=np.full(3, 5),
                detected=np.array([True, False, True]),
                excess_px2=np.zeros(2),
                false_births=0,
            )
        )
    return model


def no_tracks() -> TrackerEvidence:
    """A step's evidence of no track at all: the model learns nothing from it, but draws again."""
    return TrackerEvidence(
        pose=look_at(CAMERA, [7.5, 4.0], 1.0),
        mean_m=np.zeros((0, 2)),
        position_sigma_m=np.zeros(0),
        existence=np.zeros(0),
        hits=np.zeros(0, dtype=int),
        detected=np.zeros(0, dtype=bool),
        excess_px2=np.zeros(0),
        false_births=0,
    )


def tracks_far_away() -> Tracks:
    """Three people 8 to 16 m from the camera: a few tens of pixels tall at zoom 1, where recall is uncertain."""
    mean = np.array([[3.0, 4.0, 0.0, 0.0], [8.0, 8.0, 0.0, 0.0], [12.0, 10.0, 0.0, 0.0]])
    covariance = np.tile(np.diag([0.3, 0.3, 0.5, 0.5]), (3, 1, 1))
    return Tracks(np.arange(3), mean, covariance, np.ones(3), np.full(3, 4), next_id=3)


def policy(recall, method: str) -> InformationGainPolicy:
    return InformationGainPolicy(CAMERA, GRID, recall, V, HEIGHT_M, WIDTH_M, method, samples=100)


def rewards(recall, method: str) -> np.ndarray:
    actions = np.arange(len(GRID.poses))
    return policy(recall, method).rewards(actions, tracks_far_away(), np.random.default_rng(3))


def test_the_same_evidence_with_other_generators_gives_the_same_mode_and_other_planning_curves():
    """The draw is random: two cameras told the same plan with different curves, about the same mode."""
    first, second = learned_model(1), learned_model(2)
    # 30 steps of 3 people fully in view, 2 of them found each time.
    assert first.trials.sum() == pytest.approx(90.0) and first.successes.sum() == pytest.approx(60.0)
    assert first.curve == second.curve
    np.testing.assert_array_equal(first(HEIGHTS_PX), second(HEIGHTS_PX))
    assert first.planning_curve != second.planning_curve
    assert not np.allclose(first.planner()(HEIGHTS_PX), second.planner()(HEIGHTS_PX), atol=0.01)
    # The same generator draws the same curve: the draw is the generator's, not the clock's.
    assert learned_model(1).planning_curve == first.planning_curve


def test_every_step_draws_a_new_planning_curve_and_the_planner_follows_it():
    model = learned_model(5)
    planner = model.planner()
    drawn = []
    for _ in range(4):
        model.observe(no_tracks())
        np.testing.assert_array_equal(planner(HEIGHTS_PX), model.planning_curve(HEIGHTS_PX))
        drawn.append(model.planning_curve)
    assert len(set(drawn)) > 1


@pytest.mark.parametrize("method", ["intg", "smpl"])
def test_the_policys_rewards_are_those_of_the_drawn_curve_not_of_the_mode(method):
    model = learned_model(2)
    assert model.planning_curve != model.curve
    planned = rewards(model.planner(), method)
    np.testing.assert_allclose(planned, rewards(model.planning_curve, method), rtol=1e-12)
    assert not np.allclose(planned, rewards(model.curve, method), rtol=1e-3)


def test_a_scenarios_information_policy_plans_with_its_detector_models_latest_draw():
    """Built from a scenario with the model learned online, intg's rewards are those of the model's
    current draw, before and after the model draws anew."""
    scenario = scenario_from_dict({"frames": 5, "detector": {"kind": "realistic", "model": "online"}})
    world = episode_world(scenario, 0)
    model = world.detector_model
    assert model is not None and model.learning
    built = make_policy("intg", scenario, world)
    actions = np.arange(len(world.grid.poses))
    tracks = tracks_far_away()
    drawn = set()
    for _ in range(3):
        drawn.add(model.planning_curve)
        with_draw = replace(built, recall=model.planning_curve)
        np.testing.assert_allclose(
            built.rewards(actions, tracks, np.random.default_rng(0)),
            with_draw.rewards(actions, tracks, np.random.default_rng(0)),
            rtol=1e-12,
        )
        model.observe(no_tracks())
    assert len(drawn) > 1
