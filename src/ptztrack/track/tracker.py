"""Multi-person tracker: one EKF per person on the ground, association in the image.

Observations are feet pixels taken at a known pose; the observation function
is the ground-to-image homography of that pose, linearised at the predicted
state (the paper's section 3.1). Detections are associated with tracks by
the Hungarian assignment (default) or by the Cheap JPDAF of
:mod:`ptztrack.track.jpdaf` (``Tracker.association``).
"""

from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import linear_sum_assignment
from scipy.stats import chi2

from ptztrack.config import Detector, Tracker
from ptztrack.geometry.ptz import (
    PTZCamera,
    apply_homography,
    feet_jacobian,
    ground_to_image,
    image_to_ground,
    inside_image,
)
from ptztrack.track import jpdaf, kalman


# Feet are found on a pixel grid: the tracker trusts them to half a pixel at
# best, which also keeps the innovation covariance invertible for a
# noiseless simulated detector.
MIN_PIXEL_NOISE_PX = 0.5


def pixel_noise_covariance(detector: Detector) -> np.ndarray:
    """``V`` (2, 2) px^2: the feet-pixel noise the tracker and the policies assume."""
    return max(detector.pixel_noise_px, MIN_PIXEL_NOISE_PX) ** 2 * np.eye(2)


@dataclass(frozen=True)
class Tracks:
    """All live tracks.

    ids : (n,) stable integer ids.
    mean : (n, 4) states [x_m, y_m, vx_m_s, vy_m_s].
    covariance : (n, 4, 4).
    missed_steps : (n,) consecutive steps without an associated detection.
    hits : (n,) steps with an associated detection, the one that started the track included.
    next_id : the id the next new track gets.
    """

    ids: np.ndarray
    mean: np.ndarray
    covariance: np.ndarray
    missed_steps: np.ndarray
    hits: np.ndarray
    next_id: int = 0

    def __len__(self) -> int:
        return len(self.ids)

    def select(self, keep) -> "Tracks":
        return replace(
            self,
            ids=self.ids[keep],
            mean=self.mean[keep],
            covariance=self.covariance[keep],
            missed_steps=self.missed_steps[keep],
            hits=self.hits[keep],
        )

    def confirmed(self, config: Tracker) -> "Tracks":
        """The tracks the tracker reports: those detected at least ``config.confirmation_hits`` times."""
        return self.select(self.hits >= config.confirmation_hits)

    @property
    def position_sigma_m(self) -> np.ndarray:
        """(n,) standard deviation along the most uncertain ground direction."""
        return np.sqrt(np.linalg.eigvalsh(self.covariance[:, :2, :2])[:, -1])


def no_tracks() -> Tracks:
    return Tracks(
        np.zeros(0, dtype=int), np.zeros((0, 4)), np.zeros((0, 4, 4)), np.zeros(0, dtype=int), np.zeros(0, dtype=int)
    )


def observation_matrix(camera: PTZCamera, pose, mean) -> np.ndarray:
    """``C_x(a)``: (n, 2, 4) Jacobian of the feet pixel w.r.t. the state, at the states ``mean``."""
    position_block = feet_jacobian(camera, pose, mean[:, :2])
    return np.concatenate([position_block, np.zeros_like(position_block)], axis=-1)


def predict_tracks(tracks: Tracks, F, U) -> Tracks:
    mean, covariance = kalman.predict(tracks.mean, tracks.covariance, F, U)
    return replace(tracks, mean=mean, covariance=covariance)


def predicted_feet_px(camera: PTZCamera, pose, mean) -> tuple[np.ndarray, np.ndarray]:
    """Where the states ``mean`` (n, 4) put the feet in the image at ``pose``.

    Returns the pixels (n, 2) and whether each point is in front of the camera (n,).
    """
    H = ground_to_image(camera, pose)
    in_front = (mean[:, :2] @ H[2, :2] + H[2, 2]) > 0
    return apply_homography(H, mean[:, :2]), in_front


