"""The LPOM paper's occupancy experiment: people on the ground from several calibrated views, found by
the locus-based occupancy map and by the clustering baseline, scored against the truth (MODA, MODP,
precision, recall within 0.5 m; the tracker fed by LPOM: MOTA, MOTP, IDF1).

A run is one recording, a dataset's (:func:`dataset_runs`), the synthetic room's with 1 and with
3 people (:func:`room_runs`) or the synthetic plaza's with 4 and with 8 (:func:`plaza_runs`), both
detectors over every frame (:func:`run_recording`); its rows, one per method, are tabled by
:func:`format_occupancy_table`.
"""

import math
from collections.abc import Callable, Sequence

import numpy as np

from ptztrack.builders.occupancy import recording_from_dataset
from ptztrack.builders.occupancy_cost import refuse_if_map_too_large
from ptztrack.builders.occupancy_synthetic import PLAZA_LEAD_IN_FRAMES, plaza_recording, room_recording
from ptztrack.builders.parameters import parameters_from
from ptztrack.config import MultiViewDataset, Occupancy, OccupancyTracker, Tracker, pets_dataset
from ptztrack.names import OCCUPANCY_MAP_METHODS
from ptztrack.occupancy.detectors import ClusteringDetector, LpomDetector, LpomForegroundDetector, lpom_parameters
from ptztrack.occupancy.evaluation import (
    MapDetector,
    OccupancyRun,
    PooledDetectors,
    detect_frames,
    fitted_prior,
    halves,
    score_recording,
    scored_truth,
)
from ptztrack.occupancy.feet import fitted_feet_variances
from ptztrack.occupancy.foreground import ViewForeground, view_foregrounds
from ptztrack.occupancy.multiview import MultiViewRecording
from ptztrack.occupancy.parameters import ForegroundParameters, OccupancyParameters, PomParameters
from ptztrack.occupancy.pom import PomDetector
from ptztrack.occupancy.pom_rectangles import fitted_box_scales
from ptztrack.scene.pets import DatasetError
from ptztrack.track.parameters import TrackerParameters

ROOM_PEOPLE = (1, 3)
# S2.L1 has 5.8 people in its area on average, 8 at most: 4 (two pairs) is a sparse plaza, where the
# far views' loci rarely cross another person's; 8 is S2.L1 at its busiest.
PLAZA_PEOPLE = (4, 8)
# POM's person rectangle: its widest diameter (PomParameters' 0.5 m, the a-priori one, first: it wins
# ties) and narrower, down to a body's depth (0.3 m), fitted on the other half with the threshold: a
# silhouette fills only part of the rectangle of its widest diameter (legs, head, arms).
POM_WIDTH_CHOICES_M = (0.5, 0.4, 0.3)
# Where a view has both video and a detector's boxes, its POM mask is its silhouettes (the paper's
# foreground, first: it wins ties) or its boxes, fitted on the other half with the width; views whose
# mask is their boxes have their rectangles scaled to the boxes'
# (:func:`~ptztrack.occupancy.pom_rectangles.fitted_box_scales`, on the other half too), so the width
# matters only to views masked by their silhouettes.
POM_MASK_SOURCES = ("silhouettes", "boxes")
# The table's columns (a row's key) and their formats.
OCCUPANCY_COLUMNS = (
    ("method", "{}"),
    ("people", "{}"),
    ("moda", "{:.1%}"),
    ("modp", "{:.1%}"),
    ("precision", "{:.1%}"),
    ("recall", "{:.1%}"),
    ("error_m", "{:.3f}"),
    ("mota", "{:.1%}"),
    ("motp_m", "{:.3f}"),
    ("idf1", "{:.1%}"),
)


