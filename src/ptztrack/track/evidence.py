"""What a tracker step tells the models that learn as the camera runs.

Given the predicted tracks and the :class:`~ptztrack.types.TrackUpdate` a step made of them:
:func:`paired_innovations`, the innovations (k, 2) px and their covariances (k, 2, 2) px^2 of the detections
the step paired with tracks (a feet-pixel bias learns from them, :mod:`ptztrack.track.sensor_bias`);
:func:`tracker_evidence`, the :class:`~ptztrack.types.TrackerEvidence` a detector model learns from (which
tracks were detected, their spread, the false births); :func:`birth_exposure`, the share of the image,
sampled every ``EXPOSURE_GRID_PX`` px, where a detection would have started a track.
"""

import numpy as np

from ptztrack.geometry.ptz import PTZCamera
from ptztrack.track import kalman
from ptztrack.track.association import gated_innovations, student_t_gate
from ptztrack.track.lifecycle import existence_after_miss
from ptztrack.track.observation import gate_in_front, observation_matrix, predicted_feet_px
from ptztrack.track.parameters import TrackerParameters
from ptztrack.types import TrackerEvidence, Tracks, TrackUpdate

# The image's pixels are sampled every 2 px for the share outside the gates: the smallest gate, of the
# half-pixel noise floor at the 0.99 chi-square gate, is 3 px across.
EXPOSURE_GRID_PX = 2


def paired_innovations(tracks: Tracks, update: TrackUpdate, feet_px, camera: PTZCamera, pose, V):
    """The innovations ``z - h(x-)`` (k, 2) px of the detections ``feet_px`` (K, 2) that ``update`` paired
    with the predicted ``tracks`` (new tracks left out), and their covariances ``S`` (k, 2, 2) px^2 under
    the noise ``V`` (2, 2) px^2."""
    index_of_id = {track_id: index for index, track_id in enumerate(tracks.ids.tolist())}
    pairs = [
        (index_of_id[track_id], measurement)
        for track_id, measurement in zip(update.track_ids.tolist(), update.measurement_index.tolist(), strict=True)
        if track_id in index_of_id
    ]
    index, measurement = np.array(pairs, dtype=int).reshape(-1, 2).T
    predicted_px, _ = predicted_feet_px(camera, pose, tracks.mean[index])
    C = observation_matrix(camera, pose, tracks.mean[index])
    feet_px = np.asarray(feet_px, dtype=float).reshape(-1, 2)
    return feet_px[measurement] - predicted_px, kalman.innovation_covariance(tracks.covariance[index], C, V)


def tracker_evidence(
    tracks: Tracks, update: TrackUpdate, feet_px, camera: PTZCamera, pose, detectable, parameters: TrackerParameters
) -> TrackerEvidence:
    """What the step that took the predicted ``tracks`` to ``update`` tells about the detector
    (:class:`~ptztrack.types.TrackerEvidence`); ``detectable`` (n,) as
    :func:`~ptztrack.track.tracker.update_tracks` was given it."""
    detected = np.isin(tracks.ids, update.track_ids)
    feet_px = np.asarray(feet_px, dtype=float).reshape(-1, 2)
    measurement_of = dict(zip(update.track_ids.tolist(), update.measurement_index.tolist(), strict=True))
    index = np.flatnonzero(detected)
    predicted_px, _ = predicted_feet_px(camera, pose, tracks.mean[index])
    C = observation_matrix(camera, pose, tracks.mean[index])
    spread_px2 = np.trace(C @ tracks.covariance[index] @ np.swapaxes(C, -1, -2), axis1=-2, axis2=-1)
    measured_px = feet_px[[measurement_of[track_id] for track_id in tracks.ids[index].tolist()]].reshape(-1, 2)
    excess_px2 = np.sum((measured_px - predicted_px) ** 2, axis=-1) - spread_px2
    missed_away = ~detected & (existence_after_miss(tracks.existence, detectable) < parameters.existence_to_delete)
    return TrackerEvidence(
        pose=np.asarray(pose, dtype=float),
        mean_m=tracks.mean[:, :2],
        position_sigma_m=tracks.position_sigma_m,
        existence=tracks.existence,
        hits=tracks.hits,
        detected=detected,
        excess_px2=excess_px2,
        false_births=int(np.sum(missed_away & (tracks.hits == 1))),
    )


def birth_exposure(
    tracks: Tracks, update: TrackUpdate, camera: PTZCamera, pose, V, parameters: TrackerParameters
) -> float:
    """The share of the image where a detection at ``pose`` would have started a track in the step that took
    the predicted ``tracks`` to ``update`` under the noise ``V`` (2, 2) px^2: 1 for ``birth`` 'unassigned'
    (the CJPDAF's included, though it starts no track in a gate either); for 'outside_gates', the share of
    the image (sampled every :data:`EXPOSURE_GRID_PX` px) in the gate of no surviving track, as
    :func:`~ptztrack.track.tracker.update_tracks` gates its births."""
    if parameters.birth == "unassigned":
        return 1.0
    surviving = np.isin(tracks.ids, update.tracks.ids)
    mean = tracks.mean[surviving]
    covariance = tracks.covariance[surviving]
    predicted_px, _ = predicted_feet_px(camera, pose, mean)
    S = kalman.innovation_covariance(covariance, observation_matrix(camera, pose, mean), V)
    half = EXPOSURE_GRID_PX / 2
    u, v = np.meshgrid(
        np.arange(half, camera.image_width_px, EXPOSURE_GRID_PX),
        np.arange(half, camera.image_height_px, EXPOSURE_GRID_PX),
    )
    gate = student_t_gate(parameters.gate_probability, parameters.noise_dof)
    pairable = gate_in_front(camera, pose, mean, covariance, gate)
    _, _, gated = gated_innovations(predicted_px, pairable, S, np.c_[u.ravel(), v.ravel()], gate)
    return float(1.0 - np.mean(gated.any(axis=0)))