def gated_innovations(predicted_px, in_front, S, feet_px, gate_probability: float):
    """Innovations of every track w.r.t. every detection, and the chi-square gate.

    predicted_px : (n, 2) and in_front : (n,) from :func:`predicted_feet_px`;
    S : (n, 2, 2) innovation covariances; feet_px : (K, 2) detections.
    Returns the innovations (n, K, 2) ``feet - predicted``, their squared
    Mahalanobis distances (n, K), and which pairs are allowed (n, K): those
    within the chi-square quantile ``gate_probability`` (2 degrees of
    freedom) of tracks in front of the camera.
    """
    residual = feet_px[None, :, :] - predicted_px[:, None, :]
    distance2 = np.einsum("tdi,tij,tdj->td", residual, np.linalg.inv(S), residual)
    allowed = in_front[:, None] & (distance2 <= chi2.ppf(gate_probability, df=2))
    return residual, distance2, allowed


def associate(predicted_px, in_front, S, feet_px, gate_probability: float) -> tuple[np.ndarray, np.ndarray]:
    """Hungarian assignment of detections to predicted tracks on the Mahalanobis distance.

    predicted_px : (n, 2) and in_front : (n,) from :func:`predicted_feet_px`;
    S : (n, 2, 2) innovation covariances; feet_px : (K, 2) detections.
    Pairs whose squared Mahalanobis distance exceeds the chi-square quantile
    ``gate_probability`` (2 degrees of freedom) are not allowed, nor are
    tracks behind the camera. Returns matched (track_index, detection_index) arrays.
    """
    if len(predicted_px) == 0 or len(feet_px) == 0:
        return np.zeros(0, dtype=int), np.zeros(0, dtype=int)
    _, distance2, allowed = gated_innovations(predicted_px, in_front, S, feet_px, gate_probability)
    cost = np.where(allowed, distance2, chi2.ppf(gate_probability, df=2) * 1e3)
    rows, cols = linear_sum_assignment(cost)
    keep = allowed[rows, cols]
    return rows[keep], cols[keep]


def start_tracks(feet_px, camera: PTZCamera, pose, V, config: Tracker, first_id: int) -> Tracks:
    """New tracks at the ground points of detections, with the pixel noise carried to the ground.

    Velocity starts at 0 with spread ``initial_speed_sigma_m_s`` per axis.
    Detections at or above the horizon cannot start a track and are dropped.
    """
    G = image_to_ground(camera, pose)
    # G (u, v, 1) = (x, y, 1) / depth, so its last entry is positive only for
    # pixels whose ray meets the ground in front of the camera.
    homogeneous = feet_px @ G[:, :2].T + G[:, 2]
    ok = homogeneous[:, 2] > 0
    ground_xy = homogeneous[ok, :2] / homogeneous[ok, 2:]
    count = len(ground_xy)
    J_inv = np.linalg.inv(feet_jacobian(camera, pose, ground_xy))
    covariance = np.zeros((count, 4, 4))
    covariance[:, :2, :2] = J_inv @ V @ np.swapaxes(J_inv, -1, -2)
    covariance[:, 2:, 2:] = config.initial_speed_sigma_m_s**2 * np.eye(2)
    return Tracks(
        ids=first_id + np.arange(count),
        mean=np.concatenate([ground_xy, np.zeros((count, 2))], axis=-1),
        covariance=covariance,
        missed_steps=np.zeros(count, dtype=int),
        hits=np.ones(count, dtype=int),
        next_id=first_id + count,
    )