def run_recording(
    recording: MultiViewRecording,
    occupancy: Occupancy,
    tracker: Tracker,
    label: dict | None = None,
    progress: Callable[[int, int], None] | None = None,
    methods: Sequence[str] = OCCUPANCY_MAP_METHODS,
) -> OccupancyRun:
    """Every method over every frame of ``recording``, scored (the recording needs ground truth): LPOM
    from motion edges (the paper's), LPOM from foreground silhouettes (where a view has video), POM
    (where every view's image size is known), the last two where ``methods`` names them, and the
    clustering baseline."""
    if recording.truth is None:
        raise DatasetError(f"{recording.name}: the experiment needs ground truth (ground_truth)")
    settings = parameters_from(occupancy, OccupancyParameters)
    parameters = lpom_parameters(settings)
    refuse_if_map_too_large(recording, parameters)
    lpom = LpomDetector(recording, parameters)
    maps: dict[str, Sequence[MapDetector]] = {"lpom": [lpom]}
    # One background model per view with video, shared: each frame's silhouettes are made once.
    foregrounds = view_foregrounds(recording, ForegroundParameters())
    if "lpom-foreground" in methods and any(view.frames is not None for view in recording.views):
        maps["lpom-foreground"] = [LpomForegroundDetector(recording, parameters, foregrounds, lpom.tables)]
    pom_settings: list[tuple[float, str]] = []
    priors: list[float] = []
    box_scales: list[list[np.ndarray]] = []
    feet_variances: list[np.ndarray] = []
    if "pom" in methods and all(view.image_size_px is not None for view in recording.views):
        maps["pom"], pom_settings, priors, box_scales, feet_variances = pom_detectors(recording, foregrounds)
    clustering = ClusteringDetector(recording, settings.linkage_m, settings.min_box_score, settings.blob_min_area_px)
    frames = detect_frames(recording, maps, clustering, progress)
    # People leave a dataset's area (and never the room's, whose tracks stay well localised).
    tracking = parameters_from(tracker, TrackerParameters)
    run = score_recording(recording, lpom.grid, frames, tracking, occupancy.separation_m, label)
    for row in run.rows:
        if row["method"] == "pom":
            variants = row.pop("fitted_variant")
            row["fitted_prior"] = priors
            row["fitted_width_m"] = [pom_settings[index][0] for index in variants]
            row["fitted_masks"] = [pom_settings[index][1] for index in variants]
            row["fitted_box_scales"] = [
                np.round(scales[index], 3).tolist() for scales, index in zip(box_scales, variants, strict=True)
            ]
            if feet_variances:
                row["fitted_feet_sd_m"] = [
                    [round(float(np.sqrt(variance)), 3) if np.isfinite(variance) else None for variance in variances]
                    for variances in feet_variances
                ]
    return run


def pom_detectors(
    recording: MultiViewRecording, foregrounds: dict[int, ViewForeground]
) -> tuple[list[PooledDetectors], list[tuple[float, str]], list[float], list[list[np.ndarray]], list[np.ndarray]]:
    """POM's detectors for each :func:`halves` pair, fitted on the pair's other half, and the (width,
    mask source) of each setting they pool: every width of ``POM_WIDTH_CHOICES_M`` with the silhouettes
    where a view has them, then, where a view has both silhouettes and boxes, the same with every box view
    masked by its boxes (the a-priori width alone where that leaves no view to silhouettes: a box view's
    rectangles are scaled to its boxes, whatever the width). Also each pair's prior and box scales (per
    setting, (views, 2)) and, where a view has boxes, each pair's feet variances (views,) m^2, with which
    the candidates are localized by the views' box feet (:func:`~ptztrack.occupancy.feet.fitted_feet_variances`,
    on the other half too)."""
    truth_m = scored_truth(recording)
    widths = [PomDetector(recording, PomParameters(width_m=width_m), foregrounds) for width_m in POM_WIDTH_CHOICES_M]
    poms = [(pom, POM_MASK_SOURCES[0]) for pom in widths]
    if any(view.boxes is not None and index in foregrounds for index, view in enumerate(recording.views)):
        from_boxes = [pom.with_masks_from_boxes() for pom in widths]
        every_view_boxed = len(from_boxes[0].box_mask_views()) == len(recording.views)
        poms += [(pom, POM_MASK_SOURCES[1]) for pom in (from_boxes[:1] if every_view_boxed else from_boxes)]
    settings = [(pom.parameters.width_m, source) for pom, source in poms]
    boxed = any(view.boxes is not None for view in recording.views)
    parameters = widths[0].parameters
    detectors, priors, box_scales, feet_variances = [], [], [], []
    for _, fitting in halves(recording.frames):
        prior = fitted_prior(truth_m[fitting], widths[0].grid.cells)
        scales = [
            fitted_box_scales(recording, truth_m, fitting, pom.parameters, pom.box_mask_views()) for pom, _ in poms
        ]
        pooled = [pom.with_prior(prior).with_box_scales(scale) for (pom, _), scale in zip(poms, scales, strict=True)]
        if boxed:
            variances = fitted_feet_variances(
                recording, truth_m, fitting, parameters.feet_gate_m, parameters.min_box_score
            )
            pooled = [pom.with_feet_variances(variances) for pom in pooled]
            feet_variances.append(variances)
        detectors.append(PooledDetectors(pooled))
        priors.append(prior)
        box_scales.append(scales)
    return detectors, settings, priors, box_scales, feet_variances


