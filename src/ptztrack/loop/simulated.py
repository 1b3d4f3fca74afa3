"""The simulated closed loop: scene -> cameras -> detectors -> one ground belief -> one decision, step by
step, recorded, for a network of cameras, fixed or PTZ, or one camera alone (:func:`run_loop`: the
network of it alone).

Every step: one prediction of the shared belief
(:class:`ptztrack.roles.NetworkTracker`); one decision for every camera
together (:class:`ptztrack.roles.NetworkPolicy`: a fixed camera is one whose
choice never changes); then, camera after camera in the network's order,
each lands, detects and updates the belief (the same steps as the
one-camera loop, :func:`ptztrack.loop.steps.land`, :func:`ptztrack.loop.steps.look` and
:func:`ptztrack.loop.steps.take_in`).

Where the cameras work. A camera's landing and detection need no belief:
each camera's :class:`CameraWorker` does them with its own streams, in this
process (:class:`InProcessCameras`) or in an actor of its own on a Ray
cluster (:class:`ptztrack.loop.camera_actors.RayCameras`), and returns
its :class:`~ptztrack.loop.steps.Look`; the belief, its updates and the decision
stay in this process. The cameras' streams travel with their workers, so
where they run does not change the episode.

Streams. The first camera draws its detections and landings from the
streams :func:`ptztrack.loop.simulated.run_loop` draws them from, so a network of one
camera is the one-camera loop step for step; every further camera has
streams of its own, spawned after those, and keeps them whatever the other
cameras do. Configurations that share a camera at the same place in their
list meet, there, the same detector luck (common random numbers).
"""

import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from ptztrack.loop.alone import AlonePolicy, AloneTracker
from ptztrack.loop.history import StepHistory
from ptztrack.loop.steps import (
    STEP_NUMBERS,
    Episode,
    Look,
    StepObserver,
    World,
    command,
    episode_of,
    land,
    look,
    take_in,
    timed,
)  # fmt: skip
from ptztrack.loop.streams import episode_streams
from ptztrack.roles import NetworkPolicy, NetworkTracker, Policy, Tracker
from ptztrack.types import DecisionContext, GroundTruth, Tracks


@dataclass(frozen=True)
class NetworkWorld:
    """Every camera's :class:`~ptztrack.loop.steps.World`, in the network's order; they share the truth and the
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
    cameras : each camera's :class:`~ptztrack.loop.steps.Episode` (its ``tracks`` are the network's, its
        ``decision_s`` the network's decision's).
    update_s : (T,) wall seconds of every camera's update of the belief, summed over the cameras (not
        the waits for their looks).
    step_s : (T,) wall seconds of each whole step: prediction, decision, looks and updates.
    """

    truth: GroundTruth
    area_polygon_m: np.ndarray
    tracks: Sequence[Tracks]
    decision_s: np.ndarray
    cameras: tuple[Episode, ...]
    update_s: np.ndarray
    step_s: np.ndarray


def camera_streams(
    detector_seed: np.random.SeedSequence, landing_seed: np.random.SeedSequence, cameras: int, steps: int
) -> tuple[list[list[np.random.SeedSequence]], list[np.random.Generator]]:
    """Each camera's per-step detector streams (cameras lists of ``steps``) and its landing generator:
    the first camera's are the episode's own (a camera alone's), the others' spawned after them."""
    frame_seeds = [detector_seed.spawn(steps)]
    frame_seeds += [camera.spawn(steps) for camera in detector_seed.spawn(cameras - 1)]
    landing = [np.random.default_rng(landing_seed)]
    landing += [np.random.default_rng(camera) for camera in landing_seed.spawn(cameras - 1)]
    return frame_seeds, landing


@dataclass
class CameraWorker:
    """One camera's own work every step, the part that needs no belief: it lands where it is sent,
    drawing from its landing stream, and looks (:func:`~ptztrack.loop.steps.look`) with the step's detector
    stream. It reads ``world``'s backend, detector, pose source and landing error only.

    frame_seeds : its per-step detector streams; landing_rng : its landing errors' generator.
    commanded, pose : (3,) where it was last sent and where it is (before the first step: its start
    action's pose, both).
    """

    world: World
    frame_seeds: list[np.random.SeedSequence]
    landing_rng: np.random.Generator
    commanded: np.ndarray = field(init=False)
    pose: np.ndarray = field(init=False)

    def __post_init__(self):
        self.commanded = self.pose = self.world.grid.poses[self.world.start_action]

    def look(self, step: int, commanded, wanted: bool) -> Look:
        """Sent to ``commanded`` (3,) at ``step``: it lands (anew only when the command changed) and
        looks, detecting where ``wanted``."""
        self.pose = land(self.world, step, commanded, self.commanded, self.pose, self.landing_rng)
        self.commanded = commanded
        return look(self.world, step, commanded, self.pose, np.random.default_rng(self.frame_seeds[step]), wanted)


class CameraFleet(Protocol):
    """Where the cameras' workers run (in this process, or as actors on a cluster)."""

    def looks(self, step: int, commanded: Sequence[np.ndarray], wanted: Sequence[bool]) -> Iterator[Look]:
        """Every camera's look at ``step`` (camera ``k`` sent to ``commanded[k]``, detecting where
        ``wanted[k]``), in the network's order, each as soon as it is ready."""
        ...

    def close(self) -> None:
        """Release what the fleet holds (actors); it is not used after."""
        ...


