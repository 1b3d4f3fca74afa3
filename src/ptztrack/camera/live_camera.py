"""A live ONVIF camera for the real-time loop: poses in the model's units, and reconnection with backoff.

:class:`ReconnectingCamera` is the :class:`ptztrack.live.LiveCamera` of an
ONVIF camera. It converts poses with the camera's calibration
(:class:`ptztrack.camera.onvif_spaces.CameraSpaces`); a command is sent
only while the camera stands still (the paper's camera is not sent a new
decision while it moves); an image is taken only while it stands still,
with the pose its GetStatus reports, and after a move only once
``image_delay_s`` has passed (a stream shows a pose a frame or more after
the camera reaches it). When a call fails (the camera is
gone, stalls past its timeout, or answers with a fault) it logs one line,
gives nothing for the step, and tries to reconnect after 0.5 s, then 1, 2,
4 and at most 8 s, logging one line when the camera is back.
"""

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ptztrack.camera.onvif_client import CameraError, ONVIFClient
from ptztrack.camera.onvif_spaces import CameraSpaces

log = logging.getLogger("ptztrack.live")


@dataclass(frozen=True)
class Capture:
    """One image of the camera: (h, w, 3) uint8 BGR, the pose (3,) it was taken at, and when (epoch s)."""

    image: np.ndarray
    pose: np.ndarray
    time_s: float


FIRST_RETRY_S = 0.5
LONGEST_RETRY_S = 8.0


class ReconnectingCamera:
    """An ONVIF camera made by ``connect()`` (a connected :class:`ONVIFClient`), seen in the model's poses."""

    def __init__(
        self, connect: Callable[[], ONVIFClient], spaces: CameraSpaces, image_delay_s: float, clock=time.monotonic
    ):
        self._connect, self.spaces, self.image_delay_s, self._clock = connect, spaces, image_delay_s, clock
        self.client: ONVIFClient | None = connect()
        self._moved = False
        self._retry_s, self._retry_at, self._lost_at = FIRST_RETRY_S, 0.0, 0.0
        self.failures = 0

    def send(self, pose) -> bool:
        client = self._client()
        if client is None:
            return False
        try:
            if client.status().moving:
                return False
            client.move_to(self.spaces.normalised(pose))
            self._moved = True
            return True
        except CameraError as error:
            self._lose(error)
            return False

    def capture(self, until_s: float) -> Capture | None:
        client = self._client()
        if client is None:
            return None
        try:
            status = client.wait_still(until_s)
            if status.moving:
                return None
            if self._moved:  # the images of the new pose come after the camera stands there
                time.sleep(self.image_delay_s)
                self._moved = False
            image = client.snapshot()
            return Capture(image, self.spaces.pose(status.position), time.time())
        except CameraError as error:
            self._lose(error)
            return None

    def close(self) -> None:
        if self.client is not None:
            self.client.close()
            self.client = None

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
        return self.client

    def _lose(self, error: CameraError) -> None:
        self.failures += 1
        log.warning("camera lost (%s); the tracker runs on predictions, retrying in %.1f s", error, self._retry_s)
        if self.client is not None:
            self.client.close()
        self.client = None
        self._lost_at = self._clock()
        self._retry_at = self._lost_at + self._retry_s
