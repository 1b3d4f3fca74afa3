import numpy as np
import pytest

from ptztrack.evaluate.metrics import clear_metrics, truth_within
from ptztrack.types import GroundTruth

NAN = np.nan


def test_hand_computed_example():
    """Two people, three frames.

    frame 0: A(0,0)-track 1 at 0.1 m, B(5,0)-track 2 at 0.2 m: two matches.
    frame 1: A-track 1 at 0.3 m; track 2 is 2 m from B, beyond the 1 m gate: a miss and a false positive.
    frame 2: B has left; A is now tracked by track 3 at 0.4 m: an identity switch.
    objects 5, matches 4, misses 1, false positives 1, switches 1:
    MOTA = 1 - 3/5 = 0.4; MOTP = (0.1 + 0.2 + 0.3 + 0.4) / 4 = 0.25 m.
    IDF1: best identity pairing A-1 (2 frames), B-2 (1 frame within the gate):
    IDTP = 3, 5 truth and 5 track positions, IDF1 = 2*3 / (5 + 5) = 0.6.
    """
    truth = np.array([[[0, 0], [5, 0]], [[0, 0], [5, 0]], [[0, 0], [NAN, NAN]]], dtype=float)
    ids = [np.array([1, 2]), np.array([1, 2]), np.array([3])]
    positions = [np.array([[0.1, 0], [5, 0.2]]), np.array([[0, 0.3], [7, 0]]), np.array([[0, 0.4]])]
    metrics = clear_metrics(truth, ids, positions)
    assert metrics["objects"] == 5
    assert metrics["matches"] == 4
    assert metrics["misses"] == 1
    assert metrics["false_positives"] == 1
    assert metrics["switches"] == 1
    assert metrics["mota"] == pytest.approx(0.4)
    assert metrics["motp_m"] == pytest.approx(0.25)
    assert metrics["idf1"] == pytest.approx(0.6)


def test_gate_is_one_metre_and_configurable():
    truth = np.array([[[0.0, 0.0]]])
    far = [np.array([[0.0, 1.2]])]
    assert clear_metrics(truth, [np.array([0])], far)["matches"] == 0
    assert clear_metrics(truth, [np.array([0])], far, gate_m=1.5)["matches"] == 1


def test_frames_without_tracks_count_as_misses():
    truth = np.zeros((4, 2, 2))
    truth[:, 1] = [3.0, 0.0]
    metrics = clear_metrics(truth, [np.zeros(0, int)] * 4, [np.zeros((0, 2))] * 4)
    assert metrics["misses"] == 8
    assert metrics["mota"] == pytest.approx(0.0)


def test_truth_within_a_polygon_keeps_people_only_at_the_steps_their_feet_are_inside():
    positions_m = np.array(
        [
            [[1.0, 1.0], [5.0, 1.0]],
            [[1.5, 1.0], [np.nan, np.nan]],
            [[2.5, 1.0], [1.0, 1.9]],
        ]
    )
    truth = GroundTruth(positions_m, np.array([1.7, 1.8]), np.array([0.5, 0.5]), 5.0)
    cut = truth_within(truth, [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]])
    expected = positions_m.copy()
    expected[0, 1] = expected[2, 0] = np.nan
    np.testing.assert_array_equal(cut.positions_m, expected)
    np.testing.assert_array_equal(cut.heights_m, truth.heights_m)
    np.testing.assert_array_equal(truth.positions_m[0, 1], [5.0, 1.0])
