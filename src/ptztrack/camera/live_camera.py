"""A live ONVIF camera for the real-time loop: its pictures, its pose at any moment and its commands,
each in a thread of its own, and reconnection with backoff.

:class:`LiveONVIFCamera` never makes its user wait for the camera. Its
pictures come from its RTSP stream (its snapshot URI where it has none),
read without pause (:mod:`ptztrack.camera.stream`). Its control thread asks
for GetStatus every ``poll_s`` and keeps the answers
(:class:`~ptztrack.camera.pose_timeline.PoseTimeline`), and sends the newest
target it was given at once, whether the camera still moves or not (a
newer target replaces one not yet sent). Poses are in the model's units,
converted with the camera's calibration
(:class:`~ptztrack.camera.onvif_spaces.CameraSpaces`). When a call fails
(the camera is gone, stalls past its timeout, or answers with a fault) it
logs one line and tries to reconnect after 0.5 s, then 1, 2, 4 and at most
8 s, logging one line when the camera is back; meanwhile the timeline has
no new samples and the stream no new pictures.

Given a ``sweep`` (a camera that reports no positions, or whose positions
are not trusted: ``ptztrack live --pose registered``), it first builds a
reference index from a sweep of its own pictures
(:func:`~ptztrack.camera.reference_sweep.sweep_index`); then its control
thread, instead of asking GetStatus, registers each picture whose pose is
asked for (the newest one when none has been for ``REGISTER_IDLE_S``) and
puts its pose into the timeline (a
:class:`~ptztrack.camera.registered_timeline.RegisteredTimeline`) at the
picture's capture time, and sends a target once the last move could have
landed, as a move from the newest registered pose
(:class:`~ptztrack.camera.reference_sweep.Mover`). A picture that does not
register is not used, with at most one log line a second; after a second
without a sample it gives a dead-reckoned one, from which the moves go on.
"""

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ptztrack.camera.onvif_client import CameraError, ONVIFClient
from ptztrack.camera.onvif_spaces import CameraSpaces
from ptztrack.camera.pose_timeline import PoseTimeline
from ptztrack.camera.reference_sweep import (
    KnownView,
    Mover,
    PictureRegistration,
    registered_sd,
    stop_at,
    sweep_index,
)
from ptztrack.camera.registered_timeline import RegisteredTimeline
from ptztrack.camera.stream import Frame, FrameStream, rtsp_pictures
from ptztrack.geometry.ptz import PTZCamera

log = logging.getLogger("ptztrack.loop.live")

FIRST_RETRY_S = 0.5
LONGEST_RETRY_S = 8.0
# GetStatus this often: a camera at 90 deg/s turns 3.6 deg between two samples.
POLL_S = 0.04
# A camera without a stream is asked for its snapshot at most this often.
SNAPSHOT_INTERVAL_S = 0.1
# Pictures that do not register are logged at most once in this many seconds.
UNREGISTERED_LOG_S = 1.0
# A camera placed by its pictures registers the pictures whose poses are asked for, and, when none is
# asked for this long, its newest one: a priori, five a second keep a camera's pose current between
# decisions at a fraction of the cost of every picture.
REGISTER_IDLE_S = 0.2


@dataclass(frozen=True)
class Sweep:
    """What a camera placed by its pictures sweeps at the start: from the ``known`` view over a grid
    covering ``grid_poses`` (G, 3), its views bundle-adjusted through ``model`` (the world's camera)."""

    known: KnownView
    grid_poses: np.ndarray
    model: PTZCamera


