"""The closed loop against a live camera, pipelined so that no stage waits for another.

:func:`run_live` drives a camera that moves in its own time
(:class:`LiveCamera`, :class:`ptztrack.camera.live_camera.LiveONVIFCamera`)
with four stages in their own threads:

* the camera's pictures, decoded without pause, only the newest kept, each
  with its capture time (:mod:`ptztrack.camera.stream`);
* its pose, sampled by GetStatus and looked up at any moment with its
  uncertainty (:mod:`ptztrack.camera.pose_timeline`), and its commands,
  sent as soon as they are made;
* the detector, on the newest picture not yet seen, at the pose of its
  capture time, within a budget it measures as it runs: after each
  detection it rests as long as that detection took (busy at most half the
  time: the rest of the machine is the stream's decoder's, the pose
  samples' and the tracker's, whose timing places the pictures), and the
  pictures that come meanwhile are dropped, except for the first picture
  taken at rest where the camera was sent after a move, the one worth the
  most, which it takes at once. A picture the pose source cannot place
  (one that did not register) is passed on without detections;
* the tracker and the policy (the calling thread): every picture predicts
  the tracker to its capture time (the scenario's time: wall time times
  ``time_scale``), and a detected one updates it, with the pose's
  uncertainty in the measurement noise (a picture without a pose only
  predicts: it costs its step); once no newer picture waits, the
  policy decides on the tracks as the newest picture left them, and the
  camera is sent there. While the camera still moves to its last target,
  and until a picture taken at rest there is in the belief, it is given
  that target only (the paper's camera is sent no new decision while it
  moves).

So a busy machine drops pictures rather than falling behind: a decision
follows each picture the tracker takes and is never made on a picture older
than the newest. Before the first picture
the stages are run once on copies (:func:`warm_up`), so that compiling and
caching are done and the first decision is as fast as the others. Ctrl-C
(or ``steps`` pictures used) ends the run with what was recorded.

:func:`run_live_network` is the same loop for several cameras sharing one
ground belief (:class:`ptztrack.roles.NetworkTracker`): a detector stage per
camera, every picture updating the belief through its camera's updater, and
one joint decision (:class:`ptztrack.roles.NetworkPolicy`) for every camera
once no newer picture waits. :func:`run_live` is that loop with one camera.
"""

import copy
import queue
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial
from typing import Protocol

import cv2
import numpy as np

from ptztrack.camera.pose_timeline import PoseTimeline
from ptztrack.camera.stream import LatestFrame
from ptztrack.loop.alone import AlonePolicy, AloneTracker
from ptztrack.loop.steps import StepObserver, World, command, timed, track
from ptztrack.loop.streams import episode_streams
from ptztrack.roles import NetworkPolicy, NetworkTracker, Policy, Tracker
from ptztrack.types import DecisionContext, Detections, PeopleInView, Tracks

# How long the detector waits for a pose sample after a picture's capture time before it looks the pose
# up anyway (the camera's move-time model then carries it past the last sample).
POSE_WAIT_S = 0.1
IDLE_WAIT_S = 0.5
# The detector takes the next picture no sooner than this many times its last detection's time after it took
# the last one (but the first at rest after a move).
DETECTOR_DUTY_INVERSE = 2.0


RowSink = Callable[[int, dict], None]
"""``sink(camera, row)``: a picture's row of a live run, handed over as it is made (camera: its index)."""

PlanAhead = Callable[[Tracks, float], Tracks]
"""``plan_ahead(tracks, seconds)``: the tracks a live policy plans on, from the belief's and the scenario
seconds since the capture of the picture the decision is made on."""


class LiveCamera(Protocol):
    """A camera that moves in its own time (:class:`ptztrack.camera.live_camera.LiveONVIFCamera`)."""

    timeline: PoseTimeline

    @property
    def frames(self) -> "FrameSource": ...

    def send(self, pose: np.ndarray) -> bool:
        """Have the camera go to ``pose`` without waiting; whether it is a new target."""
        ...


class FrameSource(Protocol):
    latest: LatestFrame


