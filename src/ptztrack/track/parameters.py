"""The ground-plane tracker's parameters and their defaults, in a module of plain data that the
configuration maps onto (:mod:`ptztrack.config` takes its defaults from here)."""

import math
from dataclasses import dataclass
from typing import Annotated, Literal

from ptztrack.names import MAX_FRAMES, Tunable

_PROBABILITY = {"gt": 0, "lt": 1}
Association = Literal["hungarian", "cjpdaf"]
ExistenceUpdate = Literal["bayes", "fixed"]


@dataclass(frozen=True)
class TrackerParameters:
    """The ground-plane tracker's parameters (see :func:`ptztrack.track.tracker.update_tracks`); each
    field's one-line doc, unit and bounds are its :class:`~ptztrack.names.Tunable`.

    association : 'hungarian' or 'cjpdaf' (:mod:`ptztrack.track.jpdaf`). clutter_density_per_px2: a tracker
    given a learned clutter rate uses that instead; 0 for a detector that reports no false positives.
    existence_update : 'bayes' (see :mod:`ptztrack.track.tracker`) or 'fixed'.
    noise_dof : finite for Student-t noise of scale ``V``, whose gate is wider and whose far detections
    update less (:func:`ptztrack.track.pixel_noise.student_t_noise`).
    birth : 'unassigned' (every detection assigned to no track) or 'outside_gates' (only those in the gate
    of no surviving track, as the CJPDAF does: a detection another track could explain is not taken for a
    new person).
    """

    acceleration_sigma_m_s2: Annotated[
        float,
        Tunable(
            "the constant-velocity model's white acceleration noise per axis",
            "m/s^2",
            gt=0,
            at_most=(100, "metres per second squared"),
        ),
    ] = 1.5
    initial_speed_sigma_m_s: Annotated[
        float,
        Tunable("spread of a new track's velocity per axis", "m/s", gt=0, at_most=(100, "metres per second")),
    ] = 0.9
    gate_probability: Annotated[
        float, Tunable("the chi-square gate (2 degrees of freedom) of the association", **_PROBABILITY)
    ] = 0.99
    existence_at_birth: Annotated[float, Tunable("the existence probability of a new track", **_PROBABILITY)] = 0.5
    existence_when_detected: Annotated[
        float, Tunable("the existence probability of a track just detected", **_PROBABILITY)
    ] = 0.99
    existence_to_delete: Annotated[
        float, Tunable("the existence probability below which a track is deleted", **_PROBABILITY)
    ] = 0.1
    max_position_sigma_m: Annotated[
        float,
        Tunable(
            "a track more uncertain than this is deleted (inf where people never leave)",
            "m",
            gt=0,
            at_most=(10_000, "metres"),
        ),
    ] = 2.0
    confirmation_hits: Annotated[
        int, Tunable("detections a track needs before it is reported", ge=1, at_most=(MAX_FRAMES, "steps"))
    ] = 1
    report_position_sigma_m: Annotated[
        float,
        Tunable("a track more uncertain than this is kept but not reported", "m", gt=0, at_most=(10_000, "metres")),
    ] = 1.0
    association: Annotated[Association, Tunable("the data association")] = "hungarian"
    clutter_density_per_px2: Annotated[
        float,
        Tunable(
            "the CJPDAF's C, and the false detections' density kappa of the existence update",
            "1/px^2",
            ge=0,
            at_most=(1, "detections per pixel"),
        ),
    ] = 0.0
    existence_update: Annotated[ExistenceUpdate, Tunable("how a track's existence is updated")] = "bayes"
    existence_to_report: Annotated[
        float, Tunable("the existence probability from which a track is reported", **_PROBABILITY)
    ] = 0.5
    noise_dof: Annotated[float, Tunable("the feet-pixel noise's degrees of freedom: inf for Gaussian noise", gt=0)] = (
        math.inf
    )
    birth: Annotated[
        Literal["unassigned", "outside_gates"], Tunable("which detections the Hungarian association starts tracks from")
    ] = "unassigned"