class LiveONVIFCamera:
    """The ONVIF camera that ``connect()`` (a connected :class:`ONVIFClient`) reaches, seen in the
    model's poses; ``connect`` is called at once, and its CameraError is the caller's.

    spaces : the calibration's spaces; timeline : where GetStatus samples and targets go;
    image_delay_s : how much older than its arrival a picture is; transport : RTSP over 'tcp' or 'udp'.
    sweep : place the camera by its pictures (module docstring; ``timeline`` a RegisteredTimeline and
    ``spaces`` in world degrees), None to ask GetStatus.
    ``frames.latest`` holds the newest picture; ``failures`` counts the calls that failed (each an
    outage), ``reconnects`` the connections made again after one; ``away_since_s`` is the epoch second
    the camera was lost (None while connected) and ``lost_because`` the failure's one line;
    ``registration`` is the pictures' registration once swept.
    """

    def __init__(
        self,
        connect: Callable[[], ONVIFClient],
        spaces: CameraSpaces,
        timeline: PoseTimeline,
        image_delay_s: float,
        transport: str = "tcp",
        poll_s: float = POLL_S,
        clock: Callable[[], float] = time.monotonic,
        sweep: Sweep | None = None,
    ):
        if sweep is not None and not isinstance(timeline, RegisteredTimeline):
            raise TypeError("a camera placed by its pictures keeps them in a RegisteredTimeline")
        self._connect, self.spaces, self.timeline = connect, spaces, timeline
        self.sweep = sweep
        self.registration: PictureRegistration | None = None
        self._mover: Mover | None = None
        self._stop_s: float | None = None
        self._registered_number = 0
        self._unregistered, self._unregistered_logged_s = 0, -np.inf
        self.transport, self.poll_s, self._clock = transport, poll_s, clock
        self.client: ONVIFClient | None = connect()
        self.frames = FrameStream(self._open_pictures, image_delay_s)
        self.failures, self.reconnects = 0, 0
        self.away_since_s: float | None = None
        self.lost_because = ""
        self._lock = threading.Lock()
        self._wake, self._stopping = threading.Event(), threading.Event()
        self._pending: np.ndarray | None = None
        self._last_target: np.ndarray | None = None
        self._retry_s, self._retry_at, self._lost_at = FIRST_RETRY_S, 0.0, 0.0
        self._control = threading.Thread(target=self._run, name="camera-control", daemon=True)
        if isinstance(timeline, RegisteredTimeline):
            timeline.asked = self._wake.set  # a picture's pose asked for: register it at once

    def start(self) -> None:
        """Start the stream and the control thread; with a ``sweep``, sweep first (a CameraError of one line
        if the camera cannot be placed by its pictures)."""
        if self.sweep is None:
            self._control.start()
            self.frames.start()
            return
        self.frames.start()
        self._swept()
        self._control.start()

    def _swept(self) -> None:
        """Choose the moves the camera's node offers and build the reference index from the sweep."""
        client = self.client
        assert client is not None and self.sweep is not None and self.timeline.move_times is not None
        moves = client.moves()
        if not (moves.relative or moves.continuous):
            raise CameraError(f"{client.address}: the camera offers neither RelativeMove nor ContinuousMove")
        if self.sweep.known.preset is None and not moves.absolute:
            raise CameraError(
                f"{client.address}: the camera has no AbsoluteMove to reach a known view: give its calibration "
                "a ground_view (camera calibrate --geometry)"
            )
        self._mover = Mover(self.spaces, self.timeline.move_times, relative=moves.relative)
        sweep = self.sweep
        self.registration = sweep_index(
            client, self.frames.latest, sweep.model, self._mover, sweep.known, sweep.grid_poses
        )

    def send(self, pose) -> bool:
        """Have the camera go to ``pose`` (3,) as soon as the control thread can; whether it is a new target."""
        pose = np.asarray(pose, dtype=float)
        with self._lock:
            if self._last_target is not None and np.array_equal(pose, self._last_target):
                return False
            self._pending = self._last_target = pose
        self._wake.set()
        return True

    def close(self) -> None:
        """Stop the threads and close the client; the camera stays where it is."""
        self._stopping.set()
        self._wake.set()
        if self._control.is_alive():
            self._control.join()
        self.frames.stop()
        if self.client is not None:
            self.client.close()
            self.client = None

    def _run(self) -> None:
        while not self._stopping.is_set():
            started = self._clock()
            client = self._client()
            if client is not None:
                try:
                    self._step(client)
                except CameraError as error:
                    self._lose(error)
            self._wake.wait(max(0.0, started + self.poll_s - self._clock()))
            self._wake.clear()

    def _step(self, client: ONVIFClient) -> None:
        if self.registration is not None:
            self._registered_step(client)
            return
        with self._lock:
            target, self._pending = self._pending, None
        if target is not None:
            sent_s = time.time()
            client.move_to(self.spaces.normalised(target))
            self.timeline.sent(sent_s, target)
        asked_s = time.time()
        status = client.status()
        answered_s = time.time()
        self.timeline.sample((asked_s + answered_s) / 2, self.spaces.pose(status.position), status.moving)

    def _registered_step(self, client: ONVIFClient) -> None:
        """Stop a ContinuousMove that is due, register the picture whose pose is asked for (or, after
        REGISTER_IDLE_S without one, the newest), and send the pending target once the timeline is ready
        for a move."""
        assert isinstance(self.timeline, RegisteredTimeline) and self._mover is not None
        if self._stop_s is not None and time.time() >= self._stop_s:
            stop_at(client, self._stop_s)
            self._stop_s = None
        wanted_s, latest = self.timeline.wanted(), self.frames.latest
        frame = latest.newer(self._registered_number, 0.0)
        if wanted_s is not None:
            frame = latest.captured_at(wanted_s) or frame
        elif time.time() < self.timeline.newest_s() + self.frames.delay_s + REGISTER_IDLE_S:
            frame = None
        if frame is not None and frame.time_s > self.timeline.newest_s():  # the samples stay in time order
            self._registered_number = max(self._registered_number, frame.number)
            self._register(frame)
        with self._lock:
            target = self._pending
        if target is None or not self.timeline.ready(time.time()):
            return
        current = self.timeline.current()
        with self._lock:
            if self._pending is target:
                self._pending = None
        sent_s = time.time()
        self._stop_s = self._mover.move(client, current, target)
        self.timeline.sent(sent_s, target)

    def _register(self, frame: Frame) -> None:
        """Put the pose of ``frame`` into the timeline; where it does not register, the picture is not
        used (the timeline may dead-reckon the camera's moves from it) and a line is logged (at most one
        a second)."""
        assert isinstance(self.timeline, RegisteredTimeline) and self.registration is not None
        pose = self.registration.pose(frame.image)
        if pose is not None:
            self.timeline.registered(frame.time_s, pose, registered_sd(pose))
            return
        self._unregistered += 1
        reckoned = self.timeline.dead_reckoned(frame.time_s)
        now_s = self._clock()
        if now_s >= self._unregistered_logged_s + UNREGISTERED_LOG_S:
            what = "not used; the moves go on from where the last ones took it" if reckoned else "not used"
            log.warning(
                "picture %d did not register against the reference views (%d since the last such line): %s",
                frame.number, self._unregistered, what,
            )  # fmt: skip
            self._unregistered, self._unregistered_logged_s = 0, now_s

    def _open_pictures(self):
        """The stream's ``read`` and ``close`` (:class:`FrameStream`), the snapshots' where it has no stream."""
        client = self.client
        if client is None:
            raise ConnectionError("the camera is away")
        try:
            return rtsp_pictures(client.stream_uri(), self.transport)()
        except (CameraError, ConnectionError) as error:
            log.debug("no RTSP stream (%s): snapshots instead", error)
            return self._snapshot, lambda: None

    def _snapshot(self) -> np.ndarray | None:
        """The connected camera's snapshot, at most every SNAPSHOT_INTERVAL_S; None once it is away."""
        client = self.client
        if self._stopping.wait(SNAPSHOT_INTERVAL_S) or client is None:
            return None
        try:
            return client.snapshot()
        except CameraError:
            return None

    def _client(self) -> ONVIFClient | None:
        """The connected client, reconnecting when a retry is due; None while the camera is away."""
        if self.client is not None or self._clock() < self._retry_at:
            return self.client
        try:
            self.client = self._connect()
        except CameraError as error:
            self._retry_at = self._clock() + self._retry_s
            log.warning("camera still unreachable (%s); next try in %.1f s", error, self._retry_s)
            self._retry_s = min(2 * self._retry_s, LONGEST_RETRY_S)
            return None
        log.warning("camera back after %.1f s", self._clock() - self._lost_at)
        self.reconnects += 1
        self.away_since_s = None
        self._retry_s = FIRST_RETRY_S
        with self._lock:
            self._pending = self._last_target  # the target the camera may not have had
        return self.client

    def _lose(self, error: CameraError) -> None:
        self.failures += 1
        self.away_since_s, self.lost_because = time.time(), str(error)
        log.warning("camera lost (%s); the tracker runs on predictions, retrying in %.1f s", error, self._retry_s)
        client, self.client = self.client, None
        if client is not None:
            client.close()
        self._lost_at = self._clock()
        self._retry_at = self._lost_at + self._retry_s
