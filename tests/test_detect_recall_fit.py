import numpy as np
import pytest

from ptztrack.detect.recall_fit import MIN_R0_PX, fit_recall
from ptztrack.detect.simulated import realistic_recall


@pytest.mark.parametrize("kd, r0", [(0.0098, 21.29), (0.3, 12.0)])
def test_the_fit_recovers_the_curve_that_drew_the_trials(kd, r0):
    rng = np.random.default_rng(1)
    heights = rng.uniform(5, 200, size=20000)
    detected = rng.random(heights.size) < realistic_recall(heights, kd, r0)
    fitted_kd, fitted_r0 = fit_recall(heights, detected)
    assert fitted_kd == pytest.approx(kd, rel=0.1)
    assert fitted_r0 == pytest.approx(r0, abs=1.0)


def test_the_curve_is_zero_below_r0_and_rises_towards_one():
    heights = np.array([5.0, 21.29, 50.0, 500.0])
    values = realistic_recall(heights, 0.0098, 21.29)
    assert values[0] == 0 and values[1] == 0
    assert values[2] == pytest.approx(1 - np.exp(-0.0098 * (50 - 21.29)))
    assert values[3] > 0.98


def test_r0_stays_at_a_pixel_or_more_when_even_the_smallest_people_are_found():
    # A detector that finds 80 % of people at every height: the best curve would put r0 below zero,
    # which would make the walkable area (where people look taller than r0) unbounded.
    rng = np.random.default_rng(3)
    height_px = rng.uniform(2.0, 60.0, 2000)
    kd, r0 = fit_recall(height_px, rng.random(2000) < 0.8)
    assert r0 >= MIN_R0_PX and kd > 0
