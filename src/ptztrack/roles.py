"""The roles of the closed loop, as protocols over :mod:`ptztrack.types`.

Every run is the same loop (:func:`ptztrack.loop.simulated.run_loop`): a camera backend
shows the scene at a pose, a detector finds people in it, a tracker keeps
beliefs about them on the ground plane, and a policy chooses the next pose.
A new backend, detector, tracker or policy implements one of these protocols
and nothing else changes; :mod:`ptztrack.registry` gives it a name that
scenario files and the command line can use.
"""

from collections.abc import Callable, Sequence
from typing import Protocol

import numpy as np

from ptztrack.types import DecisionContext, Detections, PeopleInView, Tracks, TrackUpdate

ImageSource = Callable[[], np.ndarray | None]
"""``view()``: the image the camera shows at the step and pose the tracker is updated for, or None."""

PoseSource = Callable[[int, np.ndarray, np.ndarray], np.ndarray | None]
"""``source(step, commanded, actual)``: the (3,) pose the tracker maps detections with, or None when it
cannot tell (the loop then uses the commanded one)."""


class CameraBackend(Protocol):
    """What a camera shows at a step and a pose (pan_deg, tilt_deg, zoom)."""

    def image(self, step: int, pose: np.ndarray) -> np.ndarray | None:
        """The view, (h, w, 3) uint8 BGR, or None for a camera that renders no images."""
        ...

    def people(self, step: int, pose: np.ndarray) -> PeopleInView | None:
        """The people in view as a simulation knows them, or None for a real camera."""
        ...


class Detector(Protocol):
    """Finds people in what a camera shows."""

    def detect(
        self,
        camera: CameraBackend,
        step: int,
        pose: np.ndarray,
        rng: np.random.Generator,
        believed_pose: np.ndarray | None = None,
    ) -> Detections:
        """Detections in the view at ``pose``, where the camera is; ``rng`` is the step's own stream (draw
        only from it). ``believed_pose`` is the pose the system takes the camera to be at (its pose
        source's, else the commanded one; None: ``pose``): a detector that plans where to look plans
        there, since only a simulation knows ``pose``."""
        ...


class Updater(Protocol):
    """What a loop's measurement step needs of a tracker: one camera's update of the belief."""

    def wants_detections(self, step: int) -> bool:
        """Whether the detector should run at ``step`` (a tracker may measure on its own in between)."""
        ...

    def update(
        self, detections: Detections | None, pose: np.ndarray, view: ImageSource, pose_sd: np.ndarray | None = None
    ) -> TrackUpdate:
        """Update with the step's detections (None where it did not ask for any), taken at ``pose``, known
        to within ``pose_sd`` (3,) standard deviations (None: exactly)."""
        ...


class Tracker(Updater, Protocol):
    """Keeps beliefs about people on the ground plane, one step at a time."""

    def predict(self, dt_s: float | None = None) -> Tracks:
        """Advance every track by one step (``dt_s`` seconds; None: the tracker's own step); returns the
        predicted tracks, which the policy plans with."""
        ...

    def reported(self) -> Tracks:
        """The tracks the tracker reports now (the metrics score these)."""
        ...


class Policy(Protocol):
    """Chooses where the camera looks next; may keep state across the steps of one episode."""

    def choose(self, context: DecisionContext) -> int | np.ndarray:
        """The flat index of the next grid action, one of ``context.reachable``; or, for a policy that
        commands the camera continuously (and keeps to its mechanics itself), a (3,) pose."""
        ...


class NetworkTracker(Protocol):
    """One ground belief that several cameras update in turn (:func:`ptztrack.loop.simulated.run_network_loop`)."""

    def predict(self, dt_s: float | None = None) -> Tracks:
        """Advance every track by one step, once for the whole network; returns the predicted tracks."""
        ...

    def updater(self, camera: int) -> Updater:
        """The update of the belief by camera ``camera`` (an index into the network's cameras)."""
        ...

    def reported(self) -> Tracks:
        """The tracks the network reports now (the metrics score these)."""
        ...


class NetworkPolicy(Protocol):
    """Chooses where every camera of a network looks next, one choice per camera."""

    def choose(self, contexts: Sequence[DecisionContext]) -> list[int | np.ndarray]:
        """Per camera, in the order of ``contexts`` (one per camera, all with the same predicted tracks), what
        :meth:`Policy.choose` would return for it: a flat action index of its grid, or a (3,) pose."""
        ...