@dataclass(frozen=True)
class LiveEpisode:
    """What a live run recorded, one row per picture used (T pictures).

    capture_time_s : (T,) epoch seconds each picture was taken; picked_s, detected_s, tracked_s : (T,) epoch
    seconds the detector took it, its detections were ready (when it was passed on, for a picture not
    detected), and the tracker was done with it; detected : (T,) whether the detector ran on it (not on
    a picture the pose source could not place); poses :
    (T, 3) the pose at its capture and pose_sd : (T, 3) its standard deviation;
    decided_s : (T,) epoch seconds of the decision that followed the picture, NaN where a newer picture
    was already waiting and none was made; decision_s : (T,) the policy's time (NaN likewise);
    commanded : (T, 3) the pose the camera was sent to last, after the picture; sent : (T,) whether a new
    target went out then; tracks, detections : per picture, the tracks reported after its update and the
    detections it was updated with; images : per picture, its JPEG (empty unless kept).
    frames_received : pictures that came from the camera; started_s, ended_s : the run's epoch seconds.
    """

    capture_time_s: np.ndarray
    picked_s: np.ndarray
    detected_s: np.ndarray
    tracked_s: np.ndarray
    detected: np.ndarray
    poses: np.ndarray
    pose_sd: np.ndarray
    decided_s: np.ndarray
    decision_s: np.ndarray
    commanded: np.ndarray
    sent: np.ndarray
    tracks: list
    detections: list
    images: list
    frames_received: int
    started_s: float
    ended_s: float

    def rates(self) -> dict[str, float]:
        """Pictures used, pictures detected and decisions per second over the run (intervals over the time
        they span), and each decision's age: seconds from its picture's capture to the decision."""
        decided = np.isfinite(self.decided_s)
        age_s = (self.decided_s - self.capture_time_s)[decided]
        return {
            "frames_used_per_s": _rate(self.capture_time_s),
            "frames_detected_per_s": _rate(self.capture_time_s[self.detected]),
            "decisions_per_s": _rate(self.decided_s[decided]),
            "frames_received_per_s": self.frames_received / max(self.ended_s - self.started_s, 1e-9),
            "frame_age_s_p95": float(np.percentile(age_s, 95)) if len(age_s) else float("nan"),
            "median_decision_s": float(np.median(self.decision_s[decided])) if decided.any() else float("nan"),
        }


def _rate(times_s) -> float:
    """Events per second: the intervals between the first and the last of ``times_s``, over their span."""
    if len(times_s) < 2:
        return float("nan")
    return (len(times_s) - 1) / max(float(times_s[-1] - times_s[0]), 1e-9)


class _CapturedView:
    """A picture as a camera backend for the detector: a real camera knows no people."""

    def __init__(self, image: np.ndarray):
        self._image = image

    def image(self, step: int, pose) -> np.ndarray:
        return self._image

    def people(self, step: int, pose) -> PeopleInView | None:
        return None


def warm_up(world: World, policy: Policy, tracker: Tracker, steps: int = 3) -> None:
    """Run the detector, the tracker and the policy on copies for ``steps`` steps, as :func:`run_live`
    runs them (from the start pose, one person standing low in the view, then a second beside: Numba
    compiles again for arrays of one row, which NumPy takes for contiguous), so that whatever compiles
    or caches on first use is done."""
    pose = world.grid.poses[world.start_action]
    blank = np.zeros((world.camera.image_height_px, world.camera.image_width_px, 3), np.uint8)
    world.detector.detect(_CapturedView(blank), 0, pose, np.random.default_rng(0))
    tracker, policy = copy.deepcopy(tracker), copy.deepcopy(policy)
    feet_px = np.array([[0.35, 0.8], [0.65, 0.8]]) * [world.camera.image_width_px, world.camera.image_height_px]
    grid, rng = world.grid, np.random.default_rng(0)
    for step in range(steps):
        seen = Detections(feet_px[: 1 + min(step, 1)], np.full(1 + min(step, 1), 100.0), np.full(1 + min(step, 1), -1))
        tracker.predict(None if step == 0 else 0.1)
        update = tracker.update(seen, pose, partial(_CapturedView(blank).image, step, pose), np.full(3, 0.1))
        tracker.reported()
        policy.choose(
            DecisionContext(step, world.start_action, grid.reachable(world.start_action), update.tracks, rng, pose)
        )


