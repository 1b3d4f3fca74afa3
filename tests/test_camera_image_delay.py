"""A stream's delay, timed from where its pictures begin to shift once the head turns."""

import threading

import cv2
import numpy as np
import pytest

from ptztrack.camera.move_timing import _grey, _shift_onset
from ptztrack.camera.stream import LatestFrame

PERIOD_S, DELAY_S, SPEED_PX_S = 0.04, 0.05, 400.0


def _scene() -> np.ndarray:
    rng = np.random.default_rng(0)
    texture = cv2.GaussianBlur(rng.uniform(0, 255, (240, 320)).astype(np.float32), (0, 0), 3.0)
    return cv2.cvtColor(cv2.normalize(texture, None, 0, 255, cv2.NORM_MINMAX).astype(np.uint8), cv2.COLOR_GRAY2BGR)


@pytest.mark.parametrize("began_after_tick_s", [0.0, 0.013, 0.031])
def test_the_delay_is_where_the_pictures_shift_begins_whenever_within_a_frame_the_head_turned(began_after_tick_s):
    """Pictures taken every 40 ms arrive 50 ms later; the head begins to turn between two of them and the
    picture shifts 400 px/s from then: the line through the shifts crosses zero at the turn plus the delay,
    to the millisecond, where the first picture showing the turn is up to a frame later."""
    scene, latest = _scene(), LatestFrame()
    began_s = 1000.0 + began_after_tick_s

    def camera() -> None:
        for k in range(30):
            taken_s = 1000.0 - 0.2 + k * PERIOD_S
            shift_px = SPEED_PX_S * max(0.0, taken_s - began_s)
            moved = cv2.warpAffine(
                scene, np.float32([[1, 0, -shift_px], [0, 1, 0]]), (320, 240), borderMode=cv2.BORDER_REFLECT
            )
            latest.put(moved, taken_s + DELAY_S)
            threading.Event().wait(0.005)

    feeder = threading.Thread(target=camera)
    feeder.start()
    onset_s = _shift_onset(latest, 0, _grey(scene))
    feeder.join()
    assert onset_s - began_s == pytest.approx(DELAY_S, abs=0.002)
