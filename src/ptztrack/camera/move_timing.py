"""How long a camera's moves take, measured the way Frigate calibrates its autotracker: timed moves of
growing size on each axis, each timed from the command until GetStatus reports the camera idle, and a
straight line ``time = intercept + slope x distance`` fitted through them by least squares; and how late
its stream's pictures are (:func:`measure_image_delay`)."""

import time

import cv2
import numpy as np

from ptztrack.camera.onvif_client import ONVIFClient
from ptztrack.camera.onvif_spaces import CameraSpaces, MoveTimes
from ptztrack.camera.stream import OPEN_TIMEOUT_S, LatestFrame

# Moves of these fractions of each axis' range, there and back from the middle of the range.
MOVE_FRACTIONS = (0.05, 0.1, 0.2, 0.4)


def timed_move(client: ONVIFClient, position, timeout_s: float = 30.0) -> float:
    """Seconds from an AbsoluteMove to ``position`` (3,) (normalised) until the camera reports it idle."""
    started = time.monotonic()
    client.move_to(position)
    if client.wait_still(started + timeout_s).moving:
        raise TimeoutError(f"the camera was still moving after {timeout_s:g} s")
    return time.monotonic() - started


def measure_move_times(client: ONVIFClient, spaces: CameraSpaces) -> tuple[MoveTimes, dict]:
    """Fit each axis' move time from timed moves; also returns the samples, {axis: (distances, seconds)}."""
    middle = spaces.pose(np.array([0.0, 0.0, 0.5]))
    ends = spaces.pose(np.array([[-1.0, -1.0, 0.0], [1.0, 1.0, 1.0]]))
    samples, fits = {}, []
    for axis, name in enumerate(("pan", "tilt", "zoom")):
        timed_move(client, spaces.normalised(middle))
        distances, seconds = [], []
        for fraction in MOVE_FRACTIONS:
            target = middle.copy()
            target[axis] += fraction * (ends[1, axis] - ends[0, axis])
            for there in (target, middle):
                start = spaces.pose(client.status().position)
                seconds.append(timed_move(client, spaces.normalised(there)))
                distances.append(abs(there[axis] - start[axis]))
        fits.append(fitted_move_time(distances, seconds))
        samples[name] = (np.asarray(distances), np.asarray(seconds))
    return MoveTimes(*fits), samples


def fitted_move_time(distances, seconds) -> tuple[float, float]:
    """(intercept_s, slope) of ``seconds = intercept + slope x distance`` by least squares over timed moves
    (M,) and (M,), neither below 0."""
    slope, intercept = np.polyfit(np.asarray(distances, dtype=float), np.asarray(seconds, dtype=float), 1)
    return max(float(intercept), 0.0), max(float(slope), 0.0)


# The pictures' sideways shift is measured on grey copies this wide (px), by phase correlation with the
# picture before the turn, until they have shifted SHIFT_FRACTION of it (well within what it tells apart);
# a picture has begun to shift once it is SHIFTED_PX off.
SHIFT_WIDTH_PX, SHIFT_FRACTION, SHIFTED_PX = 160, 0.3, 0.5
SETTLE_S = 0.5


