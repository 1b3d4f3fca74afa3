"""Tracking metrics on the ground plane (paper section 5), computed with motmetrics.

MOTA and IDF1 as usual; MOTP is the mean distance in metres between matched
truth and track positions (lower is better, as in the paper), with a match
allowed only within ``gate_m`` (1 m). Over several runs, the standard error of a
figure's mean.
"""

from collections.abc import Iterable, Sequence
from dataclasses import replace

import motmetrics as mm
import numpy as np

from ptztrack.geometry.area import inside
from ptztrack.loop.live import LiveEpisode
from ptztrack.loop.simulated import NetworkEpisode
from ptztrack.loop.steps import Episode
from ptztrack.names import GATE_M
from ptztrack.types import GroundTruth, Tracks

# How each figure is shown in tables: label and format.
DISPLAY = {
    "mota": ("MOTA", "{:.1%}"),
    "motp_m": ("MOTP [m]", "{:.3f}"),
    "idf1": ("IDF1", "{:.1%}"),
    "height_px": ("Height [px]", "{:.1f}"),
    "detections": ("# Dets", "{:.1f}"),
    "zoom": ("Zoom [x]", "{:.2f}"),
    "switches": ("ID switches", "{:.0f}"),
    "motp_iou": ("MOTP [IoU]", "{:.1%}"),
    "false_positives": ("False positives", "{:.0f}"),
    "misses": ("Misses", "{:.0f}"),
    "matches": ("Matches", "{:.0f}"),
    "objects": ("Person-frames", "{:.0f}"),
}
# Why a figure can have no value: written beside it (metrics.json's ``undefined``), since JSON has no NaN.
UNDEFINED_BECAUSE = {
    "mota": "no person was in view of the scene: MOTA divides by the number of person-instances",
    "motp_m": "no track was matched to a person: MOTP is a mean over matches",
    "motp_iou": "no track was matched to a person: MOTP is a mean over matches",
    "idf1": "there was neither a person nor a track: IDF1 divides by their number",
    "height_px": "no detection had a known height",
    "zoom": "the episode has no steps",
    "frames_used_per_s": "fewer than two pictures were used",
    "frames_detected_per_s": "the detector took fewer than two pictures",
    "decisions_per_s": "fewer than two decisions were made",
    "frame_age_s_p95": "no decision was made",
    "median_decision_s": "no decision was made",
}


def format_figures(metrics: dict, figures: Sequence[str]) -> str:
    """The ``figures`` of ``metrics``, one a line, named and formatted as ``DISPLAY`` says."""
    width = max(len(DISPLAY[key][0]) for key in figures)
    return "\n".join(f"{DISPLAY[key][0]:<{width}}  {DISPLAY[key][1].format(metrics[key])}" for key in figures)


def gated_distances_m(truth_m, tracks_m, gate_m: float = GATE_M) -> np.ndarray:
    """The distances (n, k) m from n people at truth_m (n, 2) m to k tracks at tracks_m (k, 2) m; NaN, where
    motmetrics allows no match, beyond ``gate_m``."""
    distance_m = np.linalg.norm(np.asarray(truth_m)[:, None, :] - np.asarray(tracks_m)[None, :, :], axis=-1)
    distance_m[distance_m > gate_m] = np.nan
    return distance_m


def frames_accumulator(frames: Iterable[tuple]) -> mm.MOTAccumulator:
    """The motmetrics accumulator of ``frames``, each (truth_ids (n,), track_ids (k,), distances (n, k)
    with NaN where no match is allowed): its ``mot_events`` pair every person with a track, frame by
    frame (MATCH, SWITCH, MISS, FP)."""
    accumulator = mm.MOTAccumulator(auto_id=True)
    for truth_ids, track_ids, distances in frames:
        accumulator.update(np.asarray(truth_ids).tolist(), np.asarray(track_ids).tolist(), distances)
    return accumulator


def metric_accumulator(truth_positions_m, track_ids, track_positions_m, gate_m: float = GATE_M):
    """The motmetrics accumulator of tracks against the truth (arguments as :func:`clear_metrics`, see
    :func:`frames_accumulator`); the truth's ids are its columns."""

    def frames():
        for truth_frame, ids, positions in zip(truth_positions_m, track_ids, track_positions_m, strict=True):
            present = np.flatnonzero(~np.isnan(truth_frame[:, 0]))
            yield present, ids, gated_distances_m(truth_frame[present], positions, gate_m)

    return frames_accumulator(frames())


def clear_metrics(truth_positions_m, track_ids, track_positions_m, gate_m: float = GATE_M) -> dict:
    """CLEAR-MOT and identity metrics of tracks against the truth.

    truth_positions_m : (T, N, 2), NaN where person n is absent at frame t.
    track_ids : per frame, (n_t,) track ids.
    track_positions_m : per frame, (n_t, 2) estimated positions.
    Returns mota, motp_m, idf1, switches, false_positives, misses, objects and
    matches (every truth-track correspondence, switches included).
    """
    return accumulator_metrics(metric_accumulator(truth_positions_m, track_ids, track_positions_m, gate_m))


