"""The closed loop of a camera network: several cameras, fixed or PTZ, one ground belief, one decision.

Every step: one prediction of the shared belief
(:class:`ptztrack.roles.NetworkTracker`); one decision for every camera
together (:class:`ptztrack.roles.NetworkPolicy`: a fixed camera is one whose
choice never changes); then, camera after camera in the network's order,
each lands, detects and updates the belief (the same steps as the
one-camera loop, :func:`ptztrack.loop.land` and :func:`ptztrack.loop.observe`).

Streams. The first camera draws its detections and landings from the
streams :func:`ptztrack.loop.run_loop` draws them from, so a network of one
camera is the one-camera loop step for step; every further camera has
streams of its own, spawned after those, and keeps them whatever the other
cameras do. Configurations that share a camera at the same place in their
list meet, there, the same detector luck (common random numbers).
"""

from dataclasses import dataclass

import numpy as np

from ptztrack.loop import PER_STEP, Episode, World, command, episode_of, episode_seeds, land, observe, timed
from ptztrack.roles import NetworkPolicy, NetworkTracker
from ptztrack.types import DecisionContext, GroundTruth, Tracks


@dataclass(frozen=True)
class NetworkWorld:
    """Every camera's :class:`~ptztrack.loop.World`, in the network's order; they share the truth and the
    walkable area (the first camera's are the network's)."""

    cameras: tuple[World, ...]

    @property
    def truth(self) -> GroundTruth:
        return self.cameras[0].truth

    @property
    def area_polygon_m(self) -> np.ndarray:
        return self.cameras[0].area_polygon_m


@dataclass(frozen=True)
class NetworkEpisode:
    """What happened in one run of a network.

    truth : the people; area_polygon_m : (K, 2) the walkable area.
    tracks : per step, the tracks the network reported after every camera's update.
    decision_s : (T,) wall seconds the network policy took to choose every camera's action.
    cameras : each camera's :class:`~ptztrack.loop.Episode` (its ``tracks`` are the network's, its
        ``decision_s`` the network's decision's).
    """

    truth: GroundTruth
    area_polygon_m: np.ndarray
    tracks: list[Tracks]
    decision_s: np.ndarray
    cameras: tuple[Episode, ...]


def camera_streams(
    detector_seed: np.random.SeedSequence, landing_seed: np.random.SeedSequence, cameras: int, steps: int
) -> tuple[list[list[np.random.SeedSequence]], list[np.random.Generator]]:
    """Each camera's per-step detector streams (cameras lists of ``steps``) and its landing generator:
    the first camera's are :func:`~ptztrack.loop.run_loop`'s, the others' spawned after them."""
    frame_seeds = [detector_seed.spawn(steps)]
    frame_seeds += [camera.spawn(steps) for camera in detector_seed.spawn(cameras - 1)]
    landing = [np.random.default_rng(landing_seed)]
    landing += [np.random.default_rng(camera) for camera in landing_seed.spawn(cameras - 1)]
    return frame_seeds, landing


def run_network_loop(world: NetworkWorld, policy: NetworkPolicy, tracker: NetworkTracker, seed: int) -> NetworkEpisode:
    """Run the network's closed loop for every frame of ``world.truth``, with the streams of ``seed``."""
    _, detector_seed, policy_seed, landing_seed, _, _ = episode_seeds(seed)
    steps = world.truth.positions_m.shape[0]
    frame_seeds, landing_rngs = camera_streams(detector_seed, landing_seed, len(world.cameras), steps)
    policy_rng = np.random.default_rng(policy_seed)

    nearest = [camera.start_action for camera in world.cameras]
    commanded = [camera.grid.poses[camera.start_action] for camera in world.cameras]
    pose = list(commanded)
    per_camera: list[dict[str, list]] = [{name: [] for name in PER_STEP} for _ in world.cameras]
    reported: list[Tracks] = []
    decision_times_s = []
    for step in range(steps):
        predicted = tracker.predict()
        contexts = [
            DecisionContext(step, nearest[k], camera.grid.reachable(nearest[k]), predicted, policy_rng, commanded[k])
            for k, camera in enumerate(world.cameras)
        ]
        choices, decision_s = timed(policy.choose, contexts)
        records = []
        for k, (camera, choice) in enumerate(zip(world.cameras, choices, strict=True)):
            previous = commanded[k]
            action, commanded[k] = command(camera.grid, choice)
            nearest[k] = action if action >= 0 else camera.grid.nearest(commanded[k])
            pose[k] = land(camera, step, commanded[k], previous, pose[k], landing_rngs[k])
            rng = np.random.default_rng(frame_seeds[k][step])
            looked = observe(camera, tracker.updater(k), step, commanded[k], pose[k], rng)
            records.append(
                {"actions": action, "commanded": commanded[k], "poses": pose[k], "decision_s": decision_s, **looked}
            )
        tracks = tracker.reported()
        reported.append(tracks)
        decision_times_s.append(decision_s)
        for record, history in zip(records, per_camera, strict=True):
            for name, value in {**record, "tracks": tracks}.items():
                history[name].append(value)
    return NetworkEpisode(
        world.truth,
        world.area_polygon_m,
        reported,
        np.asarray(decision_times_s),
        tuple(episode_of(camera, history) for camera, history in zip(world.cameras, per_camera, strict=True)),
    )
