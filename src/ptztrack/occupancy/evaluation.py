"""The occupancy-map experiment: LPOM and the clustering baseline on a multi-view recording, scored.

Every frame of the recording goes through both detectors
(:mod:`ptztrack.occupancy.detectors`) in order. Each method has one threshold, which
is fitted on disjoint frames: the frames are split into a first and a
second half, each half is scored with the threshold that gives the best
MODA on the other half (two-fold cross-validation; a recording too short to
split is scored with the threshold fitted on itself, and the rows say so).
LPOM's threshold is a mode's strength (its value over the frame's largest);
the baseline's is the number of views that must support a cluster. POM's
threshold is fitted together with the radius over which its weaker
candidates merge into stronger ones and the views a candidate's cell needs
(:func:`merged_scores`, :func:`fitted_variant_selection`); and its prior
(:func:`fitted_prior`) is fitted too: each half is detected with the prior
of the other half's people, and scored with the settings fitted on the
other half detected with that same prior.

Detection is scored as in the multi-view detection literature (MVDet,
WILDTRACK): per frame, detections and people are matched one to one by the
Hungarian assignment on ground distances within ``MATCH_RADIUS_M`` (0.5 m);
MODA = 1 - (false positives + misses) / people, MODP = mean of
(1 - d / 0.5 m) over the matches, precision, recall, and ``error_m`` the
mean distance of the matches (the LPOM paper's "mean error"). People
outside the recording's area are not scored. LPOM's modes also feed the
ground-plane EKF tracker as measurements of position with the mode's
covariance (:func:`ptztrack.track.tracker.update_tracks_on_ground`), scored
by MOTA, MOTP and IDF1 (:func:`ptztrack.evaluate.metrics.clear_metrics`,
1 m gate).
"""

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from scipy.optimize import linear_sum_assignment
from scipy.spatial.distance import cdist

from ptztrack.evaluate.metrics import clear_metrics
from ptztrack.occupancy.clustering import Clusters
from ptztrack.occupancy.detectors import ClusteringDetector
from ptztrack.occupancy.lpom import GroundGrid, Modes
from ptztrack.occupancy.multiview import MultiViewRecording, outside_area
from ptztrack.track.kalman import constant_velocity_model
from ptztrack.track.parameters import TrackerParameters
from ptztrack.track.tracker import predict_tracks, update_tracks_on_ground
from ptztrack.types import Tracks

MATCH_RADIUS_M = 0.5
STRENGTH_CHOICES = tuple(np.round(np.arange(0.05, 1.0, 0.05), 2))
# POM's candidates are cells' local maxima over a cell's neighbours (:class:`~ptztrack.occupancy.parameters.
# PomParameters`): where views disagree on where a person stands, one person lights two cells. How far
# apart depends on the views' calibrations, so the radius over which weaker candidates are merged into
# stronger ones is fitted with the threshold, among the neighbours' radius, LPOM's separation, the
# clustering baseline's linkage and the midpoint of the two. A cell few views see is pinned down by
# few rectangles (one view's box explains a whole ray of them), so the views a candidate's cell needs
# are fitted too, as the baseline's views a cluster needs are.
MERGED_METHODS = ("pom",)
MERGE_RADIUS_CHOICES_M = (0.375, 0.5, 0.75, 1.0)
UNMATCHED_COST = 1e6


def detection_metrics(truth_m, detections_m, radius_m: float = MATCH_RADIUS_M) -> dict:
    """MODA, MODP, precision, recall and the mean error of matched detections over frames.

    truth_m : (T, N, 2) m, NaN where absent; detections_m : per frame, (K_t, 2) m.
    Also returns the counts: ``matches``, ``false_positives``, ``misses``, ``objects`` (people to find).
    """
    distances, false_positives, misses = [], 0, 0
    for truth, found in zip(truth_m, detections_m, strict=True):
        truth = truth[~np.isnan(truth[:, 0])]
        distance_m = cdist(truth, np.asarray(found, dtype=float).reshape(-1, 2))
        allowed = distance_m <= radius_m
        rows, columns = linear_sum_assignment(np.where(allowed, distance_m, UNMATCHED_COST))
        matched = distance_m[rows, columns][allowed[rows, columns]]
        distances.append(matched)
        false_positives += len(found) - len(matched)
        misses += len(truth) - len(matched)
    matched_m = np.concatenate(distances) if distances else np.zeros(0)
    objects = len(matched_m) + misses
    found = len(matched_m) + false_positives
    return {
        "moda": 1 - (false_positives + misses) / objects if objects else float("nan"),
        "modp": float(np.mean(1 - matched_m / radius_m)) if len(matched_m) else float("nan"),
        "precision": len(matched_m) / found if found else float("nan"),
        "recall": len(matched_m) / objects if objects else float("nan"),
        "error_m": float(np.mean(matched_m)) if len(matched_m) else float("nan"),
        "matches": len(matched_m),
        "false_positives": false_positives,
        "misses": misses,
        "objects": objects,
    }


