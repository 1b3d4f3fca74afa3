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
"""

import logging
import threading
import time
from collections.abc import Callable

import numpy as np

from ptztrack.camera.onvif_client import CameraError, ONVIFClient
from ptztrack.camera.onvif_spaces import CameraSpaces
from ptztrack.camera.pose_timeline import PoseTimeline
from ptztrack.camera.stream import FrameStream, rtsp_pictures

log = logging.getLogger("ptztrack.loop.live")

FIRST_RETRY_S = 0.5
LONGEST_RETRY_S = 8.0
# GetStatus this often: a camera at 90 deg/s turns 3.6 deg between two samples.
POLL_S = 0.04
# A camera without a stream is asked for its snapshot at most this often.
SNAPSHOT_INTERVAL_S = 0.1


class LiveONVIFCamera:
    """The ONVIF camera that ``connect()`` (a connected :class:`ONVIFClient`) reaches, seen in the
    model's poses; ``connect`` is called at once, and its CameraError is the caller's.

    spaces : the calibration's spaces; timeline : where GetStatus samples and targets go;
    image_delay_s : how much older than its arrival a picture is; transport : RTSP over 'tcp' or 'udp'.
    ``frames.latest`` holds the newest picture; ``failures`` counts the calls that failed.
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
    ):
        self._connect, self.spaces, self.timeline = connect, spaces, timeline
        self.transport, self.poll_s, self._clock = transport, poll_s, clock
        self.client: ONVIFClient | None = connect()
        self.frames = FrameStream(self._open_pictures, image_delay_s)
        self.failures = 0
        self._lock = threading.Lock()
        self._wake, self._stopping = threading.Event(), threading.Event()
        self._pending: np.ndarray | None = None
        self._last_target: np.ndarray | None = None
        self._retry_s, self._retry_at, self._lost_at = FIRST_RETRY_S, 0.0, 0.0
        self._control = threading.Thread(target=self._run, name="camera-control", daemon=True)

    def start(self) -> None:
        self._control.start()
        self.frames.start()

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
        self._retry_s = FIRST_RETRY_S
        with self._lock:
            self._pending = self._last_target  # the target the camera may not have had
        return self.client

    def _lose(self, error: CameraError) -> None:
        self.failures += 1
        log.warning("camera lost (%s); the tracker runs on predictions, retrying in %.1f s", error, self._retry_s)
        client, self.client = self.client, None
        if client is not None:
            client.close()
        self._lost_at = self._clock()
        self._retry_at = self._lost_at + self._retry_s