def measure_image_delay(
    client: ONVIFClient, spaces: CameraSpaces, move_times: MoveTimes, latest: LatestFrame, moves: int = 6
) -> tuple[float, float, np.ndarray]:
    """How much older than its arrival a picture of the camera's stream is: ``moves`` pans of a tenth of
    the range, either way from where the camera stands when asked, each timed from the moment the head
    began to turn (its first GetStatus that has moved, less the distance over the pan's speed from
    ``move_times``) to the arrival at which its pictures began to shift (``latest``: the stream's pictures
    stamped with their arrival). A picture shows the head at one moment, so its shift ``x`` grows with the
    time since the turn began, and the straight line through the (arrival, ``x``) of the pictures that have
    shifted crosses ``x = 0`` at that moment plus the delay. Returns the median delay (s), how uncertain a
    capture time is (s: the delays' standard deviation) and each move's delay (moves,)."""
    here = spaces.pose(client.status().position)  # where it stands shows the scene; the middle may not
    pan_ends = spaces.pose(np.array([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]))[:, 0]
    step_deg = 0.1 * float(np.ptp(pan_ends))
    here[0] = np.clip(here[0], pan_ends.min() + step_deg, pan_ends.max() - step_deg)
    delays = []
    for move in range(moves):
        start, there = here.copy(), here.copy()
        there[0] += step_deg if move % 2 == 0 else -step_deg
        timed_move(client, spaces.normalised(start))
        baseline = _still_picture(latest)
        number = latest.received
        client.move_to(spaces.normalised(there))
        began_s = _began_turning(client, spaces, start, move_times.pan[1])
        delays.append(_shift_onset(latest, number, baseline) - began_s)
    return float(np.median(delays)), float(np.std(delays, ddof=1)), np.asarray(delays)


def _grey(image: np.ndarray) -> np.ndarray:
    """A picture (h, w, 3) uint8 BGR as a float32 grey copy SHIFT_WIDTH_PX wide."""
    height_px = max(1, round(SHIFT_WIDTH_PX * image.shape[0] / image.shape[1]))
    grey = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
    return cv2.resize(grey, (SHIFT_WIDTH_PX, height_px), interpolation=cv2.INTER_AREA).astype(np.float32)


def _still_picture(latest: LatestFrame) -> np.ndarray:
    """The newest picture (grey, :func:`_grey`) once the camera has stood for SETTLE_S."""
    if latest.newer(0, OPEN_TIMEOUT_S) is None:
        raise TimeoutError(f"no picture from the stream within {OPEN_TIMEOUT_S:g} s")
    time.sleep(SETTLE_S)
    frame = latest.newer(0, SETTLE_S)
    if frame is None:
        raise TimeoutError(f"no picture from the stream in {SETTLE_S:g} s")
    return _grey(frame.image)


def _began_turning(client: ONVIFClient, spaces: CameraSpaces, start, seconds_per_deg: float) -> float:
    """Epoch seconds the head began to turn: its first GetStatus away from ``start``, less its pan over the
    speed."""
    ends_s = time.monotonic() + 5.0
    while time.monotonic() < ends_s:
        asked_s = time.time()
        pan_deg = spaces.pose(client.status().position)[0]
        answered_s = time.time()
        if abs(pan_deg - start[0]) > 1e-6:
            return (asked_s + answered_s) / 2 - abs(pan_deg - start[0]) * seconds_per_deg
    raise TimeoutError("the camera did not begin to turn within 5 s")


def _shift_onset(latest: LatestFrame, number: int, baseline: np.ndarray) -> float:
    """The arrival time at which the pictures after picture ``number`` began to shift sideways from
    ``baseline``: the straight line through (arrival, shift) of those that have shifted, followed until they
    have shifted SHIFT_FRACTION of the width, at no shift."""
    arrivals, shifts_px = [], []
    ends_s = time.monotonic() + 5.0
    while time.monotonic() < ends_s:
        frame = latest.newer(number, 1.0)
        if frame is None:
            continue
        number = frame.number
        (shift_px, _), _ = cv2.phaseCorrelate(baseline, _grey(frame.image))
        if abs(shift_px) > SHIFT_FRACTION * SHIFT_WIDTH_PX:
            break
        arrivals.append(frame.time_s)
        shifts_px.append(abs(shift_px))
    shifted = np.asarray(shifts_px) > SHIFTED_PX
    if shifted.sum() < 2:
        raise TimeoutError("fewer than 2 pictures showed the turn beginning within 5 s")
    first_s = arrivals[0]
    slope, intercept = np.polyfit(np.asarray(arrivals)[shifted] - first_s, np.asarray(shifts_px)[shifted], 1)
    return first_s - intercept / slope
