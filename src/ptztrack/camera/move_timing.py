"""How long a camera's moves take, measured the way Frigate calibrates its autotracker: timed moves of
growing size on each axis, each timed from the command until GetStatus reports the camera idle, and a
straight line ``time = intercept + slope x distance`` fitted through them by least squares; and how late
its stream's pictures are (:func:`measure_image_delay`)."""

import time

import numpy as np

from ptztrack.camera.onvif_client import ONVIFClient
from ptztrack.camera.onvif_spaces import CameraSpaces, MoveTimes
from ptztrack.camera.stream import OPEN_TIMEOUT_S, LatestFrame, thumbnail

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
        slope, intercept = np.polyfit(distances, seconds, 1)
        fits.append((max(float(intercept), 0.0), max(float(slope), 0.0)))
        samples[name] = (np.asarray(distances), np.asarray(seconds))
    return MoveTimes(*fits), samples


# A picture has changed when it differs from the one before the move by this many times the differences of
# pictures of the standing camera (the scene's own motion, the stream's noise), and by at least CHANGED_GREY.
CHANGED_NOISE_RATIO, CHANGED_GREY = 4.0, 2.0
SETTLE_S = 0.5


def measure_image_delay(
    client: ONVIFClient, spaces: CameraSpaces, move_times: MoveTimes, latest: LatestFrame, moves: int = 6
) -> tuple[float, np.ndarray]:
    """How much older than its arrival a picture of the camera's stream is: ``moves`` pans of a tenth of
    the range, either way from where the camera stands when asked, each timed from the moment the head
    began to turn (its first GetStatus that has moved, less the distance over the pan's speed from
    ``move_times``) to the arrival of the first picture that shows it (``latest``: the stream's pictures
    stamped with their arrival), less half the stream's frame interval (a picture shows the head at a
    moment within its interval). Returns the median delay (s) and each move's (moves,)."""
    here = spaces.pose(client.status().position)  # where it stands shows the scene; the middle may not
    pan_ends = spaces.pose(np.array([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]))[:, 0]
    step_deg = 0.1 * float(np.ptp(pan_ends))
    here[0] = np.clip(here[0], pan_ends.min() + step_deg, pan_ends.max() - step_deg)
    delays = []
    for move in range(moves):
        start, there = here.copy(), here.copy()
        there[0] += step_deg if move % 2 == 0 else -step_deg
        timed_move(client, spaces.normalised(start))
        arrivals, changes, baseline = _still_pictures(latest)
        interval_s = float(np.median(np.diff(arrivals)))
        threshold = max(CHANGED_NOISE_RATIO * float(np.max(changes)), CHANGED_GREY)
        number = latest.received
        client.move_to(spaces.normalised(there))
        began_s = _began_turning(client, spaces, start, move_times.pan[1])
        delays.append(_first_changed(latest, number, baseline, threshold) - began_s - interval_s / 2)
    return float(np.median(delays)), np.asarray(delays)


def _still_pictures(latest: LatestFrame) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The arrival times of the pictures of SETTLE_S while the camera stands, their thumbnails'
    differences from one to the next, and the last thumbnail."""
    if latest.newer(0, OPEN_TIMEOUT_S) is None:
        raise TimeoutError(f"no picture from the stream within {OPEN_TIMEOUT_S:g} s")
    time.sleep(SETTLE_S)
    number, arrivals, thumbnails = latest.received, [], []
    ends_s = time.monotonic() + SETTLE_S
    while time.monotonic() < ends_s:
        frame = latest.newer(number, SETTLE_S)
        if frame is None:
            break
        number = frame.number
        arrivals.append(frame.time_s)
        thumbnails.append(thumbnail(frame.image))
    if len(thumbnails) < 3:
        raise TimeoutError(f"fewer than 3 pictures from the stream in {SETTLE_S:g} s")
    changes = np.mean(np.abs(np.diff(np.asarray(thumbnails), axis=0)), axis=(1, 2))
    return np.asarray(arrivals), changes, thumbnails[-1]


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


def _first_changed(latest: LatestFrame, number: int, baseline: np.ndarray, threshold: float) -> float:
    """The arrival time of the first picture after picture ``number`` that differs from ``baseline`` by more
    than ``threshold`` grey levels on average."""
    ends_s = time.monotonic() + 5.0
    while time.monotonic() < ends_s:
        frame = latest.newer(number, 1.0)
        if frame is None:
            continue
        number = frame.number
        if np.mean(np.abs(thumbnail(frame.image) - baseline)) > threshold:
            return frame.time_s
    raise TimeoutError("no picture showed the move within 5 s")
