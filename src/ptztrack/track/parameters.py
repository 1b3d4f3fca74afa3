"""The ground-plane tracker's parameters and their defaults, in a module of plain data that the
configuration maps onto (:mod:`ptztrack.config` takes its defaults from here)."""

import math
from dataclasses import dataclass
from typing import Literal


@dataclass(frozen=True)
class TrackerParameters:
    """The ground-plane tracker's parameters (see :func:`ptztrack.track.tracker.update_tracks`).

    acceleration_sigma_m_s2 : the constant-velocity model's white acceleration noise per axis (m/s^2).
    velocity_time_constant_s : how fast a track's velocity is predicted to decay (s); inf: constant velocity
        (:func:`ptztrack.track.kalman.constant_velocity_model`).
    initial_speed_sigma_m_s : spread of a new track's velocity per axis (m/s).
    gate_probability : the chi-square gate (2 degrees of freedom) of the association.
    existence_at_birth, existence_when_detected, existence_to_delete : the existence probability
        of a new track, of a track just detected, and below which a track is deleted.
    max_position_sigma_m : a track more uncertain than this is deleted (inf where people never leave).
    confirmation_hits, report_position_sigma_m : what the tracker reports (see
        :mod:`ptztrack.track.tracker`).
    association : 'hungarian' or 'cjpdaf' (:mod:`ptztrack.track.jpdaf`).
    clutter_density_per_px2 : the CJPDAF's C, and the false detections' density ``kappa`` of the existence
        update (a tracker given a learned clutter rate uses that instead); 0 for a detector that
        reports no false positives.
    existence_update : 'bayes' (see :mod:`ptztrack.track.tracker`) or 'fixed'; existence_to_report :
        the existence from which a track is reported.
    noise_dof : the feet-pixel noise's degrees of freedom: inf for Gaussian noise, finite for Student-t
        noise of scale ``V``, whose gate is wider and whose far detections update less
        (:func:`ptztrack.track.pixel_noise.student_t_noise`).
    birth : which detections the Hungarian association starts tracks from: 'unassigned' (every detection
        assigned to no track) or 'outside_gates' (only those in the gate of no surviving track, as the
        CJPDAF does: a detection another track could explain is not taken for a new person).
    negative_information : a look that misses a track also moves its position out of where the camera
        would have seen it (:mod:`ptztrack.track.negative_information`); keep_within_area : where people
        never leave, every track is truncated to the walkable area after each update (same module).
    association_cost : the Hungarian assignment's cost, 'mahalanobis' or 'likelihood'
        (:func:`ptztrack.track.association.associate`).
    lost_tracks_kept : how many deleted tracks are kept to be taken back by a detection that would start
        a track (:mod:`ptztrack.track.lost_tracks`); 0: none.
    """

    acceleration_sigma_m_s2: float = 1.5
    velocity_time_constant_s: float = math.inf
    initial_speed_sigma_m_s: float = 0.9
    gate_probability: float = 0.99
    existence_at_birth: float = 0.5
    existence_when_detected: float = 0.99
    existence_to_delete: float = 0.1
    max_position_sigma_m: float = 2.0
    confirmation_hits: int = 1
    report_position_sigma_m: float = 1.0
    association: Literal["hungarian", "cjpdaf"] = "hungarian"
    clutter_density_per_px2: float = 0.0
    existence_update: Literal["bayes", "fixed"] = "bayes"
    existence_to_report: float = 0.5
    noise_dof: float = math.inf
    birth: Literal["unassigned", "outside_gates"] = "unassigned"
    negative_information: bool = False
    keep_within_area: bool = True
    association_cost: Literal["mahalanobis", "likelihood"] = "mahalanobis"
    lost_tracks_kept: int = 0
