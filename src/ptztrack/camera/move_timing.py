"""How long a camera's moves take, measured the way Frigate calibrates its autotracker: timed moves of
growing size on each axis, each timed from the command until GetStatus reports the camera idle, and a
straight line ``time = intercept + slope x distance`` fitted through them by least squares."""

import time

import numpy as np

from ptztrack.camera.onvif_client import ONVIFClient
from ptztrack.camera.onvif_spaces import CameraSpaces, MoveTimes

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