def run_live(
    world: World,
    policy: Policy,
    tracker: Tracker,
    camera: LiveCamera,
    steps: int,
    time_scale: float,
    seed: int,
    observer: StepObserver | None = None,
    keep_images: bool = False,
    plan_ahead: PlanAhead | None = None,
) -> LiveEpisode:
    """Use at most ``steps`` pictures; Ctrl-C ends the run early with what was recorded.

    time_scale : scenario seconds per wall-clock second (a virtual camera's recording plays that fast).
    plan_ahead : what the policy plans on, as :func:`run_live_network` takes it.
    observer : called after every decision as :func:`ptztrack.loop.simulated.run_loop` calls it, with the row's
    fields, its ``actions`` (flat index, -1 off the grid), ``poses`` and the picture as ``image``.
    keep_images : keep each picture used, as JPEG, in the episode (for its video).
    """
    # A camera alone is a network of one: the same stages, the same order.
    (episode,) = run_live_network(
        (world,), AlonePolicy(policy), AloneTracker(tracker), [camera], steps, time_scale, seed,
        observer, keep_images, plan_ahead,
    )  # fmt: skip
    return episode


def run_live_network(
    worlds: Sequence[World],
    policy: NetworkPolicy,
    tracker: NetworkTracker,
    cameras: Sequence[LiveCamera],
    steps: int,
    time_scale: float,
    seed: int,
    observer: StepObserver | None = None,
    keep_images: bool = False,
    plan_ahead: PlanAhead | None = None,
    sink: RowSink | None = None,
    stop: threading.Event | None = None,
) -> tuple[LiveEpisode, ...]:
    """Drive every camera of ``cameras``, each deciding in its world of ``worlds`` (in the same order; a
    network's :attr:`ptztrack.loop.simulated.NetworkWorld.cameras`), with one ground belief: use at most
    ``steps`` pictures in all; Ctrl-C ends the run early with what was recorded.

    Each camera has its own detector stage (its own thread and detector stream: the first camera's is the
    episode's, as a camera alone has it, every other's spawned from it). Every detected picture, whichever
    camera took it, predicts ``tracker`` to its capture time and updates it through that camera's updater;
    once no newer picture waits, ``policy`` decides for every camera together, each camera's context as
    :func:`run_live` makes it (a moving camera is given its target only), and each is sent its choice.

    Returns each camera's :class:`LiveEpisode`: the pictures it supplied, each with the belief's tracks
    after its update, and its camera's command after it. observer : called after every decision with the
    context and row of the camera whose picture led to it, the row's ``camera`` its index; plan_ahead :
    ``plan_ahead(tracks, seconds)``, the tracks the policy plans on, given the belief's and the scenario
    seconds since the capture of the picture decided on (None: the belief's as they are); the rest as
    :func:`run_live`.

    sink : ``sink(camera, row)`` is handed every picture's row (the :class:`LiveEpisode` fields of one
    picture, after the decision that followed it) instead of keeping it: the episodes returned are then
    empty, and a run of unbounded ``steps`` holds no history. stop : the run ends, as Ctrl-C ends it,
    once this is set (within IDLE_WAIT_S and a picture's tracking).
    """
    streams = episode_streams(seed)
    policy_rng = np.random.default_rng(streams.policy)
    # The first camera detects with the episode's detector stream (alone: the one-camera run's), every other
    # with a stream spawned from it.
    detector_seeds = [streams.detector, *streams.detector.spawn(len(cameras) - 1)]
    grids = [camera_world.grid for camera_world in worlds]
    actions = [camera_world.start_action for camera_world in worlds]
    commanded = [grid.poses[action] for grid, action in zip(grids, actions, strict=True)]
    for camera, pose in zip(cameras, commanded, strict=True):
        camera.send(pose)
    # Each detector is at most one picture ahead.
    detected: queue.Queue = queue.Queue(maxsize=len(cameras))
    stopping = threading.Event()
    detectors = [
        threading.Thread(
            target=_detect_pictures,
            args=(index, camera_world, camera, seeds, detected, stopping),
            name=f"live-detector-{index}",
            daemon=True,
        )
        for index, (camera_world, camera, seeds) in enumerate(zip(worlds, cameras, detector_seeds, strict=True))
    ]
    rows: list[list[dict]] = [[] for _ in cameras]
    # Whether each camera's newest picture used shows it at rest where it was last sent: only then has the
    # belief seen what its last move was for, and may it choose the next.
    settled = [False for _ in cameras]
    used = 0
    started_s = time.time()
    for detector in detectors:
        detector.start()
    last_time_s: float | None = None
    last_decided_s: float | None = None
    try:
        while used < steps and not (stop is not None and stop.is_set()):
            try:
                item = detected.get(timeout=IDLE_WAIT_S)
            except queue.Empty:
                continue
            if isinstance(item, BaseException):
                raise item
            index, frame, at, detections, picked_s, detected_s = item
            # Pictures of different cameras may come out of their capture order: the belief never goes back.
            dt_s = None if last_time_s is None else max(frame.time_s - last_time_s, 0.0) * time_scale
            last_time_s = frame.time_s if last_time_s is None else max(last_time_s, frame.time_s)
            planned = tracker.predict(dt_s)
            measured, pose, pose_sd = None, np.full(3, np.nan), np.full(3, np.nan)
            if at is not None:
                pose, pose_sd = at.pose, at.sd
            if at is not None and detections is not None:  # else the decision is made on the prediction
                image = partial(_CapturedView(frame.image).image, used, pose)
                update, measured = track(tracker.updater(index), detections, pose, image, pose_sd)
                planned = update.tracks
            settled[index] = cameras[index].timeline.settled(frame.time_s)
            row = {
                "capture_time_s": frame.time_s,
                "picked_s": picked_s,
                "detected_s": detected_s,
                "tracked_s": time.time(),
                "detected": detections is not None,
                "poses": pose,
                "pose_sd": pose_sd,
                "decided_s": np.nan,
                "decision_s": np.nan,
                "sent": False,
                "tracks": tracker.reported(),
                "detections": Detections.empty() if measured is None else measured,
                "images": _jpeg(frame.image) if keep_images else b"",
            }
            if detected.empty():  # decide on the newest picture only
                decided_s = time.time()
                since_s = None if last_decided_s is None else (decided_s - last_decided_s) * time_scale
                last_decided_s = decided_s
                if plan_ahead is not None:
                    planned = plan_ahead(planned, max(decided_s - frame.time_s, 0.0) * time_scale)
                contexts = [
                    _context(camera, grid, sent_to, used, planned, policy_rng, decided_s, since_s, at_rest)
                    for camera, grid, sent_to, at_rest in zip(cameras, grids, commanded, settled, strict=True)
                ]
                choices, row["decision_s"] = timed(policy.choose, contexts)
                sent = []
                for k, (camera, grid, choice) in enumerate(zip(cameras, grids, choices, strict=True)):
                    actions[k], commanded[k] = command(grid, choice)
                    sent.append(camera.send(commanded[k]))
                row["sent"] = sent[index]  # the row is its camera's
                row["decided_s"] = time.time()
            row["commanded"] = commanded[index]
            if observer is not None and np.isfinite(row["decided_s"]):
                observer(
                    used, contexts[index], {**row, "actions": actions[index], "image": frame.image, "camera": index}
                )
            if sink is None:
                rows[index].append(row)
            else:
                sink(index, row)
            used += 1
    except KeyboardInterrupt:
        pass  # the rows recorded whole so far are the run
    finally:
        stopping.set()
        for detector in detectors:
            detector.join()
    ended_s = time.time()
    return tuple(
        _episode(camera_rows, camera.frames.latest.received, started_s, ended_s)
        for camera_rows, camera in zip(rows, cameras, strict=True)
    )


