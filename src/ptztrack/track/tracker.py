"""Multi-person tracker: one EKF per person on the ground, association in the image.

Observations are feet pixels taken at a known pose; the observation function
is the ground-to-image homography of that pose, linearised at the predicted
state (the paper's section 3.1). Detections are associated with tracks by
the Hungarian assignment (default; :mod:`ptztrack.track.association`) or by
the Cheap JPDAF of :mod:`ptztrack.track.jpdaf` (``TrackerParameters.association``).

The observation model is :mod:`ptztrack.track.observation`, the pixel noise :mod:`ptztrack.track.pixel_noise`,
a track's birth and the Bayes update of its existence :mod:`ptztrack.track.lifecycle`, and what a step tells
the learning models :mod:`ptztrack.track.evidence`; this module holds the tracker's steps and the tracker.

Track lifecycle. A PTZ camera looks at a few people at a time; a person it
does not look at is still there, only more uncertain, and the information
gain policies come back to exactly such people. So a track is not deleted
because it is uncertain (except, where people can leave the scene, beyond
``max_position_sigma_m``) but on evidence that its person is not there: each
track carries the probability that its person exists, ``existence``, updated
by Bayes' rule every step, as the integrated PDA and the Bernoulli filter
update it. Not detected, while the detector would have found the person with
probability ``q`` (the detector model's prediction at the pose: the person's
predicted feet and head in the image, recall at their size, and not hidden
by other tracked people), it becomes ``r (1 - q) / (1 - r q)``: a miss where
the detector could not have seen anybody changes nothing, a miss where it
surely would have is strong evidence. Detected with innovation ``nu`` of
covariance ``S``, against false detections of density ``kappa`` per px^2,

    r' = r (1 - q + q g / kappa) / (1 - r q + r q g / kappa),   g = N(nu; 0, S),

the ratio of the detection's likelihood as this person's to its likelihood as
clutter; at most ``existence_when_detected`` (a detection never makes a track
certain: a false positive can repeat). ``existence_update`` 'fixed' sets
it to ``existence_when_detected`` instead and reports every track until it is deleted.
Below ``existence_to_delete`` the track goes. A new track starts at
``existence_at_birth`` (one detection: a new person, a false positive or
somebody already tracked). Every track is kept for the policy and for
re-association; the tracker reports those whose existence is at least
``existence_to_report``, detected at least ``confirmation_hits`` times and
localised to within ``report_position_sigma_m`` (beyond that, a reported
track is more often a false positive and a miss at once than a match).
"""

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from ptztrack.geometry.ptz import PTZCamera, inside_image, pose_noise_px2
from ptztrack.roles import ImageSource
from ptztrack.track import jpdaf, kalman
from ptztrack.track.association import associate, associate_on_ground, gated_innovations, student_t_gate
from ptztrack.track.evidence import birth_exposure, paired_innovations, tracker_evidence
from ptztrack.track.lifecycle import (
    existence_after_detection,
    existence_after_miss,
    start_ground_tracks,
    start_tracks,
)
from ptztrack.track.lost_tracks import kept_lost, revived
from ptztrack.track.negative_information import after_miss, within_area
from ptztrack.track.observation import gate_in_front, ground_points, observation_matrix, predicted_feet_px
from ptztrack.track.parameters import TrackerParameters
from ptztrack.track.pixel_noise import innovation_likelihood, squared_distances, student_t_noise, student_t_weight
from ptztrack.track.sensor_bias import PixelBias
from ptztrack.types import Detections, TrackerEvidence, Tracks, TrackUpdate

# A picture taken at the very moment of the camera's last one repeats it: it weighs (almost) nothing, and
# its noise V / w stays finite.
MIN_LOOK_WEIGHT = 1e-6


DetectionModel = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]
"""``model(mean_m (n, 2), position_cov_m2 (n, 2, 2), pose (3,)) -> (n,)``: the probability that the
detector finds each predicted person at the pose, were the person there."""


def predict_tracks(tracks: Tracks, F, U) -> Tracks:
    mean, covariance = kalman.predict(tracks.mean, tracks.covariance, F, U)
    return replace(tracks, mean=mean, covariance=covariance)


