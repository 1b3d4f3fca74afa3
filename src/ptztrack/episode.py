"""The closed loop: scene -> camera -> tracker -> controller, step by step, recorded.

``run_episode`` knows only the roles: a camera backend with ``observe``, the
tracker's predict and update, and a policy with ``choose``. Random draws come
from three independent streams spawned from the seed (scene, detector,
policy), so different policies run with the same seed meet the same people.
"""

from dataclasses import dataclass

import numpy as np

from ptztrack.camera.simulated import SimulatedPTZ
from ptztrack.config import Scenario
from ptztrack.control.baselines import FixPolicy, PatrolPolicy, RandomPolicy, patrol_route, widest_view_action
from ptztrack.control.policy import DecisionContext, Policy
from ptztrack.detect.simulated import Detections
from ptztrack.scene.synthetic import GroundTruth, walk_people
from ptztrack.track.kalman import constant_velocity_model
from ptztrack.track.tracker import Tracks, no_tracks, predict_tracks, update_tracks

POLICIES = ("fix", "patrol", "random")
# Feet are found on a pixel grid: the tracker trusts them to half a pixel at
# best, which also keeps the innovation covariance invertible for a
# noiseless simulated detector.
MIN_PIXEL_NOISE_PX = 0.5


@dataclass(frozen=True)
class Episode:
    """What happened in one run.

    truth : the people.
    actions : (T,) flat action index taken at each step.
    poses : (T, 3) those actions as (pan_deg, tilt_deg, zoom).
    tracks : per step, the tracks after that step's update.
    detections : per step, what the detector reported.
    """

    truth: GroundTruth
    actions: np.ndarray
    poses: np.ndarray
    tracks: list[Tracks]
    detections: list[Detections]


def make_policy(name: str, scenario: Scenario) -> Policy:
    """A fresh policy of the given name for one episode."""
    camera, grid = scenario.ptz_camera(), scenario.action_grid()
    if name == "fix":
        return FixPolicy(widest_view_action(camera, grid, scenario.area_m))
    if name == "patrol":
        return PatrolPolicy(grid, patrol_route(camera, grid, scenario.area_m))
    if name == "random":
        return RandomPolicy()
    raise ValueError(f"unknown policy {name!r}; expected one of {', '.join(POLICIES)}")


def run_episode(scenario: Scenario, policy_name: str, seed: int) -> Episode:
    """Run one closed-loop episode of ``scenario.frames`` steps on the synthetic scene."""
    scene_seed, detector_seed, policy_seed = np.random.SeedSequence(seed).spawn(3)
    camera, grid = scenario.ptz_camera(), scenario.action_grid()
    truth = walk_people(
        scenario.people, scenario.area_m, scenario.frames, scenario.frame_rate_hz, np.random.default_rng(scene_seed)
    )
    backend = SimulatedPTZ(camera, truth, scenario.detector)
    policy = make_policy(policy_name, scenario)
    detector_rng, policy_rng = np.random.default_rng(detector_seed), np.random.default_rng(policy_seed)
    F, U = constant_velocity_model(1.0 / scenario.frame_rate_hz, scenario.tracker.acceleration_sigma_m_s2)
    V = max(scenario.detector.pixel_noise_px, MIN_PIXEL_NOISE_PX) ** 2 * np.eye(2)

    action = widest_view_action(camera, grid, scenario.area_m)
    tracks = no_tracks()
    actions, track_history, detection_history = [], [], []
    for step in range(scenario.frames):
        tracks = predict_tracks(tracks, F, U)
        context = DecisionContext(step, action, grid.reachable(action), tracks, policy_rng)
        action = policy.choose(context)
        pose = grid.poses[action]
        detections = backend.observe(step, pose, detector_rng)
        tracks = update_tracks(tracks, detections.feet_px, camera, pose, V, scenario.tracker)
        actions.append(action)
        track_history.append(tracks)
        detection_history.append(detections)
    actions = np.asarray(actions)
    return Episode(truth, actions, grid.poses[actions], track_history, detection_history)