def accumulator_metrics(accumulator: mm.MOTAccumulator, motp_key: str = "motp_m") -> dict:
    """The figures of :func:`clear_metrics` from a motmetrics accumulator; MOTP, the mean distance of the
    matches, under the name ``motp_key`` (it carries the distances' unit)."""
    summary = mm.metrics.create().compute(
        accumulator,
        metrics=[
            "mota",
            "motp",
            "idf1",
            "num_switches",
            "num_false_positives",
            "num_misses",
            "num_detections",
            "num_objects",
        ],
        name="episode",
    )
    row = summary.loc["episode"]
    return {
        "mota": float(row["mota"]),
        motp_key: float(row["motp"]),
        "idf1": float(row["idf1"]),
        "switches": int(row["num_switches"]),
        "false_positives": int(row["num_false_positives"]),
        "misses": int(row["num_misses"]),
        "matches": int(row["num_detections"]),
        "objects": int(row["num_objects"]),
    }


def episode_metrics(episode: Episode, with_truth: bool = True) -> dict:
    """The paper's figures for one episode.

    Besides :func:`clear_metrics`: ``height_px``, the mean pixel height of the
    detections whose height is known (a simulated false positive has none); ``detections``, the number of detections the
    detector reported (false positives included); ``zoom``, the mean zoom. Without ``with_truth`` (a real
    camera's run, which has no ground truth) the figures of :func:`clear_metrics` are left out, not zero.
    """
    scores = tracking_metrics(episode.truth, episode.tracks) if with_truth else {}
    return {**scores, **looking_metrics([episode])}


def live_metrics(live: LiveEpisode) -> dict:
    """A live run's figures that need no truth: ``pictures`` used of ``frames_received``, ``decisions``,
    ``targets_sent`` (new poses sent to the camera), ``tracks_reported`` (distinct track ids) and the pace
    (:meth:`LiveEpisode.rates`)."""
    return {
        "pictures": len(live.capture_time_s),
        "frames_received": live.frames_received,
        "decisions": int(np.isfinite(live.decided_s).sum()),
        "targets_sent": int(live.sent.sum()),
        "tracks_reported": len(set().union(*(tracks.ids.tolist() for tracks in live.tracks))),
        **live.rates(),
    }


def network_metrics(episode: NetworkEpisode) -> dict:
    """:func:`episode_metrics` of a camera network: the figures of its one set of tracks, and
    ``height_px``, ``detections`` and ``zoom`` over every camera's detections and poses."""
    return {**tracking_metrics(episode.truth, episode.tracks), **looking_metrics(episode.cameras)}


def tracks_within(tracks: Sequence[Tracks], polygon_m) -> list[Tracks]:
    """Each step's tracks whose ground position lies inside the polygon (K, 2) m: the ones a truth
    annotated only there can score."""
    return [step.select(inside(polygon_m, step.mean[:, :2])) if len(step) else step for step in tracks]


def truth_within(truth: GroundTruth, polygon_m) -> GroundTruth:
    """``truth`` with every person absent (NaN) at the steps their feet lie outside the polygon (K, 2) m."""
    positions_m = truth.positions_m.copy()
    present = truth.present
    outside = np.zeros_like(present)
    outside[present] = ~inside(polygon_m, positions_m[present])
    positions_m[outside] = np.nan
    return replace(truth, positions_m=positions_m)


def tracking_metrics(truth: GroundTruth, tracks: Sequence[Tracks]) -> dict:
    """:func:`clear_metrics` of the reported ``tracks`` of every step against ``truth``."""
    return clear_metrics(truth.positions_m, [step.ids for step in tracks], [step.mean[:, :2] for step in tracks])


def looking_metrics(cameras: Sequence[Episode]) -> dict:
    """What the cameras saw, over all of them: ``height_px``, the mean pixel height of the detections whose
    height is known (a simulated false positive has none); ``detections``, how many the detectors
    reported (false positives included); ``zoom``, the mean zoom over cameras and steps."""
    detections = [found for camera in cameras for found in camera.detections]
    detected_heights_px = np.concatenate([d.height_px[np.isfinite(d.height_px)] for d in detections])
    return {
        "height_px": float(np.mean(detected_heights_px)) if len(detected_heights_px) else float("nan"),
        "detections": int(sum(len(d) for d in detections)),
        "zoom": float(np.mean(np.concatenate([camera.poses[:, 2] for camera in cameras]))),
    }


def standard_error(values) -> float:
    """The standard error of the mean of ``values`` (sample standard deviation / sqrt(n)); 0 for one value."""
    values = np.asarray(values, dtype=float)
    return float(values.std(ddof=1) / np.sqrt(len(values))) if len(values) > 1 else 0.0


def with_undefined_noted(metrics: dict) -> dict:
    """``metrics`` with ``undefined``: {figure: why} for every figure that has no value (NaN)."""
    undefined = {
        key: UNDEFINED_BECAUSE.get(key, "undefined")
        for key, value in metrics.items()
        if isinstance(value, float) and not np.isfinite(value)
    }
    return {**metrics, "undefined": undefined}
