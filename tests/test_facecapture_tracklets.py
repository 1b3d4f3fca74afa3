"""The tracklet tracker: the MSG from observations alone, gating after blind gaps, and its predictions."""

import numpy as np
import pytest

from ptztrack.facecapture.parameters import TrackletTrackerParameters
from ptztrack.facecapture.tracklets import FaceCapture, Observation, TrackletTracker, UnitSighting

RATE_HZ = 5.0


def tracker(**config):
    return TrackletTracker(40.0, RATE_HZ, (20.0, 20.0), TrackletTrackerParameters(**config))


def walker(blob, start_m, heading, speed_m_s, step, came_from=(), count=1):
    """A unit seen at ``step`` that has walked straight from ``start_m`` since step 0."""
    heading = np.asarray(heading, float) / np.linalg.norm(heading)
    x, y = np.asarray(start_m, float) + heading * speed_m_s * step / RATE_HZ
    return UnitSighting(blob, count, (x, y), (heading[0], heading[1]), came_from)


def test_a_join_and_a_split_become_a_compound_vertex_between_solo_ones():
    t = tracker()
    for step in range(30):
        if step < 10:
            units = [walker(0, (5, 5), (1, 1), 1.0, step), walker(1, (5, 5.2), (1, 1), 1.0, step)]
        elif step < 20:
            units = [walker(2, (5, 5), (1, 1), 1.0, step, came_from=(0, 1) if step == 10 else (), count=2)]
        else:
            came_from = (2,) if step == 20 else ()
            units = [walker(3, (5, 5), (1, 1), 1.0, step, came_from), walker(4, (5, 5), (1, -1), 1.0, step, came_from)]
        t.update(Observation(step, False, tuple(units)))
    graph = t.graph
    (compound,) = [v for v in graph if graph.nodes[v]["count"] == 2]
    assert graph.in_degree(compound) == 2 and graph.out_degree(compound) == 2
    assert graph.nodes[compound]["length"] == 10 and graph.nodes[compound]["blobs"] == {2}
    # Every observed person-step is in exactly one tracklet.
    assert sum(node["count"] * node["length"] for _, node in graph.nodes(data=True)) == 60


def blind_gap(start_m, heading_after_gap, gap_steps=10, speed_m_s=1.5):
    """Walker 0 (blob 0) walks +x from ``start_m``; the camera zooms in on a far walker (blob 1) for ``gap_steps``
    after step 9, and walker 0 walks on along ``heading_after_gap`` from step 10. Returns the tracker and
    walker 0's tracklet before the gap."""
    t = tracker(zoom_steps=gap_steps)
    far = [walker(1, (35, 5), (0, 1), 1.0, step) for step in range(30)]
    for step in range(10):
        t.update(Observation(step, False, (walker(0, start_m, (1, 0), speed_m_s, step), far[step])))
    before = t.vertex_of[0]
    for step in range(10, 10 + gap_steps):
        t.update(Observation(step, True, (far[step],)))
    at_gap_m = walker(0, start_m, (1, 0), speed_m_s, 10).position_m
    step = 10 + gap_steps
    seen_again = walker(2, at_gap_m, heading_after_gap, speed_m_s, step - 10)
    t.update(Observation(step, False, (seen_again, far[step])))
    return t, before


def test_a_walker_seen_again_where_predicted_continues_its_tracklet():
    t, before = blind_gap((10, 10), (1, 0))
    assert t.vertex_of[2] == before
    assert t.graph.nodes[before]["blobs"] == {0, 2} and t.graph.nodes[before]["length"] == 11


def test_the_gate_can_miss_the_truth_a_walker_who_turned_early_starts_afresh():
    t, before = blind_gap((10, 10), (0, 1))  # turned right after the camera zoomed in
    after = t.vertex_of[2]
    assert after != before and t.graph.in_degree(after) == 0, "its own tracklet is not a candidate"
    assert not t.graph.nodes[before]["active"]


def test_a_blind_gap_makes_x_ambiguities_only_between_walkers_who_could_have_swapped():
    t = tracker(zoom_steps=6)
    starts = [(5.0, 5.0), (5.5, 5.0), (30.0, 10.0)]  # two walkers half a metre apart, a third far away

    def seen(step, blobs):
        return tuple(walker(blob, starts[i], (1, 1), 1.0, step) for i, blob in enumerate(blobs) if blob is not None)

    for step in range(10):
        t.update(Observation(step, False, seen(step, [0, 1, 2])))
    lost = [t.vertex_of[0], t.vertex_of[1]]
    for step in range(10, 16):
        t.update(Observation(step, True, seen(step, [None, None, 2])))
    t.update(Observation(16, False, seen(16, [3, 4, 2])))
    for blob in (3, 4):
        assert set(t.graph.pred[t.vertex_of[blob]]) == set(lost), "either lost tracklet could be this one"
    far = t.vertex_of[2]
    assert t.graph.nodes[far]["length"] == 17 and t.graph.in_degree(far) == 0


def test_a_captured_face_labels_the_tracklet_it_was_captured_on():
    t = tracker()
    for step in range(3):
        capture = FaceCapture(0, 7) if step == 2 else None
        t.update(Observation(step, False, (walker(0, (5, 5), (1, 0), 1.0, step),), capture))
    node = t.graph.nodes[t.vertex_of[0]]
    assert node["labeled"] and node["face"] == 7


def two_steps_of(units_at):
    """A tracker that has seen the units of ``units_at(step)`` at steps 0 and 1 (so it knows their speeds)."""
    t = tracker()
    for step in range(2):
        t.update(Observation(step, False, tuple(units_at(step))))
    return t


def test_constant_velocity_predictions_of_position_and_exit():
    t = two_steps_of(lambda step: [walker(0, (10, 20), (1, 0), 1.0, step)])
    np.testing.assert_allclose(t.predicted_position_m(0, 10), [10 + 0.2 + 2.0, 20])
    assert t.steps_to_exit(0) == pytest.approx((40 - 10.2) * RATE_HZ)


@pytest.mark.parametrize(
    "other_start, other_heading, steps, meets",
    [
        ((15.0, 15.0), (0, 1), 40, True),  # both reach (15, 20) after 5 s
        ((30.0, 10.0), (0, 1), 40, False),  # reaches (30, 20) after 10 s, when the first is at (20, 20)
        ((14.0, 20.0), (1, 0), 40, False),  # ahead on the same road at the same speed
        ((14.0, 20.0), (-1, 0), 40, True),  # walking towards it
        ((14.0, 20.0), (-1, 0), 3, False),  # but not within 0.6 s
    ],
)
def test_a_meeting_is_predicted_where_the_extrapolations_come_close(other_start, other_heading, steps, meets):
    t = two_steps_of(
        lambda step: [walker(0, (10, 20), (1, 0), 1.0, step), walker(1, other_start, other_heading, 1.0, step)]
    )
    assert t.meets_within(0, steps) is meets


def test_a_capture_is_expected_of_a_walker_facing_the_camera_and_meeting_nobody():
    # The camera stands at the centre, (20, 20).
    towards = two_steps_of(lambda step: [walker(0, (10, 20), (1, 0), 1.0, step)])
    away = two_steps_of(lambda step: [walker(0, (10, 20), (-1, 0), 1.0, step)])
    meeting = two_steps_of(
        lambda step: [walker(0, (10, 20), (1, 0), 1.0, step), walker(1, (12, 20), (-1, 0), 1.0, step)]
    )
    assert towards.capture_expected(0)
    assert not away.capture_expected(0)
    assert not meeting.capture_expected(0)
