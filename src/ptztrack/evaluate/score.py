"""Any tracker's MOTChallenge file scored against its truth with ptztrack's metrics (``ptztrack score``).

Both files hold MOTChallenge rows ``frame,id,left,top,width,height,conf,x,y,z``, frames from 1, as a
run folder's ``truth_mot.txt`` and ``tracks_mot.txt`` do. Frame by frame, tracks are matched to people
either on the ground (``world``: x and y, columns 8-9, in metres, within a gate, as ``ptztrack run``
scores) or in the image (``image``: the boxes in pixels, at an intersection over union of at least
``MATCH_MIN_IOU``, as MOTChallenge scores), and the matches are counted by the motmetrics accumulator a
run's metrics come from (:mod:`ptztrack.evaluate.metrics`). Truth rows whose conf (column 7) is below 1,
MOTChallenge's mark of a person not to score, are left out, as motmetrics' MOTChallenge evaluation
leaves them; the tracks' conf is not read.
"""

from collections.abc import Callable
from functools import partial
from pathlib import Path

import numpy as np

from ptztrack.evaluate.metrics import accumulator_metrics, frames_accumulator, gated_distances_m
from ptztrack.files import InputError
from ptztrack.names import GATE_M, MATCH_MIN_IOU, SCORE_COORDINATES
from ptztrack.scene.pets import Annotations, DatasetError, box_iou, read_mot_rows, refuse_repeated_annotations

UNFILLED = -1.0
"""MOTChallenge's value for a column a file does not fill (world positions in 2D files, boxes in ours)."""
TRUTH_MIN_CONF = 1.0
"""Truth rows of a lower conf are not scored (MOTChallenge marks a person not to score with 0)."""


def score_files(
    truth_path: str | Path, tracks_path: str | Path, coordinates: str | None = None, gate_m: float | None = None
) -> dict:
    """The metrics of the tracks in ``tracks_path`` against the truth in ``truth_path``, MOTChallenge files.

    coordinates : "world" (x and y, columns 8-9, in metres) or "image" (the boxes, in pixels); None:
        world if both files fill columns 8-9 (not -1 on every row), else image.
    gate_m : in world coordinates, how far a track may lie from a person to be matched to them (default
        ``GATE_M``, as a run is scored); image boxes are matched at an IoU of ``MATCH_MIN_IOU`` or more.
    Returns the figures of :func:`~ptztrack.evaluate.metrics.clear_metrics` (in image coordinates
    ``motp_iou``, the mean intersection over union of the matches, in place of ``motp_m``); and
    ``coordinates``, ``gate_m`` or ``min_iou``, ``frames`` (those either file has rows in), ``people``
    and ``tracks`` (their distinct ids). A bad file raises :class:`~ptztrack.scene.pets.DatasetError`
    naming it, the line and the value.
    """
    if coordinates not in (None, *SCORE_COORDINATES):
        raise ValueError(f"coordinates {coordinates!r}: expected one of {', '.join(SCORE_COORDINATES)} or None")
    truth = scored_truth(truth_path)
    tracks, _ = read_mot_file(tracks_path, "tracks")
    refuse_disjoint_frames(truth_path, truth, tracks_path, tracks)
    if coordinates is None:
        coordinates = "world" if fills_world(truth) and fills_world(tracks) else "image"
    distances: Callable[[np.ndarray, np.ndarray], np.ndarray]
    if coordinates == "world":
        for path, rows in ((truth_path, truth), (tracks_path, tracks)):
            refuse_without_world(path, rows)
        setting: dict = {"gate_m": GATE_M if gate_m is None else gate_m}
        distances = partial(gated_distances_m, gate_m=setting["gate_m"])
        truth_points, track_points = truth.ground_m, tracks.ground_m
    else:
        if gate_m is not None:
            raise InputError(
                f"--gate-m {gate_m:g}: a gate in metres is for world coordinates; in image coordinates "
                f"boxes match at an intersection over union of {MATCH_MIN_IOU:g} or more"
            )
        for path, rows in ((truth_path, truth), (tracks_path, tracks)):
            refuse_without_boxes(path, rows)
        setting = {"min_iou": MATCH_MIN_IOU}
        distances = overlap_distances
        truth_points, track_points = truth.box_px, tracks.box_px
    frames = np.union1d(truth.frame, tracks.frame)
    truth_by_frame, tracks_by_frame = rows_by_frame(truth.frame, frames), rows_by_frame(tracks.frame, frames)
    accumulator = frames_accumulator(
        (
            truth.person_id[truth_rows],
            tracks.person_id[track_rows],
            distances(truth_points[truth_rows], track_points[track_rows]),
        )
        for truth_rows, track_rows in zip(truth_by_frame, tracks_by_frame, strict=True)
    )
    metrics = accumulator_metrics(accumulator, "motp_m" if coordinates == "world" else "motp_iou")
    if coordinates == "image":
        metrics["motp_iou"] = 1.0 - metrics["motp_iou"]  # the accumulator's distances are 1 - IoU
    return {
        **metrics,
        "coordinates": coordinates,
        **setting,
        "frames": len(frames),
        "people": len(np.unique(truth.person_id)),
        "tracks": len(np.unique(tracks.person_id)),
    }


