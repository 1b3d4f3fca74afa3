"""The plain data that passes between the roles of the loop: poses, detections, truth, tracks, decisions.

Nothing here imports the rest of ptztrack, so an implementation of a role
(:mod:`ptztrack.roles`) written outside the package needs only this module
and NumPy. A pose is a ``(3,)`` array ``(pan_deg, tilt_deg, zoom)``; pixel
coordinates have their origin at the image's top-left corner, the centre of
pixel ``(i, j)`` at ``(i + 0.5, j + 0.5)``; ground coordinates are metres on
the plane z = 0.
"""

from dataclasses import dataclass, field, replace

import numpy as np


@dataclass(frozen=True)
class Detections:
    """What a detector reports for one image.

    feet_px : (K, 2) feet points in pixels, with noise.
    height_px : (K,) the person's height in pixels, NaN where unknown (a false positive).
    person_index : (K,) index of the true person where a simulation knows it, else -1.
    score : (K,) the detector's confidence, NaN where it gives none.
    """

    feet_px: np.ndarray
    height_px: np.ndarray
    person_index: np.ndarray
    score: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self):
        if len(self.score) == 0 and len(self.feet_px) > 0:
            object.__setattr__(self, "score", np.full(len(self.feet_px), np.nan))
        elif len(self.score) != len(self.feet_px):
            raise ValueError(f"{len(self.score)} scores for {len(self.feet_px)} detections")

    def __len__(self) -> int:
        return len(self.feet_px)

    @staticmethod
    def empty() -> "Detections":
        return Detections(np.zeros((0, 2)), np.zeros(0), np.zeros(0, dtype=int))


@dataclass(frozen=True)
class TrackerEvidence:
    """What one tracker step tells about its detector, without any annotation.

    pose : (3,) the pose the detections were mapped with.
    mean_m : (n, 2) the tracks' predicted ground positions before the update; position_sigma_m : (n,) their
        standard deviations along the most uncertain direction (:attr:`Tracks.position_sigma_m`).
    existence : (n,) their existence probabilities before the update; hits : (n,) their detections so far.
    detected : (n,) bool, whether a detection was assigned to each.
    excess_px2 : (m,) for each detected track, ``|nu|^2 - tr(C P C^T)``: the squared innovation less the
        share the prediction's own spread explains (its mean is ``tr V``, twice the pixel noise's variance).
    false_births : tracks started by one detection and deleted, unconfirmed, because the detector would
        have found their person again and did not (the evidence of the detector's false positives).
    exposure : the share of the view where a false detection would have started a track (1: anywhere; less
        where the tracker starts none in a surviving track's gate); the view counts as this much of one in
        the false positives' posterior.
    """

    pose: np.ndarray
    mean_m: np.ndarray
    position_sigma_m: np.ndarray
    existence: np.ndarray
    hits: np.ndarray
    detected: np.ndarray
    excess_px2: np.ndarray
    false_births: int
    exposure: float = 1.0


@dataclass(frozen=True)
class PeopleInView:
    """Who a simulated camera sees at a pose: the truth a simulated detector draws its detections from.

    person_index : (N,) the true person of each row.
    feet_px : (N, 2) the feet in the image, without noise.
    height_px : (N,) the person's height in the image.
    in_view : (N,) bool, the person is present and wholly in the image (head and feet, or the whole box).
    hidden : (N,) the fraction of the person hidden by people nearer the camera, in [0, 1].
    """

    person_index: np.ndarray
    feet_px: np.ndarray
    height_px: np.ndarray
    in_view: np.ndarray
    hidden: np.ndarray


@dataclass(frozen=True)
class GroundTruth:
    """Where everybody is, frame by frame.

    positions_m : (T, N, 2) feet positions in metres, NaN while absent.
    heights_m, widths_m : (N,) body size in metres (NaN where not known).
    frame_rate_hz : frames per second.
    """

    positions_m: np.ndarray
    heights_m: np.ndarray
    widths_m: np.ndarray
    frame_rate_hz: float

    @property
    def present(self) -> np.ndarray:
        """(T, N) bool: the person is in the scene at that frame."""
        return ~np.isnan(self.positions_m[..., 0])


@dataclass(frozen=True)
class Tracks:
    """All live tracks of a ground-plane tracker.

    ids : (n,) stable integer ids.
    mean : (n, 4) states [x_m, y_m, vx_m_s, vy_m_s].
    covariance : (n, 4, 4).
    existence : (n,) probability that the track's person exists (is there to be seen).
    hits : (n,) steps with an associated detection, the one that started the track included.
    next_id : the id the next new track gets.
    """

    ids: np.ndarray
    mean: np.ndarray
    covariance: np.ndarray
    existence: np.ndarray
    hits: np.ndarray
    next_id: int = 0

    def __len__(self) -> int:
        return len(self.ids)

    @staticmethod
    def empty() -> "Tracks":
        return Tracks(
            np.zeros(0, dtype=int),
            np.zeros((0, 4)),
            np.zeros((0, 4, 4)),
            np.zeros(0),
            np.zeros(0, dtype=int),
        )

    def select(self, keep) -> "Tracks":
        return replace(
            self,
            ids=self.ids[keep],
            mean=self.mean[keep],
            covariance=self.covariance[keep],
            existence=self.existence[keep],
            hits=self.hits[keep],
        )

    def confirmed(self, min_hits: int) -> "Tracks":
        """The tracks detected at least ``min_hits`` times."""
        return self.select(self.hits >= min_hits)

    @property
    def position_sigma_m(self) -> np.ndarray:
        """(n,) standard deviation along the most uncertain ground direction."""
        return np.sqrt(np.linalg.eigvalsh(self.covariance[:, :2, :2])[:, -1])


@dataclass(frozen=True)
class TrackUpdate:
    """What a tracker's update did with a step's measurements.

    tracks : every live track after the update (reported or not).
    track_ids, measurement_index : (M,) each track that a measurement updated or started, and which
        measurement (a row of the detections given, or of ``measurements``).
    measurements : what the tracker measured itself instead of the detections it was given
        (template matches, say); None when it used the detections.
    """

    tracks: Tracks
    track_ids: np.ndarray
    measurement_index: np.ndarray
    measurements: Detections | None = None


@dataclass(frozen=True)
class DecisionContext:
    """What a policy knows when it picks the next pose.

    step : time step being decided (0-based).
    current_action : flat index of the grid action the camera was sent to last (the nearest one
        when it was last sent to a pose off the grid; for a live camera, the nearest to where it is).
    reachable : flat indices of the actions the mechanics allow next.
    tracks : the tracks predicted to this step (``x-``, ``P-``), before observing.
    rng : the run's random generator; policies draw only from it.
    current_pose : (3,) the pose the camera was last sent to (pan_deg, tilt_deg, zoom); for a live
        camera, where it is.
    dt_s : the scenario's seconds since the last decision (None: one step).
    """

    step: int
    current_action: int
    reachable: np.ndarray
    tracks: Tracks
    rng: np.random.Generator
    current_pose: np.ndarray = field(default_factory=lambda: np.full(3, np.nan))
    dt_s: float | None = None
