"""The steps every closed loop shares: a camera's world and episode, the command a policy's choice makes,
where the camera lands, what it sees, and the tracker's update with it.

They know only the roles of :mod:`ptztrack.roles`: a camera backend, a detector, a tracker and a policy,
and where the camera lands and which pose the tracker believes. The simulated loop
(:mod:`ptztrack.loop.simulated`) and the live one (:mod:`ptztrack.loop.live`) are made of them.
"""

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np

from ptztrack.camera.actions import ActionGrid
from ptztrack.camera.parameters import LandingErrorParameters
from ptztrack.camera.pose_feedback import landed_pose
from ptztrack.detect.detector_model import OnlineDetectorModel
from ptztrack.geometry.ptz import PTZCamera
from ptztrack.roles import CameraBackend, Detector, ImageSource, PoseSource, Updater
from ptztrack.types import DecisionContext, Detections, GroundTruth, Tracks, TrackUpdate


@dataclass(frozen=True)
class World:
    """Everything a run's loop needs besides the policy and the tracker.

    camera, grid : the PTZ camera model and its action grid.
    truth : the people, for the metrics.
    backend : what the camera shows; detector : what finds people in it.
    area_polygon_m : (K, 2) the walkable area, a polygon on the ground.
    start_action : the flat action the camera is at before the first step.
    pose_source : the pose the tracker maps detections with (:mod:`ptztrack.camera.pose_feedback`).
    landing_error : where the camera lands when sent to a pose.
    tracker_seed : the episode's stream for a tracker that draws (its factory seeds it from this).
    detector_model : what the policies and the tracker know of the detector, learned as the run goes
        (:mod:`ptztrack.detect.detector_model`); None for a world built without one.
    """

    camera: PTZCamera
    grid: ActionGrid
    truth: GroundTruth
    backend: CameraBackend
    detector: Detector
    area_polygon_m: np.ndarray
    start_action: int
    pose_source: PoseSource
    landing_error: LandingErrorParameters
    tracker_seed: np.random.SeedSequence | None = None
    detector_model: OnlineDetectorModel | None = None


@dataclass(frozen=True)
class Episode:
    """What happened in one run.

    truth : the people.
    camera : the PTZ camera that looked; area_polygon_m : (K, 2) the walkable area, a polygon on the ground.
    actions : (T,) flat action index taken at each step (-1 where the policy commanded a pose off the grid).
    commanded : (T, 3) the poses the camera was sent to.
    poses : (T, 3) the poses the camera took, as (pan_deg, tilt_deg, zoom): the actions' poses
        unless the camera lands off them.
    tracker_poses : (T, 3) the poses the tracker mapped detections with.
    pose_known : (T,) whether the pose source gave a pose; where not, the tracker used the commanded one.
    decision_s : (T,) wall time the policy took to choose each action.
    tracks : per step, the tracks the tracker reported after that step's update.
    detections : per step, the measurements the tracker was updated with (the detector's).
    """

    truth: GroundTruth
    camera: PTZCamera
    area_polygon_m: np.ndarray
    actions: np.ndarray
    commanded: np.ndarray
    poses: np.ndarray
    tracker_poses: np.ndarray
    pose_known: np.ndarray
    decision_s: np.ndarray
    tracks: Sequence[Tracks]
    detections: Sequence[Detections]


# What the loop records at every step, as the fields of Episode.
# A camera's per-step numbers: name -> (shape per step, dtype); with its tracks and detections, the
# episode's per-step records.
STEP_NUMBERS = {
    "actions": ((), np.int64),
    "commanded": ((3,), np.float64),
    "poses": ((3,), np.float64),
    "tracker_poses": ((3,), np.float64),
    "pose_known": ((), np.bool_),
    "decision_s": ((), np.float64),
}
PER_STEP = (*STEP_NUMBERS, "tracks", "detections")


StepObserver = Callable[[int, DecisionContext, dict], None]
"""``observer(step, context, record)``, called after each step with the decision's context and the
step's record (the PER_STEP names); a live view draws from it, and may block to pause the run."""


