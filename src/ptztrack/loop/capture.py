"""The face-capture loop (MSG paper, section 4): one PTZ camera either zoomed out over the whole area or
zoomed in on one person until their face is captured, its tracker fed by what it observes, and a scheduler
that decides, at every zoomed-out step, whether to zoom in and on whom.

It knows only the roles: a camera whose observation at a step may hold a captured face, a tracker updated
with each observation, and a decision made from the tracker's state at a zoomed-out step. A zoom in lasts
to its ``capture_step`` (inclusive); no decision is made while it lasts.
"""

from collections.abc import Callable
from typing import Any, Protocol, TypeVar


class ZoomIn(Protocol):
    @property
    def capture_step(self) -> int:
        """The last step of the zoom, the one its face is captured at."""
        ...


class CaptureCamera(Protocol):
    def observe(self, step: int, zoom: Any = None) -> Any:
        """What the camera sees at ``step``: zoomed out (``zoom`` None) or zoomed in as ``zoom`` says; its
        ``capture`` is None, or the capture whose ``face`` is the person captured."""
        ...


class ObservationTracker(Protocol):
    def update(self, observation: Any) -> None: ...


Target = TypeVar("Target")


def run_capture_loop(
    camera: CaptureCamera,
    tracker: ObservationTracker,
    decide: Callable[[int], tuple[ZoomIn, Target] | None],
    steps: int,
) -> tuple[list[tuple[int, Target]], list[tuple[int, int]]]:
    """Run ``steps`` steps: every step the camera observes (zoomed in while a zoom lasts) and the tracker
    takes the observation in; at every zoomed-out step, ``decide(step)`` gives the zoom to start and what
    it is on (a tracker's vertex, say), or None to stay zoomed out. Returns the zooms, as (decision step,
    what it was on), and the captured faces, as (step, face)."""
    zooms: list[tuple[int, Target]] = []
    captures: list[tuple[int, int]] = []
    zoom: ZoomIn | None = None
    for step in range(steps):
        zoomed_in = zoom is not None and step <= zoom.capture_step
        observation = camera.observe(step, zoom if zoomed_in else None)
        tracker.update(observation)
        if observation.capture is not None:
            captures.append((step, observation.capture.face))
        if zoomed_in:
            continue
        decision = decide(step)
        zoom = None if decision is None else decision[0]
        if decision is not None:
            zooms.append((step, decision[1]))
    return zooms, captures