@dataclass
class InProcessCameras:
    """Every camera's worker in this process, each looking only when its look is asked for, so the
    belief's update by one camera comes before the next camera's look."""

    workers: list[CameraWorker]

    def looks(self, step: int, commanded: Sequence[np.ndarray], wanted: Sequence[bool]) -> Iterator[Look]:
        for worker, pose, wants in zip(self.workers, commanded, wanted, strict=True):
            yield worker.look(step, pose, wants)

    def close(self) -> None:
        """Nothing to release."""


def camera_workers(world: NetworkWorld, seed: int) -> list[CameraWorker]:
    """Every camera's worker for the episode of ``seed``, with its streams (:func:`camera_streams`)."""
    streams = episode_streams(seed)
    steps = world.truth.positions_m.shape[0]
    frame_seeds, landing_rngs = camera_streams(streams.detector, streams.landing, len(world.cameras), steps)
    return [
        CameraWorker(camera, seeds, rng)
        for camera, seeds, rng in zip(world.cameras, frame_seeds, landing_rngs, strict=True)
    ]


def run_network_loop(
    world: NetworkWorld,
    policy: NetworkPolicy,
    tracker: NetworkTracker,
    seed: int,
    fleet: Callable[[list[CameraWorker]], CameraFleet] = InProcessCameras,
    observer: StepObserver | None = None,
) -> NetworkEpisode:
    """Run the network's closed loop for every frame of ``world.truth``, with the streams of ``seed``.

    fleet : runs the cameras' workers (:func:`camera_workers`): in this process by default; the
    episode is the same wherever they run.
    observer : called after every step for every camera, with its decision's context and its record
    (:data:`~ptztrack.loop.steps.StepObserver`; the record's ``camera`` its index); it draws no random
    numbers, so the episode is the same with or without it.
    """
    steps = world.truth.positions_m.shape[0]
    policy_rng = np.random.default_rng(episode_streams(seed).policy)

    nearest = [camera.start_action for camera in world.cameras]
    commanded = [camera.grid.poses[camera.start_action] for camera in world.cameras]
    # A long run's memory grows by its numbers only: the per-step numbers go into arrays made for the run,
    # tracks and detections into step histories, and every camera's episode shares the network's tracks.
    reported: StepHistory[Tracks] = StepHistory()
    per_camera: list[dict[str, Any]] = [
        {name: np.empty((steps, *shape), dtype) for name, (shape, dtype) in STEP_NUMBERS.items()}
        | {"tracks": reported, "detections": StepHistory()}
        for _ in world.cameras
    ]
    decision_times_s, update_times_s, step_times_s = [], [], []
    cameras = fleet(camera_workers(world, seed))
    try:
        for step in range(steps):
            step_started = time.perf_counter()
            predicted = tracker.predict()
            contexts = [
                DecisionContext(step, here, camera.grid.reachable(here), predicted, policy_rng, sent)
                for camera, here, sent in zip(world.cameras, nearest, commanded, strict=True)
            ]
            choices, decision_s = timed(policy.choose, contexts)
            actions = []
            for k, (camera, choice) in enumerate(zip(world.cameras, choices, strict=True)):
                action, commanded[k] = command(camera.grid, choice)
                nearest[k] = action if action >= 0 else camera.grid.nearest(commanded[k])
                actions.append(action)
            wanted = [tracker.updater(k).wants_detections(step) for k in range(len(world.cameras))]
            records, update_s = [], 0.0
            for k, seen in enumerate(cameras.looks(step, commanded, wanted)):
                update_started = time.perf_counter()
                looked = take_in(world.cameras[k], tracker.updater(k), step, seen)
                update_s += time.perf_counter() - update_started
                records.append(
                    {"actions": actions[k], "commanded": commanded[k], "poses": seen.pose, "decision_s": decision_s}
                    | looked
                )
            tracks = tracker.reported()
            reported.append(tracks)
            decision_times_s.append(decision_s)
            update_times_s.append(update_s)
            step_times_s.append(time.perf_counter() - step_started)
            for index, (context, record, history) in enumerate(zip(contexts, records, per_camera, strict=True)):
                for name in STEP_NUMBERS:
                    history[name][step] = record[name]
                history["detections"].append(record["detections"])
                record["tracks"] = tracks
                if observer is not None:
                    observer(step, context, {**record, "camera": index})
    finally:
        cameras.close()
    return NetworkEpisode(
        world.truth,
        world.area_polygon_m,
        reported,
        np.asarray(decision_times_s),
        tuple(episode_of(camera, history) for camera, history in zip(world.cameras, per_camera, strict=True)),
        np.asarray(update_times_s),
        np.asarray(step_times_s),
    )


def run_loop(
    world: World, policy: Policy, tracker: Tracker, seed: int, observer: StepObserver | None = None
) -> Episode:
    """Run one camera's closed loop for every frame of ``world.truth``, with the streams of ``seed``: the
    network loop of it alone (:func:`run_network_loop`), whose first camera draws from the episode's own
    streams; its :class:`~ptztrack.loop.steps.Episode`.

    observer : called after every step (:data:`~ptztrack.loop.steps.StepObserver`); it draws no random
    numbers, so the episode is the same with or without it.
    """
    network = run_network_loop(
        NetworkWorld((world,)), AlonePolicy(policy), AloneTracker(tracker), seed, observer=observer
    )
    return network.cameras[0]