def command(grid: ActionGrid, choice: int | np.ndarray) -> tuple[int, np.ndarray]:
    """A policy's choice as (flat action index, or -1 for a pose off the grid; the (3,) commanded pose)."""
    if np.ndim(choice) == 0:
        action = int(choice)
        return action, grid.poses[action]
    pose = np.asarray(choice, dtype=float)
    if pose.shape != (3,) or not np.all(np.isfinite(pose)):
        raise ValueError(f"a policy chose the pose {pose!r}; expected (pan_deg, tilt_deg, zoom), all finite")
    return -1, pose


def timed(choose: Callable[[Any], Any], context) -> tuple[Any, float]:
    """``choose(context)`` and the wall seconds it took."""
    started = time.perf_counter()
    choice = choose(context)
    return choice, time.perf_counter() - started


def track(
    tracker: Updater, detections: Detections | None, pose, image: ImageSource, pose_sd=None
) -> tuple[TrackUpdate, Detections | None]:
    """Update ``tracker`` with a picture's ``detections`` at ``pose`` (3,) (``pose_sd`` (3,) its
    uncertainty, None where exact); returns the update and the measurements it used (the detections,
    unless the tracker measured on its own, as templates do). The step both loops share after the
    detector."""
    # Only a live camera's poses are uncertain: a tracker written for simulated runs need not take pose_sd.
    uncertain = {} if pose_sd is None else {"pose_sd": pose_sd}
    update = tracker.update(detections, pose, image, **uncertain)
    return update, update.measurements if update.measurements is not None else detections


def land(world: World, step: int, commanded, previous, pose, rng: np.random.Generator) -> np.ndarray:
    """Where the camera of ``world`` is at ``step``: it lands anew (drawing from ``rng``) when the command
    (3,) changed from ``previous`` (and at the first step), else it stays at ``pose``."""
    if step == 0 or not np.array_equal(commanded, previous):
        return landed_pose(commanded, world.landing_error, rng)
    return pose


@dataclass(frozen=True)
class Look:
    """A camera's side of a step, which needs no belief: where it is and what it found.

    pose : (3,) the pose the camera took; tracker_pose : (3,) the pose the tracker is to map its detections
    with; pose_known : whether the pose source gave that pose (else it is the commanded one);
    detections : what the detector found, None where the tracker wanted none.
    """

    pose: np.ndarray
    tracker_pose: np.ndarray
    pose_known: bool
    detections: Detections | None


def look(world: World, step: int, commanded, pose, rng: np.random.Generator, wanted: bool) -> Look:
    """The camera of ``world`` at ``step``, sent to ``commanded`` (3,) and at ``pose`` (3,): the pose the
    tracker is to believe, and, where ``wanted``, the detections (drawing from ``rng``, the step's own
    stream). Runs where the camera is: in this process, or in a camera's actor."""
    believed = world.pose_source(step, commanded, pose)
    tracker_pose = commanded if believed is None else believed
    detections = None
    if wanted:
        detections = world.detector.detect(world.backend, step, pose, rng, believed_pose=tracker_pose)
    return Look(pose, tracker_pose, believed is not None, detections)


def take_in(world: World, tracker: Updater, step: int, seen: Look) -> dict:
    """``tracker`` updated with the camera of ``world``'s :class:`Look` at ``step``; returns the step's
    record of it: ``tracker_poses``, ``pose_known`` and ``detections`` (the measurements it used)."""
    _, measured = track(tracker, seen.detections, seen.tracker_pose, partial(world.backend.image, step, seen.pose))
    return {
        "tracker_poses": seen.tracker_pose,
        "pose_known": seen.pose_known,
        "detections": Detections.empty() if measured is None else measured,
    }


def episode_of(world: World, per_step: dict[str, Sequence]) -> Episode:
    """The :class:`Episode` of the camera of ``world`` from its steps' records ({PER_STEP name: the steps'
    values in order})."""
    arrays = {name: np.asarray(per_step[name]) for name in PER_STEP if name not in ("tracks", "detections")}
    return Episode(
        world.truth,
        world.camera,
        world.area_polygon_m,
        tracks=per_step["tracks"],
        detections=per_step["detections"],
        **arrays,
    )