def tracks_ahead(
    tracks: Tracks, dt_s: float, acceleration_sigma_m_s2: float, velocity_time_constant_s: float = math.inf
) -> Tracks:
    """``tracks`` predicted ``dt_s`` seconds on by the walker model whose white acceleration has
    ``acceleration_sigma_m_s2`` (m/s^2) per axis and whose velocity decays with ``velocity_time_constant_s``
    (s; inf: constant velocity; :func:`ptztrack.track.kalman.constant_velocity_model`)."""
    return predict_tracks(
        tracks, *kalman.constant_velocity_model(dt_s, acceleration_sigma_m_s2, velocity_time_constant_s)
    )


def update_tracks(
    tracks: Tracks, feet_px, camera: PTZCamera, pose, V, parameters: TrackerParameters, detectable=None
) -> TrackUpdate:
    """Associate, update, start and delete: the tracker's step after prediction.

    feet_px : (K, 2) detections taken at ``pose``; detectable : (n,) the probability that the
    detector would have found each track's person at ``pose`` (see :data:`DetectionModel`); by
    default 1 for a track predicted in the image and 0 otherwise. ``parameters.association``
    chooses the association: 'hungarian' updates a track with at most one
    detection, and a detection assigned to no track starts one; 'cjpdaf'
    updates every track with all detections in its gate (see
    :mod:`ptztrack.track.jpdaf`), a track counts as detected when they
    explain it with probability above ``jpdaf.MIN_DETECTION_PROBABILITY`` (1/2),
    and a detection in the gate of no surviving track starts one (a
    detection shared by tracks is not a new person).

    Each track's existence follows the module's docstring: not detected where it was detectable,
    it loses existence; a PTZ camera that looks elsewhere has missed nobody. A track is deleted
    below ``existence_to_delete`` or beyond ``max_position_sigma_m``.

    The update's ``track_ids`` and ``measurement_index`` pair each surviving detected track with
    its detection (under the CJPDAF, with the detection the Hungarian assignment would give it;
    a detection shared by tracks detects none of them) and each new track with the detection
    that started it.
    """
    feet_px = np.asarray(feet_px, dtype=float).reshape(-1, 2)
    predicted_px, in_front = predicted_feet_px(camera, pose, tracks.mean)
    C = observation_matrix(camera, pose, tracks.mean)
    S = kalman.innovation_covariance(tracks.covariance, C, V)
    gate = student_t_gate(parameters.gate_probability, parameters.noise_dof)
    pairable = gate_in_front(camera, pose, tracks.mean, tracks.covariance, gate)
    track_index, detection_index = associate(predicted_px, pairable, S, feet_px, gate, parameters.association_cost)
    innovation_px = feet_px[detection_index] - predicted_px[track_index]
    if parameters.association == "cjpdaf" and not np.isinf(parameters.noise_dof):
        raise ValueError("the CJPDAF assumes Gaussian pixel noise (noise_dof inf)")
    if parameters.association == "cjpdaf":
        innovation, distance2, gated = gated_innovations(
            predicted_px, pairable, S, feet_px, parameters.gate_probability
        )
        mean, covariance, detected = jpdaf.cjpdaf_step(
            tracks.mean, tracks.covariance, innovation, distance2, gated, S, C, V, parameters.clutter_density_per_px2
        )
        paired = detected[track_index]
        track_index, detection_index, updated_index = (
            track_index[paired],
            detection_index[paired],
            np.flatnonzero(detected),
        )
    else:
        mean, covariance = tracks.mean.copy(), tracks.covariance.copy()
        mean[track_index], covariance[track_index] = kalman.update(
            tracks.mean[track_index],
            tracks.covariance[track_index],
            innovation_px,
            C[track_index],
            student_t_noise(V, innovation_px, S[track_index], parameters.noise_dof),
        )
        updated_index = track_index
    if detectable is None:
        detectable = (in_front & inside_image(camera, predicted_px)).astype(float)
    if parameters.negative_information:
        detectable = np.asarray(detectable, dtype=float)
        missed = np.setdiff1d(np.flatnonzero(detectable > 0), updated_index)
        moved = after_miss(camera, pose, mean[missed], covariance[missed], detectable[missed])
        mean[missed], covariance[missed] = moved
    likelihood_px2 = np.zeros(len(tracks))
    likelihood_px2[track_index] = innovation_likelihood(innovation_px, S[track_index], parameters.noise_dof)
    survivors, keep = _after_update(tracks, mean, covariance, updated_index, detectable, parameters, likelihood_px2)
    if parameters.association == "cjpdaf":
        unmatched = np.flatnonzero(~gated[keep].any(axis=0))
    else:
        unmatched = np.setdiff1d(np.arange(len(feet_px)), detection_index)
        if parameters.birth == "outside_gates":
            _, _, gated = gated_innovations(predicted_px, pairable, S, feet_px, gate)
            unmatched = np.intersect1d(unmatched, np.flatnonzero(~gated[keep].any(axis=0)))
    _, on_ground = ground_points(feet_px[unmatched], camera, pose)
    starting = unmatched[on_ground]
    born = start_tracks(
        feet_px[starting],
        camera,
        pose,
        V,
        parameters.initial_speed_sigma_m_s,
        tracks.next_id,
        parameters.existence_at_birth,
    )
    return _with_births(tracks, survivors, keep, born, track_index, detection_index, starting)