def scored_truth(recording: MultiViewRecording) -> np.ndarray:
    """The truth (T, N, 2) m of the recording's frames, NaN outside its area (not scored)."""
    assert recording.truth is not None
    truth = recording.truth.positions_m[: recording.frames].copy()
    truth[outside_area(truth, recording.area_m)] = np.nan
    return truth


@dataclass(frozen=True)
class Frames:
    """What the detectors found in every frame: the first map method's occupancy maps as (rows, columns)
    uint8 (scaled to each frame's largest value, for pictures), every map method's candidate modes (by
    method, in the order run; per :func:`halves` pair, the modes of every frame by the detector that
    pair uses, the same list for every pair where a method has one detector) and the baseline's clusters."""

    maps_u8: list[np.ndarray]
    modes: dict[str, list[list[Modes]]]
    clusters: list[Clusters]


class MapDetector(Protocol):
    """A detector of people as the modes of a map on the ground (LPOM, POM): ``detect(frame) -> (map, modes)``."""

    def detect(self, frame: int) -> tuple[np.ndarray, Modes]: ...


@dataclass(frozen=True)
class PooledDetectors:
    """One method's detectors under several settings (a parameter fitted on the other half of the frames,
    as the threshold is), run as one: a frame's modes are every setting's, each tagged with its setting's
    index (:attr:`Modes.variant`); the map is the first setting's."""

    detectors: Sequence[MapDetector]

    def detect(self, frame: int) -> tuple[np.ndarray, Modes]:
        found = [detector.detect(frame) for detector in self.detectors]
        modes = [frame_modes for _, frame_modes in found]
        views = [m.views for m in modes if m.views is not None]
        return found[0][0], Modes(
            np.concatenate([m.position_m for m in modes]),
            np.concatenate([m.covariance_m2 for m in modes]),
            np.concatenate([m.strength for m in modes]),
            np.concatenate(views) if len(views) == len(modes) else None,
            np.concatenate([np.full(len(m), index) for index, m in enumerate(modes)]),
        )


def detect_frames(
    recording: MultiViewRecording,
    maps: dict[str, Sequence[MapDetector]],
    clustering: ClusteringDetector,
    progress: Callable[[int, int], None] | None = None,
) -> Frames:
    """Run every detector over every frame, in order; ``maps`` by method, one detector for every
    :func:`halves` pair or one for each pair (in their order); the first detector's maps are kept."""
    pairs = len(halves(recording.frames))
    maps_u8: list[np.ndarray] = []
    found_by: dict[str, list[list[Modes]]] = {method: [[] for _ in detectors] for method, detectors in maps.items()}
    clusters = []
    for frame in range(recording.frames):
        for index, (method, detectors) in enumerate(maps.items()):
            for detector, found in zip(detectors, found_by[method], strict=True):
                occupancy, frame_modes = detector.detect(frame)
                if index == 0 and detector is detectors[0]:
                    peak = occupancy.max(initial=0.0)
                    scaled = np.round(255 * occupancy / peak) if peak > 0 else np.zeros(occupancy.shape)
                    maps_u8.append(scaled.astype(np.uint8))
                found.append(frame_modes)
        clusters.append(clustering.detect(frame))
        if progress is not None:
            progress(frame + 1, recording.frames)
    modes = {method: found * pairs if len(found) == 1 else found for method, found in found_by.items()}
    return Frames(maps_u8, modes, clusters)