def update_tracks(tracks: Tracks, feet_px, camera: PTZCamera, pose, V, config: Tracker) -> Tracks:
    """Associate, update, start and delete: the tracker's step after prediction.

    feet_px : (K, 2) detections taken at ``pose``. ``config.association``
    chooses the association: 'hungarian' updates a track with at most one
    detection, and a detection assigned to no track starts one; 'cjpdaf'
    updates every track with all detections in its gate (see
    :mod:`ptztrack.track.jpdaf`), a track counts as detected when they
    explain it with probability above ``jpdaf.MIN_DETECTION_PROBABILITY`` (1/2),
    and a detection in the gate of no surviving track starts one (a
    detection shared by tracks is not a new person).

    A step counts as missed for a track not detected only if the track was
    predicted inside the image: a PTZ camera that looks elsewhere has not
    missed anybody. A track is deleted after more than ``max_missed_steps``
    missed steps, or when its position standard deviation exceeds
    ``max_position_sigma_m`` (which is what ends a track the camera no
    longer looks at). A track not yet confirmed (fewer than
    ``confirmation_hits`` hits) is deleted at its first missed step: a
    detector's false positive rarely repeats at the same ground point.
    """
    feet_px = np.asarray(feet_px, dtype=float).reshape(-1, 2)
    predicted_px, in_front = predicted_feet_px(camera, pose, tracks.mean)
    C = observation_matrix(camera, pose, tracks.mean)
    S = kalman.innovation_covariance(tracks.covariance, C, V)
    if config.association == "cjpdaf":
        innovation, distance2, gated = gated_innovations(predicted_px, in_front, S, feet_px, config.gate_probability)
        mean, covariance, detected = jpdaf.cjpdaf_step(
            tracks.mean, tracks.covariance, innovation, distance2, gated, S, C, V, config.clutter_density_per_px2
        )
        track_index = np.flatnonzero(detected)
    else:
        track_index, detection_index = associate(predicted_px, in_front, S, feet_px, config.gate_probability)
        mean, covariance = tracks.mean.copy(), tracks.covariance.copy()
        mean[track_index], covariance[track_index] = kalman.update(
            tracks.mean[track_index],
            tracks.covariance[track_index],
            feet_px[detection_index] - predicted_px[track_index],
            C[track_index],
            V,
        )
    survivors, keep = _after_update(tracks, mean, covariance, track_index, predicted_px, in_front, camera, config)
    if config.association == "cjpdaf":
        unmatched = np.flatnonzero(~gated[keep].any(axis=0))
    else:
        unmatched = np.setdiff1d(np.arange(len(feet_px)), detection_index)
    born = start_tracks(feet_px[unmatched], camera, pose, V, config, tracks.next_id)
    return Tracks(
        ids=np.concatenate([survivors.ids, born.ids]),
        mean=np.concatenate([survivors.mean, born.mean]),
        covariance=np.concatenate([survivors.covariance, born.covariance]),
        missed_steps=np.concatenate([survivors.missed_steps, born.missed_steps]),
        hits=np.concatenate([survivors.hits, born.hits]),
        next_id=born.next_id,
    )


def _after_update(tracks: Tracks, mean, covariance, track_index, predicted_px, in_front, camera: PTZCamera, config: Tracker):
    """The updated tracks' misses, hits and deletions (see :func:`update_tracks`); returns the survivors
    and which of the tracks survived (n,) bool."""
    missed = tracks.missed_steps + (in_front & inside_image(camera, predicted_px))
    missed[track_index] = 0
    hits = tracks.hits.copy()
    hits[track_index] += 1
    updated = replace(tracks, mean=mean, covariance=covariance, missed_steps=missed, hits=hits)
    allowed_missed_steps = np.where(hits >= config.confirmation_hits, config.max_missed_steps, 0)
    keep = (updated.missed_steps <= allowed_missed_steps) & (updated.position_sigma_m <= config.max_position_sigma_m)
    return updated.select(keep), keep


def update_own_tracks(tracks: Tracks, track_ids, feet_px, camera: PTZCamera, pose, V, config: Tracker) -> Tracks:
    """Update each track with its own measurement: no association, no new tracks, no missed steps.

    track_ids : (K,) the track each measurement ``feet_px`` (K, 2) px belongs to (as template
    matching finds them); V : (2, 2) or (K, 2, 2) px^2 their noise. Such measurements neither count
    as hits nor clear missed steps: a template can settle on the background and keep matching it,
    so only the detector confirms a track or keeps it alive. Tracks too uncertain are deleted as in
    :func:`update_tracks`.
    """
    feet_px = np.asarray(feet_px, dtype=float).reshape(-1, 2)
    index_of_id = {track_id: index for index, track_id in enumerate(tracks.ids.tolist())}
    unknown = sorted(set(np.asarray(track_ids).tolist()) - set(index_of_id))
    if unknown:
        raise ValueError(f"measurements of tracks {unknown}, which are not alive")
    track_index = np.array([index_of_id[track_id] for track_id in np.asarray(track_ids).tolist()], dtype=int)
    predicted_px, _ = predicted_feet_px(camera, pose, tracks.mean)
    C = observation_matrix(camera, pose, tracks.mean)
    mean, covariance = tracks.mean.copy(), tracks.covariance.copy()
    mean[track_index], covariance[track_index] = kalman.update(
        tracks.mean[track_index], tracks.covariance[track_index], feet_px - predicted_px[track_index], C[track_index], V
    )
    updated = replace(tracks, mean=mean, covariance=covariance)
    return updated.select(updated.position_sigma_m <= config.max_position_sigma_m)
