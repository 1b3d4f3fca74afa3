"""The follow camera's figures and the one-pass (OTB) scores, on cases computed by hand."""

import numpy as np
import pytest

from ptztrack.follow.evaluation import follow_metrics, one_pass_scores
from ptztrack.scene.pets import box_iou


def test_follow_metrics_of_a_short_run_computed_by_hand():
    centres = np.array([[320.0, 240.0], [320.0, 240.0], [np.nan, np.nan], [700.0, 240.0], [320.0, 540.0]])
    heights = np.array([100.0, 120.0, np.nan, 100.0, 80.0])
    commanded = np.array([[0.0, 10.0, 1.0], [1.0, 10.0, 1.0], [3.0, 10.5, 1.0], [5.0, 10.0, 1.0], [7.0, 10.0, 1.0]])
    lost = np.array([False, True, True, False, True])
    metrics = follow_metrics(centres, heights, commanded, lost, (640, 480), np.array([320.0, 240.0]))
    assert metrics["annotated_steps"] == 4
    assert metrics["in_view_fraction"] == pytest.approx(2 / 4)  # (700, 240) and (320, 540) are outside
    assert metrics["target_point_error"] == pytest.approx((0 + 0 + 380 / 800 + 300 / 800) / 4)
    assert (metrics["losses"], metrics["recoveries"], metrics["lost_steps"]) == (2, 1, 3)
    # Second differences: pan 1, 0, 0 and tilt 0.5, -1, 0.5 -> mean |.| over both = 3 / 6.
    assert metrics["jitter_deg"] == pytest.approx(0.5)
    assert metrics["height_sd_ratio"] == pytest.approx(np.std([100, 120, 100, 80]) / 100)


def test_box_overlap_computed_by_hand():
    assert box_iou([0, 0, 10, 10], [5, 0, 10, 10]) == pytest.approx(50 / 150)
    assert box_iou([0, 0, 10, 10], [20, 20, 5, 5]) == 0.0
    assert box_iou([0, 0, 10, 10], [0, 0, 10, 10]) == 1.0
    np.testing.assert_allclose(box_iou(np.zeros((3, 4)) + [0, 0, 2, 2], [1, 1, 2, 2]), 1 / 7)


def test_one_pass_scores_of_perfect_shifted_and_absent_boxes():
    truth = np.array([[100.0, 100.0, 20.0, 40.0]] * 4)
    perfect = one_pass_scores(truth, truth)
    # Overlap 1 passes every threshold but the last (overlap > 1): 20 of 21.
    assert perfect["success_auc"] == pytest.approx(20 / 21) and perfect["precision_20px"] == 1.0
    shifted = one_pass_scores(truth + [10.0, 0.0, 0.0, 0.0], truth)  # overlap 1/3, centre 10 px away
    assert shifted["success_auc"] == pytest.approx(7 / 21)  # thresholds 0, 0.05, ..., 0.30
    assert shifted["precision_20px"] == 1.0
    far = one_pass_scores(truth + [100.0, 0.0, 0.0, 0.0], truth)
    assert far["success_auc"] == 0.0 and far["precision_20px"] == 0.0