def _context(
    camera: LiveCamera,
    grid,
    commanded,
    step: int,
    tracks: Tracks,
    rng,
    decided_s: float,
    since_s: float | None,
    settled: bool,
) -> DecisionContext:
    """The decision context of ``camera`` at epoch ``decided_s``: where it is (the pose it was sent to,
    ``commanded`` (3,), where no pose is known yet), the nearest grid action to that, and what it may reach:
    while it moves, and until a picture taken at rest where it went is in the belief (``settled``), only
    the action nearest to its target (the paper's camera is sent no new decision while it moves)."""
    now = camera.timeline.at(decided_s)
    here = commanded if now is None else now.pose
    if camera.timeline.moving() or not settled:
        nearest = grid.nearest(commanded)
        reachable = np.array([nearest])
    else:
        nearest = grid.nearest(here)
        reachable = grid.reachable(nearest)
    return DecisionContext(step, nearest, reachable, tracks, rng, here, since_s)


def _detect_pictures(index: int, world: World, camera: LiveCamera, seeds, detected: queue.Queue, stopping) -> None:
    """Camera ``index``'s detector stage: each newest picture not yet seen, at the pose of its capture, into
    ``detected`` as (index, frame, pose, detections, when it was picked, when detected), detections None
    for a picture that cannot be placed; an exception goes there too, for the tracker's stage to raise."""
    try:
        number = 0
        rest_until_s, last_settled = -np.inf, True
        while not stopping.is_set():
            frame = camera.frames.latest.newer(number, IDLE_WAIT_S)
            if frame is None:
                continue
            number, picked_s = frame.number, time.time()
            # The first picture at rest where the camera went is worth the most: it is taken at once.
            if picked_s < rest_until_s and (last_settled or not camera.timeline.settled(frame.time_s)):
                continue  # the machine's share for detection is spent: the picture is dropped
            camera.timeline.wait_past(frame.time_s, POSE_WAIT_S)
            at = camera.timeline.at(frame.time_s)
            if at is None and not camera.timeline.begun(frame.time_s):  # taken before any pose was known
                continue
            detections = None
            if at is not None:  # else a picture that cannot be placed (it did not register): no detections
                rng = np.random.default_rng(seeds.spawn(1)[0])
                detections = world.detector.detect(_CapturedView(frame.image), number, at.pose, rng)
            detected_s = time.time()
            if not _hand_over(detected, stopping, (index, frame, at, detections, picked_s, detected_s)):
                return
            if detections is not None:
                rest_until_s = picked_s + DETECTOR_DUTY_INVERSE * (detected_s - picked_s)
                last_settled = camera.timeline.settled(frame.time_s)
    except BaseException as error:  # noqa: BLE001 - handed to the tracker's stage, which raises it
        detected.put(error)