def halves(frames: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """(scored frames, fitting frames) pairs: each half fitted on the other, or the whole on itself when
    there are fewer than 2 frames."""
    every = np.arange(frames)
    if frames < 2:
        return [(every, every)]
    first, second = every[: frames // 2], every[frames // 2 :]
    return [(first, second), (second, first)]


def fitted_prior(truth_m, cells: int) -> float:
    """POM's prior (``epsilon``, :mod:`ptztrack.occupancy.pom`) from annotated frames: the mean number of
    people per frame in truth (T, N, 2) m (NaN: absent or outside the area) over the grid's ``cells``,
    the expected share of occupied cells; at least one person over the frames, so never 0."""
    people = np.sum(~np.isnan(np.asarray(truth_m)[..., 0])) / max(len(truth_m), 1)
    return float(max(people, 1.0 / max(len(truth_m), 1)) / cells)


def fitted_selection(
    truth_m, scores: Sequence[list[np.ndarray]], positions: Sequence[list[np.ndarray]], choices
) -> tuple[list, list, np.ndarray]:
    """Per frame, the detections whose score reaches the threshold fitted on the other half's frames.

    scores, positions : per :func:`halves` pair, per frame, (K_t,) and (K_t, 2): the detections of
    the detector that pair uses (one detector's lists repeated where they are the same). choices :
    thresholds to try (the first of the best is taken). Returns the kept positions per frame, the
    fitted threshold of each half, and per frame (T,) the recall at that threshold on the frames it
    was fitted on (what the tracker may assume of the detector: it is not measured on the frames it
    is used for).
    """
    kept, fitted, recall = fitted_variant_selection(truth_m, [scores], positions, choices)
    return kept, [threshold for _, threshold in fitted], recall


def fitted_variant_selection(
    truth_m, variants: Sequence[Sequence[list[np.ndarray]]], positions: Sequence[list[np.ndarray]], choices
) -> tuple[list, list[tuple[int, float]], np.ndarray]:
    """:func:`fitted_selection` with a second parameter fitted with the threshold: ``variants[v]`` are the
    detections' scores under the v-th setting of it (``-inf`` where that setting drops a detection), per
    pair and per frame as ``scores`` there. Each half gets the (variant, threshold) with the best MODA on
    the other half (the first of the best, variants before thresholds); returns the kept detections per
    frame, the fitted (variant, threshold) of each half and the recall per frame (T,) as there."""
    frames = len(truth_m)
    kept: list = [None] * frames
    fitted: list[tuple[int, float]] = []
    recall = np.zeros(frames)
    for pair, ((scored, fitting), pair_positions) in enumerate(zip(halves(frames), positions, strict=True)):
        figures = [
            (
                detection_metrics(truth_m[fitting], [pair_positions[f][variant[pair][f] >= choice] for f in fitting]),
                index,
                choice,
            )
            for index, variant in enumerate(variants)
            for choice in choices
        ]
        best = int(np.nanargmax([figure["moda"] for figure, _, _ in figures]))
        figure, variant_index, threshold = figures[best]
        fitted.append((variant_index, threshold))
        recall[scored] = figure["recall"]
        for frame in scored:
            kept[frame] = variants[variant_index][pair][frame] >= threshold
    return kept, fitted, recall


def merged_scores(
    modes: Modes, radius_m: float, min_views: int = 0, distance_m=None, variant: int | None = None
) -> np.ndarray:
    """The modes' strengths (K,) with ``-inf`` for each mode that is dropped: one whose cell fewer than
    ``min_views`` views see (where the modes say: :attr:`Modes.views`), one of another setting than
    ``variant`` (where the modes are pooled: :attr:`Modes.variant`), and one within ``radius_m`` of a
    stronger mode that is itself kept (greedy non-maximum suppression on the ground, strongest first as
    :class:`Modes` are). distance_m : (K, K) the modes' distances, where the caller has them already."""
    eligible = np.ones(len(modes), bool) if modes.views is None else modes.views >= min_views
    if variant is not None and modes.variant is not None:
        eligible &= modes.variant == variant
    if distance_m is None:
        distance_m = cdist(modes.position_m, modes.position_m)
    kept = np.zeros(len(modes), bool)
    for index in range(len(modes)):
        kept[index] = eligible[index] and not np.any(distance_m[index, :index][kept[:index]] < radius_m)
    return np.where(kept, modes.strength, -np.inf)


def track_on_ground(
    modes: list[Modes],
    recall,
    separation_m: float,
    frame_rate_hz: float,
    parameters: TrackerParameters,
) -> list[Tracks]:
    """The ground-plane EKF tracker fed by each frame's modes; the reported tracks per frame.

    recall : (T,) per frame, the probability that the map finds a person who is there; separation_m :
    the map's closest two modes. A track predicted within ``separation_m`` of another cannot have a
    mode of its own, so its miss says nothing (detection probability 0); any other's is ``recall``
    (an undetected track's loss of existence; :func:`ptztrack.track.tracker.update_tracks_on_ground`).
    """
    F, U = constant_velocity_model(1.0 / frame_rate_hz, parameters.acceleration_sigma_m_s2)
    tracks, reported = Tracks.empty(), []
    for found, recall_now in zip(modes, recall, strict=True):
        tracks = predict_tracks(tracks, F, U)
        distance_m = cdist(tracks.mean[:, :2], tracks.mean[:, :2])
        np.fill_diagonal(distance_m, np.inf)
        alone = distance_m.min(axis=1, initial=np.inf) >= separation_m
        tracks = update_tracks_on_ground(
            tracks, found.position_m, found.covariance_m2, parameters, recall_now * alone
        ).tracks
        reported.append(tracks.confirmed(parameters.confirmation_hits))
    return reported


@dataclass(frozen=True)
class OccupancyRun:
    """One recording's experiment: the rows (one per method), what each frame kept (``kept``: by map
    method; ``clustering``), the tracks fed by each map method's detections, the truth; ``grid`` is
    the first map method's."""

    rows: list[dict]
    frame_rate_hz: float
    grid: GroundGrid
    frames: Frames
    kept: dict[str, list[Modes]]
    clustering: list[Clusters]
    tracks: dict[str, list[Tracks]]
    truth_m: np.ndarray


def _used_modes(modes_by_pair: list[list[Modes]], frames: int) -> list[Modes]:
    """Per frame, the modes of the detector its :func:`halves` pair scores it with."""
    used: list = [None] * frames
    for (scored, _), modes in zip(halves(frames), modes_by_pair, strict=True):
        for frame in scored:
            used[frame] = modes[frame]
    return used


def _settings_and_scores(
    modes_by_pair: list[list[Modes]], merged: bool, views: Sequence[int]
) -> tuple[list[tuple], list[list[list[np.ndarray]]]]:
    """The settings a map method's threshold is fitted with, as (merging radius, views, pooled variant)
    (None where the method has no such setting), and its modes' scores under each, per setting, pair and
    frame (:func:`fitted_variant_selection`): the strengths themselves for a method that is not merged,
    :func:`merged_scores` for one that is."""
    if not merged:
        return [(None, None, None)], [[[m.strength for m in modes] for modes in modes_by_pair]]
    tags = [m.variant for modes in modes_by_pair for m in modes if m.variant is not None]
    variants: list[int | None] = [int(v) for v in np.unique(np.concatenate(tags))] if tags else []
    settings = list(itertools.product(MERGE_RADIUS_CHOICES_M, views, variants or [None]))
    distances_m = [[cdist(m.position_m, m.position_m) for m in modes] for modes in modes_by_pair]
    scores = [
        [
            [merged_scores(m, radius_m, min_views, d, variant) for m, d in zip(modes, pair_distances, strict=True)]
            for modes, pair_distances in zip(modes_by_pair, distances_m, strict=True)
        ]
        for radius_m, min_views, variant in settings
    ]
    return settings, scores


def score_recording(
    recording: MultiViewRecording,
    grid: GroundGrid,
    frames: Frames,
    tracker: TrackerParameters,
    separation_m: float,
    label: dict | None = None,
) -> OccupancyRun:
    """Fit each method's threshold on disjoint frames, score every method, and track each map method's
    detections.

    label : keys added to every row (e.g. ``{"people": 3}``).
    """
    truth_m = scored_truth(recording)
    common = {"dataset": recording.name, **(label or {}), "frames": recording.frames, "views": len(recording.views)}
    rows, kept, tracks = [], {}, {}
    views = tuple(range(1, len(recording.views) + 1))
    for method, modes_by_pair in frames.modes.items():
        settings, scores = _settings_and_scores(modes_by_pair, method in MERGED_METHODS, views)
        kept_modes, fitted, recall = fitted_variant_selection(
            truth_m, scores, [[m.position_m for m in modes] for modes in modes_by_pair], STRENGTH_CHOICES
        )
        strengths = [threshold for _, threshold in fitted]
        merging = {
            key: [settings[index][column] for index, _ in fitted]
            for column, key in enumerate(("fitted_merge_radius_m", "fitted_min_views", "fitted_variant"))
            if any(setting[column] is not None for setting in settings)
        }
        used = _used_modes(modes_by_pair, truth_m.shape[0])
        kept[method] = [found.select(keep) for found, keep in zip(used, kept_modes, strict=True)]
        tracks[method] = track_on_ground(kept[method], recall, separation_m, recording.frame_rate_hz, tracker)
        tracking = clear_metrics(truth_m, [t.ids for t in tracks[method]], [t.mean[:, :2] for t in tracks[method]])
        rows.append(
            {
                "method": method,
                **common,
                **detection_metrics(truth_m, [m.position_m for m in kept[method]]),
                "fitted_min_strength": [float(value) for value in strengths],
                **merging,
                "mota": tracking["mota"],
                "motp_m": tracking["motp_m"],
                "idf1": tracking["idf1"],
                "switches": tracking["switches"],
            }
        )
    pairs = len(halves(recording.frames))
    kept_clusters, min_views, _ = fitted_selection(
        truth_m, [[c.views for c in frames.clusters]] * pairs, [[c.position_m for c in frames.clusters]] * pairs, views
    )
    clustering = [found.select(keep) for found, keep in zip(frames.clusters, kept_clusters, strict=True)]
    rows.append(
        {
            "method": "clustering",
            **common,
            **detection_metrics(truth_m, [c.position_m for c in clustering]),
            "fitted_min_views": [int(value) for value in min_views],
        }
    )
    return OccupancyRun(rows, recording.frame_rate_hz, grid, frames, kept, clustering, tracks, truth_m)
