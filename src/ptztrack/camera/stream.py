"""A camera's pictures as they come, each with the time it was taken.

A :class:`FrameStream` reads its source in a thread of its own, without
pause, and keeps only the newest picture (:class:`LatestFrame`): whoever uses
the pictures takes the newest one whenever it is ready for another, and never
one it has had. The source is the camera's RTSP stream, decoded by OpenCV's
FFmpeg with one decoding thread (FFmpeg's frame threads hold each picture back
by a frame per thread), or, for a camera without a stream, its snapshot asked
for again and again. A picture's capture time is its arrival less the stream's
delay (the calibration's ``image_delay_s``): what the camera's pose is looked
up at.
"""

import logging
import os
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from urllib.parse import urlsplit

import cv2
import numpy as np

log = logging.getLogger("ptztrack.loop.live")

OPEN_TIMEOUT_S = 10.0
# OpenCV's FFmpeg reads its options from this variable when a capture opens; the lock keeps two opens
# from mixing their transports.
_FFMPEG_OPTIONS = "OPENCV_FFMPEG_CAPTURE_OPTIONS"
_OPEN_LOCK = threading.Lock()


THUMBNAIL_SIZE_PX = (64, 48)
# A LatestFrame keeps this many of the newest pictures, to be found by their capture time.
RECENT_PICTURES = 8
# The frame clock is fitted to a stream's last this many pictures (2 s at 25 fps).
FRAME_CLOCK_PICTURES = 50


def thumbnail(image: np.ndarray) -> np.ndarray:
    """A picture (h, w, 3) uint8 BGR as a (48, 64) float32 grey thumbnail, area-averaged: what survives a
    stream's compression of it."""
    grey = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
    return cv2.resize(grey, THUMBNAIL_SIZE_PX, interpolation=cv2.INTER_AREA).astype(np.float32)


@dataclass(frozen=True)
class Frame:
    """One picture: image (h, w, 3) uint8 BGR, its capture time (epoch s), and its number (1 for the
    first picture of the stream)."""

    image: np.ndarray
    time_s: float
    number: int


class LatestFrame:
    """The newest picture of a source, handed from the thread that receives to the one that uses them (and
    the RECENT_PICTURES newest, to find one by its capture time)."""

    def __init__(self) -> None:
        self._condition = threading.Condition()
        self._frame: Frame | None = None
        self._recent: deque[Frame] = deque(maxlen=RECENT_PICTURES)
        self.received = 0

    def put(self, image: np.ndarray, time_s: float) -> None:
        with self._condition:
            self.received += 1
            self._frame = Frame(image, time_s, self.received)
            self._recent.append(self._frame)
            self._condition.notify_all()

    def captured_at(self, time_s: float) -> Frame | None:
        """The picture of capture time ``time_s`` among the RECENT_PICTURES newest; None if gone or never."""
        with self._condition:
            return next((frame for frame in self._recent if frame.time_s == time_s), None)

    def newer(self, number: int, timeout_s: float) -> Frame | None:
        """The newest picture after picture ``number``, waiting at most ``timeout_s``; None if none came."""
        with self._condition:
            self._condition.wait_for(lambda: self.received > number, timeout_s)
            frame = self._frame
        return frame if frame is not None and frame.number > number else None


def open_rtsp(uri: str, transport: str = "tcp", timeout_s: float = OPEN_TIMEOUT_S) -> cv2.VideoCapture:
    """An OpenCV capture of the RTSP stream at ``uri`` over ``transport`` ('tcp' or 'udp'), one decoding
    thread, ``timeout_s`` to open and for every read; a ConnectionError naming the stream (not its
    credentials) if it does not open."""
    if transport not in ("tcp", "udp"):
        raise ValueError(f"transport {transport!r}: expected 'tcp' or 'udp'")
    milliseconds = int(1000 * timeout_s)
    properties = [
        cv2.CAP_PROP_OPEN_TIMEOUT_MSEC,
        milliseconds,
        cv2.CAP_PROP_READ_TIMEOUT_MSEC,
        milliseconds,
        cv2.CAP_PROP_N_THREADS,
        1,
    ]
    with _OPEN_LOCK:
        before = os.environ.get(_FFMPEG_OPTIONS)
        os.environ[_FFMPEG_OPTIONS] = f"rtsp_transport;{transport}"
        try:
            capture = cv2.VideoCapture(uri, cv2.CAP_FFMPEG, properties)
        finally:
            if before is None:
                del os.environ[_FFMPEG_OPTIONS]
            else:
                os.environ[_FFMPEG_OPTIONS] = before
    if not capture.isOpened():
        capture.release()
        parts = urlsplit(uri)
        raise ConnectionError(f"{parts.hostname}:{parts.port}: the RTSP stream does not open")
    return capture


