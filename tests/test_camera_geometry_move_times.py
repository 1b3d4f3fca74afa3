"""The move times a camera without AbsoluteMove gets from ``camera calibrate --geometry``'s own moves
(:func:`ptztrack.camera.geometry_calibration.timed_moves`)."""

import numpy as np
import pytest

from ptztrack.camera.geometry_calibration import timed_moves
from ptztrack.geometry.self_calibration import HeadFit

HEAD = HeadFit(focal_px=250.0, focal_sd_px=1.0, pan_deg_per_unit=150.0, tilt_deg_per_unit=-50.0, tilt_deg=17.0,
               rms_px=0.3, pairs=200)  # fmt: skip


def test_the_lines_through_the_turns_and_the_zoom_steps_are_the_cameras():
    """Turns of 0.1 and 0.2 units both ways on each axis and together (a pan of 150 deg per unit at 0.2 s
    + 10 ms/deg, a tilt of 50 deg per unit at 0.2 s + 20 ms/deg), and zoom steps of normalised 0.25 up a
    curve whose factor doubles from 1 to 4 then 8 (0.1 s + 0.3 s per unit of zoom), with a step halved
    back: each axis' line exactly, the diagonals (the slower axis' time) left out."""
    turned = []
    for pan, tilt in [(0.1, 0), (-0.1, 0), (0.2, 0), (-0.2, 0), (0, 0.1), (0, -0.2), (0.2, 0.2), (0, 0.2)]:
        seconds = max(0.2 + 0.01 * 150 * abs(pan) if pan else 0, 0.2 + 0.02 * 50 * abs(tilt) if tilt else 0)
        turned.append((np.array([pan, tilt, 0.0]), seconds))
    zoom_normalised, factors = np.array([0.0, 0.5, 1.0]), np.array([1.0, 4.0, 8.0])
    steps = [0.25, 0.25, 0.5, -0.25, 0.25]  # 0 -> 0.25 -> 0.5 -> 1.0, back to 0.75, on to 1.0
    ends = np.cumsum([0.0, *steps])
    zoomed = [
        (
            np.array([0.0, 0.0, step]),
            0.1 + 0.3 * abs(np.interp(b, zoom_normalised, factors) - np.interp(a, zoom_normalised, factors)),
        )
        for step, a, b in zip(steps, ends[:-1], ends[1:], strict=True)
    ]
    times = timed_moves(turned, zoomed, HEAD, zoom_normalised, factors)
    assert times.pan == pytest.approx((0.2, 0.01)) and times.tilt == pytest.approx((0.2, 0.02))
    assert times.zoom == pytest.approx((0.1, 0.3))