def dataset_runs(
    dataset: MultiViewDataset, frames: int | None, progress=None, methods: Sequence[str] = OCCUPANCY_MAP_METHODS
) -> list[OccupancyRun]:
    """The dataset's recording (:func:`ptztrack.builders.occupancy.recording_from_dataset`, ``frames`` as
    there), its own parameters."""
    recording = recording_from_dataset(dataset, frames)
    return [run_recording(recording, dataset.occupancy, dataset.tracker, None, progress, methods)]


def room_runs(
    frames: int, seed: int, progress=None, methods: Sequence[str] = OCCUPANCY_MAP_METHODS
) -> list[OccupancyRun]:
    """The synthetic room with 1 and with 3 people (seeds ``seed`` and ``seed + 1``), default parameters."""
    return [
        run_recording(
            room_recording(people, frames, seed + index),
            Occupancy(),
            OccupancyTracker(),
            {"people": people},
            progress,
            methods,
        )
        for index, people in enumerate(ROOM_PEOPLE)
    ]


def plaza_runs(
    frames: int,
    seed: int,
    progress=None,
    methods: Sequence[str] = OCCUPANCY_MAP_METHODS,
    lead_in_frames: int = PLAZA_LEAD_IN_FRAMES,
) -> list[OccupancyRun]:
    """The synthetic plaza with 4 and with 8 people (seeds ``seed`` and ``seed + 1``), each after
    ``lead_in_frames`` (:func:`~ptztrack.builders.occupancy_synthetic.plaza_recording`), with the built-in PETS
    dataset's parameters (its cells and kernel, its tracker), so that its rows compare with PETS's."""
    pets = pets_dataset()
    return [
        run_recording(
            plaza_recording(people, frames, seed + index, lead_in_frames),
            pets.occupancy,
            pets.tracker,
            {"people": people},
            progress,
            methods,
        )
        for index, people in enumerate(PLAZA_PEOPLE)
    ]


def format_occupancy_table(dataset: str, rows: list[dict]) -> str:
    """The table of the runs' ``rows`` on ``dataset`` (its name): a line per row, with the columns of
    ``OCCUPANCY_COLUMNS`` that some row has, then the parameters each row's method fitted."""
    columns = [(key, form) for key, form in OCCUPANCY_COLUMNS if any(key in row for row in rows)]
    width = max(10, *(len(str(row["method"])) for row in rows))
    lines = [
        f"Occupancy-map detection on {dataset}: MODA, MODP, precision, recall within 0.5 m; tracker fed by each map",
        "  ".join(f"{key:>{width if key == 'method' else 10}}" for key, _ in columns),
    ]
    for row in rows:
        cells = (_shown(row.get(key), form) for key, form in columns)
        lines.append(
            "  ".join(
                f"{cell:>{width if key == 'method' else 10}}" for cell, (key, _) in zip(cells, columns, strict=True)
            )
        )
    for row in rows:
        fitted = {key: value for key, value in row.items() if key.startswith("fitted_")}
        lines.append(
            f"{row['dataset']} {row['method']}: {fitted} (each half of the frames scored with the other's fit)"
        )
    return "\n".join(lines)


def _shown(value, form: str) -> str:
    """A table cell: empty where the row has no such figure, "n/a" where the figure is undefined (NaN:
    MODP and the mean error without a match, MODA and recall without a person to find)."""
    if value is None:
        return ""
    return "n/a" if isinstance(value, float) and math.isnan(value) else form.format(value)