def update_tracks_on_ground(
    tracks: Tracks, position_m, covariance_m2, parameters: TrackerParameters, detectable
) -> TrackUpdate:
    """Associate, update, start and delete with measurements of ground positions (a multi-camera
    occupancy map's modes, :mod:`ptztrack.occupancy.lpom`), the tracker's step after prediction.

    position_m : (K, 2) measured positions; covariance_m2 : (K, 2, 2) their noise ``R``. The
    observation is linear, ``z = [I 0] x + r``; association is the Hungarian assignment on
    ``association_cost`` with innovation covariance ``P_xy + R_k`` per pair, gated as in
    :func:`update_tracks` (:func:`~ptztrack.track.association.associate_on_ground`), and an unassigned
    measurement starts a track with ``R_k`` as its position covariance and ``existence_at_birth``. Fixed
    cameras watch every track: an undetected track loses existence as in :func:`update_tracks`, with
    ``detectable`` (scalar or (n,)) the probability
    that the map finds each track's person were it there. Only the Hungarian association is available.
    """
    if parameters.association != "hungarian":
        raise ValueError(
            f"ground measurements are associated by the Hungarian assignment, not {parameters.association!r}"
        )
    position_m = np.asarray(position_m, dtype=float).reshape(-1, 2)
    covariance_m2 = np.asarray(covariance_m2, dtype=float).reshape(-1, 2, 2)
    track_index, measurement_index, residual = associate_on_ground(
        tracks.mean,
        tracks.covariance,
        position_m,
        covariance_m2,
        parameters.gate_probability,
        parameters.association_cost,
    )
    mean, covariance = tracks.mean.copy(), tracks.covariance.copy()
    mean[track_index], covariance[track_index] = kalman.update_position(
        tracks.mean[track_index],
        tracks.covariance[track_index],
        residual[track_index, measurement_index],
        covariance_m2[measurement_index],
    )
    survivors, keep = _after_update(
        tracks, mean, covariance, track_index, np.broadcast_to(np.asarray(detectable, float), len(tracks)), parameters
    )
    starting = np.setdiff1d(np.arange(len(position_m)), measurement_index)
    born = start_ground_tracks(
        position_m[starting],
        covariance_m2[starting],
        parameters.initial_speed_sigma_m_s,
        tracks.next_id,
        parameters.existence_at_birth,
    )
    return _with_births(tracks, survivors, keep, born, track_index, measurement_index, starting)


def _with_births(tracks: Tracks, survivors: Tracks, keep, born: Tracks, track_index, measurement_index, starting):
    """The update's result: the surviving tracks and the new ones, each paired with its measurement."""
    alive = keep[track_index]
    return TrackUpdate(
        tracks=Tracks(
            ids=np.concatenate([survivors.ids, born.ids]),
            mean=np.concatenate([survivors.mean, born.mean]),
            covariance=np.concatenate([survivors.covariance, born.covariance]),
            existence=np.concatenate([survivors.existence, born.existence]),
            hits=np.concatenate([survivors.hits, born.hits]),
            next_id=born.next_id,
        ),
        track_ids=np.concatenate([tracks.ids[track_index[alive]], born.ids]),
        measurement_index=np.concatenate([measurement_index[alive], starting]),
    )


