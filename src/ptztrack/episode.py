"""The closed loop: scene -> camera -> tracker -> controller, step by step, recorded.

``run_episode`` knows only the roles: a camera backend with ``observe``, the
tracker's predict and update, and a policy with ``choose``. Random draws come
from independent streams spawned from the seed: the scene, the policy, and
one detector stream per frame. So different policies run with the same seed
meet the same people and, frame by frame, the same detector luck (common
random numbers), which makes their paired comparison far less noisy.
"""

from dataclasses import dataclass

import numpy as np

from ptztrack.camera.simulated import SimulatedPTZ
from ptztrack.config import Scenario
from ptztrack.control.baselines import FixPolicy, PatrolPolicy, RandomPolicy, patrol_route, widest_view_action
from ptztrack.control.exploration import exploration_map
from ptztrack.control.information_policy import InformationGainPolicy
from ptztrack.control.policy import DecisionContext, Policy
from ptztrack.detect.simulated import Detections
from ptztrack.scene.synthetic import GroundTruth, walk_people
from ptztrack.track.kalman import constant_velocity_model
from ptztrack.track.tracker import Tracks, no_tracks, pixel_noise_covariance, predict_tracks, update_tracks

POLICIES = ("fix", "patrol", "random", "intg", "smpl")


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
    if name in ("intg", "smpl"):
        exploration = None
        if scenario.control.beta > 0:
            exploration = exploration_map(
                camera, grid.poses, scenario.area_m, scenario.detector, scenario.control, 1.0 / scenario.frame_rate_hz
            )
        return InformationGainPolicy(
            camera,
            grid,
            scenario.detector,
            scenario.control,
            pixel_noise_covariance(scenario.detector),
            scenario.people.width_m,
            name,
            exploration,
        )
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
    frame_seeds = detector_seed.spawn(scenario.frames)
    policy_rng = np.random.default_rng(policy_seed)
    F, U = constant_velocity_model(1.0 / scenario.frame_rate_hz, scenario.tracker.acceleration_sigma_m_s2)
    V = pixel_noise_covariance(scenario.detector)

    action = widest_view_action(camera, grid, scenario.area_m)
    tracks = no_tracks()
    actions, track_history, detection_history = [], [], []
    for step in range(scenario.frames):
        tracks = predict_tracks(tracks, F, U)
        context = DecisionContext(step, action, grid.reachable(action), tracks, policy_rng)
        action = policy.choose(context)
        pose = grid.poses[action]
        detections = backend.observe(step, pose, np.random.default_rng(frame_seeds[step]))
        tracks = update_tracks(tracks, detections.feet_px, camera, pose, V, scenario.tracker)
        actions.append(action)
        track_history.append(tracks)
        detection_history.append(detections)
    actions = np.asarray(actions)
    return Episode(truth, actions, grid.poses[actions], track_history, detection_history)
