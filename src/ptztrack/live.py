"""The closed loop against a live camera, in real time: capture, detect, track and decide at the camera's pace.

:func:`run_live` is :func:`ptztrack.loop.run_loop` for a camera that is
really out there. The loop's steps keep the scenario's rate (``period_s``
apart, on the wall clock); each step the policy decides, and the decision
is sent only if the camera is not still moving from the last one; the
camera's image and its pose at capture (its own GetStatus, read just before
the image is taken while the camera stands still) go to the detector and
the tracker. While the camera moves, or cannot be reached, the tracker runs
on its predictions alone. The camera (:class:`LiveCamera`) reconnects by
itself; Ctrl-C (or ``stop``) ends the run after the step in progress and
returns what was recorded, so that its outputs are written whole.
"""

import time
from dataclasses import dataclass
from functools import partial
from typing import Protocol

import numpy as np

from ptztrack.camera.live_camera import Capture
from ptztrack.loop import StepObserver, World, command, episode_seeds
from ptztrack.roles import Policy, Tracker
from ptztrack.types import DecisionContext, Detections, PeopleInView, Tracks


class LiveCamera(Protocol):
    """A camera that moves in its own time (:class:`ptztrack.camera.live_camera.ReconnectingCamera`)."""

    def send(self, pose: np.ndarray) -> bool:
        """Send the camera to ``pose`` unless it is still moving; whether the command went out."""
        ...

    def capture(self, until_s: float) -> Capture | None:
        """The image and its pose once the camera stands still, waiting for it until ``until_s`` (on
        ``time.monotonic``'s clock); None if it still moves then, or cannot be reached."""
        ...


@dataclass(frozen=True)
class LiveEpisode:
    """What a live run recorded, per step (T steps).

    commanded : (T, 3) the decided poses; sent : (T,) whether each went out to the camera;
    poses : (T, 3) the captured poses, NaN where nothing was captured; capture_time_s : (T,) epoch
    seconds of the captures (NaN likewise); step_time_s : (T,) epoch seconds of the steps' starts;
    decision_s : (T,) the policy's time; tracks : per step, the tracks reported; detections : per
    step, the detections the tracker was updated with.
    """

    commanded: np.ndarray
    sent: np.ndarray
    poses: np.ndarray
    capture_time_s: np.ndarray
    step_time_s: np.ndarray
    decision_s: np.ndarray
    tracks: list[Tracks]
    detections: list[Detections]

    @property
    def seen_time_s(self) -> np.ndarray:
        """(T,) epoch seconds of what each step saw: its capture, or its start where nothing was captured."""
        return np.where(np.isfinite(self.capture_time_s), self.capture_time_s, self.step_time_s)


class _CapturedView:
    """The captured image as a camera backend for the detector: a real camera knows no people."""

    def __init__(self, capture: Capture):
        self._capture = capture

    def image(self, step: int, pose) -> np.ndarray:
        return self._capture.image

    def people(self, step: int, pose) -> PeopleInView | None:
        return None


def run_live(
    world: World,
    policy: Policy,
    tracker: Tracker,
    camera: LiveCamera,
    steps: int,
    period_s: float,
    seed: int,
    clock=time.monotonic,
    sleep=time.sleep,
    observer: StepObserver | None = None,
) -> LiveEpisode:
    """At most ``steps`` steps, ``period_s`` apart; Ctrl-C ends the run early with what was recorded.

    observer : called after every step as :func:`ptztrack.loop.run_loop` calls it, with the step's
    LiveEpisode fields, its ``actions`` (flat index, -1 off the grid) and the captured ``image``
    (None where nothing was captured).
    """
    _, detector_seed, policy_seed, _, _, _ = episode_seeds(seed)
    frame_seeds = detector_seed.spawn(steps)
    policy_rng = np.random.default_rng(policy_seed)
    grid = world.grid
    nearest, commanded = world.start_action, grid.poses[world.start_action]
    camera.send(commanded)
    record: dict[str, list] = {name: [] for name in LiveEpisode.__dataclass_fields__}
    started = clock()
    try:
        for step in range(steps):
            sleep(max(0.0, started + step * period_s - clock()))
            step_time_s = time.time()
            predicted = tracker.predict()
            context = DecisionContext(step, nearest, grid.reachable(nearest), predicted, policy_rng, commanded)
            deciding = time.perf_counter()
            choice = policy.choose(context)
            decision_s = time.perf_counter() - deciding
            action, commanded = command(grid, choice)
            nearest = action if action >= 0 else grid.nearest(commanded)
            sent = camera.send(commanded)
            # Half the step for the camera to land, half for the detector.
            capture = camera.capture(started + (step + 0.5) * period_s)
            measured, pose = None, np.full(3, np.nan)
            if capture is not None:  # else the tracker has its prediction alone: nothing was seen, nor missed
                view = _CapturedView(capture)
                rng = np.random.default_rng(frame_seeds[step])
                detections, pose = world.detector.detect(view, step, capture.pose, rng), capture.pose
                update = tracker.update(detections, capture.pose, partial(view.image, step, capture.pose))
                measured = update.measurements if update.measurements is not None else detections
            step_record = {
                "commanded": commanded,
                "sent": sent,
                "poses": pose,
                "capture_time_s": np.nan if capture is None else capture.time_s,
                "step_time_s": step_time_s,
                "decision_s": decision_s,
                "tracks": tracker.reported(),
                "detections": Detections.empty() if measured is None else measured,
            }
            for name, value in step_record.items():
                record[name].append(value)
            if observer is not None:
                image = None if capture is None else capture.image
                observed_s = clock()
                observer(step, context, {**step_record, "actions": action, "image": image})
                waited_s = clock() - observed_s
                if waited_s > period_s:  # a paused view: the steps after it keep their pace, not catch up
                    started += waited_s
    except KeyboardInterrupt:
        pass  # the steps recorded whole so far are the run
    done = min(len(values) for values in record.values())
    lists = ("tracks", "detections")
    return LiveEpisode(
        **{name: np.asarray(values[:done]) for name, values in record.items() if name not in lists},
        tracks=record["tracks"][:done],
        detections=record["detections"][:done],
    )
