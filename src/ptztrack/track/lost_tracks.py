"""Tracks the tracker gave up on, kept to take back the person they followed.

A track is deleted when its existence falls below ``existence_to_delete``: looked for and not found, or
hidden behind somebody the detector found. Its person is often still in the scene, and when seen again
would start a new track, a new identity. A deleted track is therefore kept as *lost*, predicted on (and
so ever more uncertain), for as long as it is localised within ``max_position_sigma_m`` (people who
can leave are forgotten once they could have left) and among the ``lost_tracks_kept`` most recently
lost. A detection that would start a track is first associated with the lost tracks (the Hungarian
assignment on the pair's negative log-likelihood, in the same chi-square gate as every association, on
the ground), and one that falls in a lost track's gate takes that track back: its id, its hits, its state
updated by the detection's ground point (the Kalman update of :mod:`ptztrack.track.kalman`), at the
existence of a new track. A second
stage of association, as trackers that keep a lost tracks' buffer (DeepSORT's and ByteTrack's) have it,
here on the ground belief's own likelihood.
"""

from dataclasses import replace

import numpy as np

from ptztrack.track import kalman
from ptztrack.track.association import associate_on_ground
from ptztrack.track.parameters import TrackerParameters
from ptztrack.types import Tracks, TrackUpdate


def joined(first: Tracks, second: Tracks) -> Tracks:
    """The tracks of ``first`` then those of ``second``, with ``first``'s next id."""
    return replace(
        first,
        ids=np.concatenate([first.ids, second.ids]),
        mean=np.concatenate([first.mean, second.mean]),
        covariance=np.concatenate([first.covariance, second.covariance]),
        existence=np.concatenate([first.existence, second.existence]),
        hits=np.concatenate([first.hits, second.hits]),
    )


def kept_lost(lost: Tracks, deleted: Tracks, parameters: TrackerParameters) -> Tracks:
    """The lost tracks after a step that deleted ``deleted`` (their predicted states): the
    ``lost_tracks_kept`` most recently lost, those localised within ``max_position_sigma_m``."""
    lost = joined(lost, deleted)
    lost = lost.select(lost.position_sigma_m <= parameters.max_position_sigma_m)
    return lost.select(np.arange(len(lost)) >= len(lost) - parameters.lost_tracks_kept)


def revived(
    update: TrackUpdate, first_new_id: int, lost: Tracks, parameters: TrackerParameters
) -> tuple[TrackUpdate, Tracks]:
    """The update with every new track (id ``first_new_id`` or more) whose position falls in a lost track's
    gate replaced by that lost track, updated by it (the module's docstring); and the lost tracks left.

    A new track's position and its covariance are its detection's ground point and the detection's noise
    carried to the ground (:func:`~ptztrack.track.lifecycle.start_tracks`), so it is matched as a ground
    measurement (:func:`~ptztrack.track.association.associate_on_ground`): a lost track may be uncertain
    over the whole scene, and its gate behind the camera, where a pixel's linearisation would not hold.
    """
    new_rows = np.flatnonzero(update.tracks.ids >= first_new_id)
    if len(new_rows) == 0 or len(lost) == 0:
        return update, lost
    tracks = update.tracks
    position_m, covariance_m2 = tracks.mean[new_rows, :2], tracks.covariance[new_rows, :2, :2]
    lost_index, new_index, residual = associate_on_ground(
        lost.mean, lost.covariance, position_m, covariance_m2, parameters.gate_probability, "likelihood"
    )
    if len(lost_index) == 0:
        return update, lost
    rows = new_rows[new_index]
    mean, covariance = kalman.update_position(
        lost.mean[lost_index], lost.covariance[lost_index], residual[lost_index, new_index], covariance_m2[new_index]
    )
    ids, hits = tracks.ids.copy(), tracks.hits.copy()
    revived_id = dict(zip(ids[rows].tolist(), lost.ids[lost_index].tolist(), strict=True))
    ids[rows], hits[rows] = lost.ids[lost_index], lost.hits[lost_index] + 1
    tracks_mean, tracks_covariance = tracks.mean.copy(), tracks.covariance.copy()
    tracks_mean[rows], tracks_covariance[rows] = mean, covariance
    tracks = replace(tracks, ids=ids, hits=hits, mean=tracks_mean, covariance=tracks_covariance)
    track_ids = np.array([revived_id.get(track_id, track_id) for track_id in update.track_ids.tolist()], dtype=int)
    left = lost.select(~np.isin(np.arange(len(lost)), lost_index))
    return replace(update, tracks=tracks, track_ids=track_ids), left