def overlap_distances(truth_px, tracks_px) -> np.ndarray:
    """1 - the intersection over union (n, k) of n people's boxes (n, 4) px and k tracks' boxes (k, 4) px
    (left, top, width, height); NaN, where motmetrics allows no match, below ``MATCH_MIN_IOU``."""
    overlap = box_iou(np.asarray(truth_px)[:, None, :], np.asarray(tracks_px)[None, :, :])
    return np.where(overlap >= MATCH_MIN_IOU, 1.0 - overlap, np.nan)


def read_mot_file(path: str | Path, what: str) -> tuple[Annotations, np.ndarray]:
    """The rows of a MOTChallenge file, checked (:func:`~ptztrack.scene.pets.read_mot_rows`, each id once
    a frame), as :class:`~ptztrack.scene.pets.Annotations` (frames from 0), and their conf (K,)."""
    table, line = read_mot_rows(path, what)
    frame, person_id = table[:, 0].astype(np.int64), table[:, 1].astype(np.int64)
    refuse_repeated_annotations(path, frame, person_id, line)
    return Annotations(frame - 1, person_id, table[:, 2:6], table[:, 7:9], line), table[:, 6]


def scored_truth(path: str | Path) -> Annotations:
    """The truth's rows that are scored: those of conf ``TRUTH_MIN_CONF`` or more."""
    truth, conf = read_mot_file(path, "truth")
    scored = conf >= TRUTH_MIN_CONF
    if not scored.any():
        raise DatasetError(
            f"{path}: every row's conf (column 7) is below {TRUTH_MIN_CONF:g}, MOTChallenge's mark of a person "
            "not to score; expected truth rows of conf 1"
        )
    return truth.select(scored)


def fills_world(rows: Annotations) -> bool:
    """Whether a file's rows carry world positions: columns 8-9 not unfilled (-1) on every row."""
    return not np.all(rows.ground_m == UNFILLED)


def refuse_without_world(path: str | Path, rows: Annotations) -> None:
    """A :class:`DatasetError` if no row of ``path`` has a world position."""
    if not fills_world(rows):
        raise DatasetError(
            f"{path}: no world positions (columns 8-9 are -1 on every row); "
            "expected x and y in metres, or score the boxes with --coordinates image"
        )


def refuse_without_boxes(path: str | Path, rows: Annotations) -> None:
    """A :class:`DatasetError` naming the first row of ``path`` whose box has no area."""
    empty = np.flatnonzero(np.any(rows.box_px[:, 2:] <= 0, axis=1))
    if len(empty) == len(rows.frame):
        raise DatasetError(
            f"{path}: no boxes (width and height, columns 5-6, not positive on any row); "
            "expected boxes in pixels, or score the world positions with --coordinates world"
        )
    if len(empty):
        assert rows.line is not None  # read from a MOTChallenge file, whose rows have lines
        first = empty[np.argmin(rows.line[empty])]
        width_px, height_px = rows.box_px[first, 2:]
        raise DatasetError(
            f"{path}: line {rows.line[first]}: a box {width_px:g} px wide and {height_px:g} px high; "
            "expected a positive width and height (columns 5-6) to match boxes by their overlap"
        )


def refuse_disjoint_frames(
    truth_path: str | Path, truth: Annotations, tracks_path: str | Path, tracks: Annotations
) -> None:
    """A :class:`DatasetError` if the tracks have no frame the truth has: most likely another sequence's."""
    if not np.isin(tracks.frame, truth.frame).any():
        raise DatasetError(
            f"{tracks_path}: frames {tracks.frame.min() + 1} to {tracks.frame.max() + 1}, none of them a frame "
            f"of the truth {truth_path} (frames {truth.frame.min() + 1} to {truth.frame.max() + 1}); "
            "expected the tracks of the truth's sequence"
        )


def rows_by_frame(row_frames, frames) -> list[np.ndarray]:
    """For each of ``frames`` (F,), the indices of the rows whose frame (K,) it is, in the rows' order."""
    order = np.argsort(row_frames, kind="stable")
    sorted_frames = np.asarray(row_frames)[order]
    starts = np.searchsorted(sorted_frames, frames, side="left")
    stops = np.searchsorted(sorted_frames, frames, side="right")
    return [order[start:stop] for start, stop in zip(starts, stops, strict=True)]