def _after_update(
    tracks: Tracks, mean, covariance, track_index, detectable, parameters: TrackerParameters, likelihood=None
):
    """The updated tracks' existence, hits and deletions (see :func:`update_tracks`); returns the
    survivors and which of the tracks survived (n,) bool. likelihood : (n,) each detected track's
    detection likelihood ``g`` (None: the fixed update)."""
    existence = existence_after_miss(tracks.existence, detectable)
    if parameters.existence_update == "fixed" or likelihood is None:
        existence[track_index] = parameters.existence_when_detected
    else:
        existence[track_index] = existence_after_detection(
            tracks.existence[track_index],
            detectable[track_index],
            likelihood[track_index],
            parameters.clutter_density_per_px2,
            parameters.existence_when_detected,
        )
    hits = tracks.hits.copy()
    hits[track_index] += 1
    updated = replace(tracks, mean=mean, covariance=covariance, existence=existence, hits=hits)
    keep = (existence >= parameters.existence_to_delete) & (updated.position_sigma_m <= parameters.max_position_sigma_m)
    return updated.select(keep), keep


def update_own_tracks(
    tracks: Tracks, track_ids, feet_px, camera: PTZCamera, pose, V, max_position_sigma_m: float
) -> Tracks:
    """Update each track with its own measurement: no association, no new tracks, no change of existence.

    track_ids : (K,) the track each measurement ``feet_px`` (K, 2) px belongs to (as template
    matching finds them); V : (2, 2) or (K, 2, 2) px^2 their noise. Such measurements neither count
    as hits nor raise existence: a template can settle on the background and keep matching it,
    so only the detector confirms a track or keeps it alive. Tracks more uncertain than
    ``max_position_sigma_m`` are deleted as in :func:`update_tracks`.
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
    return updated.select(updated.position_sigma_m <= max_position_sigma_m)


@dataclass
class EkfTracker:
    """The ground-plane tracker as a role of the loop (:class:`ptztrack.roles.Tracker`).

    camera : the camera model; step_s : the motion model's step (s) when :meth:`predict` is given none;
    V : (2, 2) px^2 the detections' noise; parameters : see :class:`TrackerParameters` (its
    ``acceleration_sigma_m_s2`` that of :func:`ptztrack.track.kalman.constant_velocity_model`);
    detection_model : what the detector would find (see :data:`DetectionModel`);
    learner : given every step's :class:`~ptztrack.types.TrackerEvidence` (a detector model that
        learns from it, say; None: nobody).
    clutter_per_view : the false detections expected in a view, read every step (a learned model's
        estimate); its density over the image replaces ``parameters.clutter_density_per_px2``.
    bias : the camera's feet-pixel bias, estimated from the innovations as the run goes and taken off its
        detections (:mod:`ptztrack.track.sensor_bias`; None: none).
    area_polygon_m : (K, 2) m, the walkable area every track is truncated to after each update, where
        people never leave and ``parameters.keep_within_area`` (:mod:`ptztrack.track.negative_information`;
        None: none).
    lost : the deleted tracks kept to be taken back (:mod:`ptztrack.track.lost_tracks`), predicted with
        the live ones.

    A picture's weight. The detector model, the pixel noise ``V`` and the existence update are those of
    one look per ``step_s``; pictures closer together than that (a live stream, which delivers several
    pictures of what a step shows) do not miss or misplace a person independently. A picture taken
    ``dt`` after this camera's last one counts as ``w = min(1, dt / step_s)`` of a look, a tempered
    likelihood: the noise is ``V / w`` and a miss multiplies the existence odds by ``(1 - q)^w``
    (the detection probability used is ``1 - (1 - q)^w``), so that ``1 / w`` pictures of one step weigh
    as one. One picture per step, as every simulated run takes, has ``w = 1``.
    """

    camera: PTZCamera
    step_s: float
    V: np.ndarray
    parameters: TrackerParameters
    detection_model: DetectionModel
    tracks: Tracks = field(default_factory=Tracks.empty)
    learner: Callable[[TrackerEvidence], None] | None = None
    clutter_per_view: Callable[[], float] | None = None
    bias: PixelBias | None = None
    area_polygon_m: np.ndarray | None = None
    lost: Tracks = field(default_factory=Tracks.empty)
    unseen_s: float = field(default=math.inf, init=False, repr=False)

    def predict(self, dt_s: float | None = None) -> Tracks:
        dt_s = self.step_s if dt_s is None else dt_s
        self.elapse(dt_s)
        motion = (self.parameters.acceleration_sigma_m_s2, self.parameters.velocity_time_constant_s)
        self.tracks = tracks_ahead(self.tracks, dt_s, *motion)
        self.lost = tracks_ahead(self.lost, dt_s, *motion)
        return self.tracks

    def elapse(self, dt_s: float) -> None:
        """Let ``dt_s`` seconds pass on this camera's clock (a network's belief is predicted once for
        every camera)."""
        self.unseen_s += dt_s

    def look_weight(self) -> float:
        """The weight ``w`` of a picture taken now (see the class's docstring), in (0, 1]."""
        return float(np.clip(self.unseen_s / self.step_s, MIN_LOOK_WEIGHT, 1.0))

    def wants_detections(self, step: int) -> bool:
        return True

    def update(self, detections: Detections | None, pose, view: ImageSource, pose_sd=None) -> TrackUpdate:
        """The step's update (:func:`update_tracks`). pose_sd : (3,) the standard deviations of ``pose``
        (deg, deg, zoom factor) where it is known only so well (a camera caught moving); the pixel noise
        they add (:func:`~ptztrack.geometry.ptz.pose_noise_px2`) widens ``V``, and is taken out of the
        innovations the learner is given."""
        detections = Detections.empty() if detections is None else detections
        tracks, pose = self.tracks, np.asarray(pose, dtype=float)
        pose_noise = np.zeros((2, 2)) if pose_sd is None else pose_noise_px2(self.camera, pose, pose_sd)
        detectable = self.detection_model(tracks.mean[:, :2], tracks.covariance[:, :2, :2], pose)
        parameters = self.parameters
        if self.clutter_per_view is not None:
            image_area_px2 = self.camera.image_width_px * self.camera.image_height_px
            parameters = replace(parameters, clutter_density_per_px2=self.clutter_per_view() / image_area_px2)
        V = self.V + pose_noise
        look = self.look_weight()
        self.unseen_s = 0.0
        looked = detectable
        if look < 1.0:
            V, looked = V / look, 1.0 - (1.0 - np.asarray(detectable, dtype=float)) ** look
        bias = self.bias
        if bias is not None:
            bias_px = bias.estimate()
            detections = replace(detections, feet_px=detections.feet_px - bias_px)
        update = update_tracks(tracks, detections.feet_px, self.camera, pose, V, parameters, looked)
        update, lost = revived(update, tracks.next_id, self.lost, parameters)
        lost = kept_lost(lost, tracks.select(~np.isin(tracks.ids, update.tracks.ids)), parameters)
        if self.area_polygon_m is not None:
            update = replace(update, tracks=self._within_area(update.tracks))
            lost = self._within_area(lost)
        self.tracks, self.lost = update.tracks, lost
        if bias is not None:
            innovation_px, S = paired_innovations(tracks, update, detections.feet_px, self.camera, pose, V)
            weight = student_t_weight(squared_distances(innovation_px, S), parameters.noise_dof)
            bias.observe(innovation_px + bias_px, S, weight)
        if self.learner is not None:
            evidence = tracker_evidence(tracks, update, detections.feet_px, self.camera, pose, detectable, parameters)
            exposure = birth_exposure(tracks, update, self.camera, pose, V, parameters)
            self.learner(replace(evidence, excess_px2=evidence.excess_px2 - np.trace(pose_noise), exposure=exposure))
        return update

    def _within_area(self, tracks: Tracks) -> Tracks:
        mean, covariance = within_area(tracks.mean, tracks.covariance, self.area_polygon_m)
        return replace(tracks, mean=mean, covariance=covariance)

    def reported(self) -> Tracks:
        """The tracks whose existence is ``existence_to_report`` or more (with the 'bayes' update), detected
        ``confirmation_hits`` times or more and localised within ``report_position_sigma_m``."""
        confirmed = self.tracks.confirmed(self.parameters.confirmation_hits)
        sure = confirmed.position_sigma_m <= self.parameters.report_position_sigma_m
        if self.parameters.existence_update == "bayes":
            sure &= confirmed.existence >= self.parameters.existence_to_report
        return confirmed.select(sure)