def on_frame_clock(numbers, times_s) -> float:
    """The capture time of the newest of a stream's pictures on the camera's frame clock: the straight line
    ``t = a + P k`` through the pictures' numbers ``k`` (n,) and their times (n,) (s, arrival less the
    delay), fitted by least squares, at the newest ``k``. A camera takes its pictures ``P`` apart, and
    the line averages away how unevenly they arrive. The newest time as it is where fewer than 3 pictures
    are given, or where they lie off any clock (rms distance from the line over a quarter of ``P``:
    snapshots, say)."""
    numbers = np.asarray(numbers, dtype=float)
    times_s = np.asarray(times_s, dtype=float)
    if len(times_s) < 3 or np.ptp(numbers) == 0:
        return float(times_s[-1])
    offsets_s = times_s - times_s[0]
    period_s, start_s = np.polyfit(numbers - numbers[0], offsets_s, 1)
    residuals_s = offsets_s - (start_s + period_s * (numbers - numbers[0]))
    if not period_s > 0 or np.sqrt(np.mean(residuals_s**2)) > period_s / 4:
        return float(times_s[-1])
    return float(times_s[0] + start_s + period_s * (numbers[-1] - numbers[0]))


class FrameStream:
    """Pictures from ``open_source()``, a callable that gives a ``read() -> image or None`` (None when
    the source has ended) and a ``close()``, or raises ConnectionError while it cannot be opened; read in
    a daemon thread, each picture stamped ``clock() - delay_s`` and put on the frame clock of the last
    FRAME_CLOCK_PICTURES pictures since the source was opened (:func:`on_frame_clock`). A source that ends
    or cannot be opened is opened again after ``retry_s``. Pictures go to ``latest``."""

    def __init__(
        self,
        open_source: Callable[[], tuple[Callable[[], np.ndarray | None], Callable[[], None]]],
        delay_s: float,
        retry_s: float = 0.5,
        clock: Callable[[], float] = time.time,
    ) -> None:
        self._open_source, self.delay_s, self._retry_s, self._clock = open_source, delay_s, retry_s, clock
        self.latest = LatestFrame()
        self._stopping = threading.Event()
        self._thread = threading.Thread(target=self._run, name="camera-frames", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def stop(self) -> None:
        self._stopping.set()
        self._thread.join(1.0)  # a read blocked on a camera gone ends at its own timeout, in a daemon thread

    def _run(self) -> None:
        while not self._stopping.is_set():
            try:
                read, close = self._open_source()
            except ConnectionError as error:
                log.debug("no pictures: %s", error)
                self._stopping.wait(self._retry_s)
                continue
            numbers: deque[int] = deque(maxlen=FRAME_CLOCK_PICTURES)
            times_s: deque[float] = deque(maxlen=FRAME_CLOCK_PICTURES)
            try:
                while not self._stopping.is_set():
                    image = read()
                    if image is None:
                        break
                    numbers.append(numbers[-1] + 1 if numbers else 0)
                    times_s.append(self._clock() - self.delay_s)
                    self.latest.put(image, on_frame_clock(numbers, times_s))
            except Exception as error:  # noqa: BLE001 - a source that fails is opened again, as one that ends
                log.debug("the pictures stopped: %s", error)
            finally:
                close()
            self._stopping.wait(self._retry_s)


def rtsp_pictures(uri: str, transport: str = "tcp"):
    """An ``open_source`` for :class:`FrameStream`: the RTSP stream at ``uri`` (``read`` None once it ends)."""

    def open_source():
        capture = open_rtsp(uri, transport)

        def read() -> np.ndarray | None:
            ok, image = capture.read()
            return image if ok else None

        return read, capture.release

    return open_source