def _hand_over(detected: queue.Queue, stopping, item) -> bool:
    """Put ``item`` into ``detected`` once there is room; False if the run stopped first."""
    while not stopping.is_set():
        try:
            detected.put(item, timeout=IDLE_WAIT_S)
            return True
        except queue.Full:
            continue
    return False


def _jpeg(image: np.ndarray) -> bytes:
    ok, encoded = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, 85])
    return encoded.tobytes() if ok else b""


def _episode(rows: list[dict], received: int, started_s: float, ended_s: float) -> LiveEpisode:
    def column(name: str, width: int = 0) -> np.ndarray:
        values = np.array([row[name] for row in rows], dtype=float)
        return values.reshape(-1, width) if width else values

    return LiveEpisode(
        capture_time_s=column("capture_time_s"),
        picked_s=column("picked_s"),
        detected_s=column("detected_s"),
        tracked_s=column("tracked_s"),
        detected=np.array([row["detected"] for row in rows], dtype=bool),
        poses=column("poses", 3),
        pose_sd=column("pose_sd", 3),
        decided_s=column("decided_s"),
        decision_s=column("decision_s"),
        commanded=column("commanded", 3),
        sent=np.array([row["sent"] for row in rows], dtype=bool),
        tracks=[row["tracks"] for row in rows],
        detections=[row["detections"] for row in rows],
        images=[row["images"] for row in rows],
        frames_received=received,
        started_s=started_s,
        ended_s=ended_s,
    )
