from dataclasses import replace

import numpy as np

from ptztrack.track.lifecycle import start_ground_tracks
from ptztrack.track.lost_tracks import kept_lost
from ptztrack.track.tracker import EkfTracker
from ptztrack.types import Detections
from test_track_tracker import CAMERA, POSE, V, feet_px, parameters

LOOKING_AWAY = np.array([60.0, 40.0, 4.0])


def lost_and_found(lost_tracks_kept: int, unseen_steps: int = 0) -> EkfTracker:
    """A track detected twice at (7.5, 6), missed three times where its person was detectable with
    probability 0.9 (deleted at the third), ``unseen_steps`` steps while the camera looks away, then
    detected there again."""
    tracker = EkfTracker(
        CAMERA, 0.2, V, parameters(lost_tracks_kept=lost_tracks_kept), lambda mean, *_: np.full(len(mean), 0.9)
    )
    seen = Detections(feet_px([[7.5, 6.0]]), np.array([np.nan]), np.array([-1]))
    for detections in (seen, seen, Detections.empty(), Detections.empty(), Detections.empty()):
        tracker.predict()
        tracker.update(detections, POSE, None)
    assert len(tracker.tracks) == 0
    for _ in range(unseen_steps):
        tracker.predict()
        tracker.update(Detections.empty(), LOOKING_AWAY, None)
    tracker.predict()
    tracker.update(seen, POSE, None)
    return tracker


def test_a_deleted_track_is_taken_back_by_a_detection_in_its_gate_with_its_id_and_hits():
    kept = lost_and_found(lost_tracks_kept=5)
    assert kept.tracks.ids.tolist() == [0] and kept.tracks.hits.tolist() == [3]
    assert kept.tracks.existence[0] < 0.99 and len(kept.lost) == 0
    forgotten = lost_and_found(lost_tracks_kept=0)
    assert forgotten.tracks.ids.tolist() == [1] and forgotten.tracks.hits.tolist() == [1]


def test_a_lost_track_uncertain_over_the_whole_scene_is_still_taken_back():
    """After a minute unseen the lost track's gate reaches behind the camera (no pixel gate holds there):
    it is matched on the ground."""
    kept = lost_and_found(lost_tracks_kept=5, unseen_steps=300)
    assert kept.tracks.ids.tolist() == [0]


def test_the_lost_tracks_kept_are_the_most_recently_lost_and_localised_within_the_bound():
    def lost(ids, sigma_m):
        return start_ground_tracks(np.zeros((len(ids), 2)), sigma_m**2 * np.eye(2)[None].repeat(len(ids), 0), 0.9, 0)

    older = replace(lost([0, 1], 0.5), ids=np.array([0, 1]))
    newer = replace(lost([2], 0.5), ids=np.array([2]))
    assert kept_lost(older, newer, parameters(lost_tracks_kept=2)).ids.tolist() == [1, 2]
    vague = replace(lost([3], 3.0), ids=np.array([3]))
    assert kept_lost(older, vague, parameters(lost_tracks_kept=5, max_position_sigma_m=2.0)).ids.tolist() == [0, 1]
