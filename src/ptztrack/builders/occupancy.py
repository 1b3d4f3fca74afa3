"""The occupancy-map experiment's recording from a dataset file: a
:class:`~ptztrack.config.MultiViewDataset` made into a :class:`~ptztrack.occupancy.multiview.MultiViewRecording`.

Each view's calibration, frames and detections are read and checked: a view that sees none of the area is
refused, ground truth outside the area and detections far from the ground truth's people are warned of,
and an occupancy map over the recording that would not fit is refused
(:mod:`ptztrack.builders.occupancy_cost`). The synthetic room and plaza are
:mod:`ptztrack.builders.occupancy_synthetic`'s.
"""

import functools
import logging
from pathlib import Path

import numpy as np
from scipy.optimize import linear_sum_assignment
from scipy.spatial.distance import cdist

from ptztrack.builders.occupancy_cost import refuse_if_map_too_large
from ptztrack.builders.parameters import parameters_from
from ptztrack.config import MAX_DATASET_FRAMES, DatasetView, MultiViewDataset
from ptztrack.geometry.calibration import (
    PinholeCalibration,
    in_image,
    load_pinhole,
    load_tsai,
    pinhole_from_tsai,
    project_pinhole,
)
from ptztrack.occupancy.detectors import lpom_parameters
from ptztrack.occupancy.multiview import (
    CameraView,
    ImageFolder,
    MultiViewRecording,
    load_mot_detections,
    mot_truth,
    outside_area,
)
from ptztrack.occupancy.parameters import OccupancyParameters
from ptztrack.scene.pets import (
    FIT_BOX_HEIGHTS,
    Annotations,
    DatasetError,
    RecordedVideo,
    box_feet_px,
    load_mot_ground_truth,
    refuse_rows_beyond,
)

log = logging.getLogger(__name__)

FIT_FRAMES = 100
"""The frames that check looks at: people enough for a median, at a cost that does not grow with the
recording."""
FIT_PEOPLE = 20
"""The fewest projected people that median is taken over."""
AREA_SAMPLES = 256
"""Points per side of the grid on which a dataset's area is checked against its views."""


def _calibration(view: DatasetView, field: str) -> tuple[PinholeCalibration, tuple[int, int] | None]:
    """A view's calibration and image size: from a Tsai XML (checked against ``image_size_px``) or a
    pinhole JSON (with ``image_size_px``, if given)."""
    path = Path(view.calibration)
    if path.suffix.lower() != ".xml":
        return load_pinhole(path, view.calibration_view or view.name), view.image_size_px
    tsai = load_tsai(path)
    if view.image_size_px is not None and tuple(view.image_size_px) != tsai.image_size_px:
        width, height = tsai.image_size_px
        raise DatasetError(
            f"{path}: <Geometry width height> is {width}x{height} px, but {field}.image_size_px is "
            f"{view.image_size_px[0]}x{view.image_size_px[1]}"
        )
    return pinhole_from_tsai(tsai), tsai.image_size_px


def _frames(view: DatasetView, size_px: tuple[int, int] | None, field: str):
    """The view's frame source, its frame count and its image size (checked against the calibration's)."""
    if view.images is not None:
        folder = ImageFolder(view.images)
        first, count, path = folder.frame(0), len(folder), Path(folder.files[0])
    else:
        path = Path(str(view.video))
        video = RecordedVideo(path)
        first, count = video.frame(0), video.frame_count
    actual_px = (int(first.shape[1]), int(first.shape[0]))
    if size_px is not None and actual_px != tuple(size_px):
        raise DatasetError(
            f"{view.calibration}: {field}'s calibration is for {size_px[0]}x{size_px[1]} px images, "
            f"but {path} is {actual_px[0]}x{actual_px[1]} px"
        )
    source = (
        ImageFolder(view.images, actual_px).frame if view.images is not None else RecordedVideo(path, actual_px).frame
    )
    # Both detectors ask for each frame: keep the last two decoded.
    return functools.lru_cache(maxsize=2)(source), count, actual_px


def recording_from_dataset(dataset: MultiViewDataset, frames: int | None = None) -> MultiViewRecording:
    """The recording a dataset describes; ``frames`` (or the dataset's) caps how many frames are used.

    Without either, every frame that all views' videos or image folders have (or, without any, up to
    the last frame of the detection files). A view that sees none of the area is refused, and a part of
    the area that no view sees is warned of (:func:`_view_sees_area`, :func:`_warn_of_unseen_area`);
    so is ground truth that lies outside the area, all of it or some (:func:`_truth_outside_area`), and
    a view's detections that the ground truth, projected into it, misses (:func:`_calibration_misfit`).
    An occupancy map over it that would not fit is refused (:func:`refuse_if_map_too_large`).
    """
    loaded, seen = [], []
    area_mm = area_points_mm(dataset.area_m)
    for index, view in enumerate(dataset.views):
        field = f"views.{index}"
        calibration, size_px = _calibration(view, field)
        source, count = None, None
        if view.video is not None or view.images is not None:
            source, count, size_px = _frames(view, size_px, field)
        seen.append(_view_sees_area(view, field, calibration, size_px, area_mm))
        boxes = None if view.detections is None else load_mot_detections(view.detections, MAX_DATASET_FRAMES, size_px)
        loaded.append((view, calibration, size_px, source, count, boxes))
    counts = [count for *_, count, _ in loaded if count is not None]
    available = min(counts) if counts else max(len(boxes) for *_, boxes in loaded if boxes is not None)
    wanted = frames or dataset.frames or available
    if wanted > available:
        raise DatasetError(f"{dataset.name}: frames is {wanted}, but the views have only {available}")
    if wanted > MAX_DATASET_FRAMES:
        raise DatasetError(
            f"{dataset.name}: {wanted} frames; at most {MAX_DATASET_FRAMES} (memory: every frame's map and "
            "modes are kept): set frames"
        )
    views = tuple(
        CameraView(
            name=view.name,
            calibration=calibration,
            image_size_px=size_px,
            frames=source,
            boxes=None if boxes is None else (boxes + [np.zeros((0, 5))] * wanted)[:wanted],
            weight=view.weight,
        )
        for view, calibration, size_px, source, count, boxes in loaded
    )
    truth, warnings = None, []
    if dataset.ground_truth is not None:
        annotations = load_mot_ground_truth(dataset.ground_truth)
        # Without a video or an image folder, the recording is as long as its annotations say.
        recorded = available if counts else MAX_DATASET_FRAMES
        described = (
            f"the {available} frames of the views' videos and images"
            if counts
            else f"the {MAX_DATASET_FRAMES} frames a recording may have (memory)"
        )
        refuse_rows_beyond(dataset.ground_truth, annotations.frame, annotations.line, recorded, described)
        warnings.append(_truth_outside_area(dataset.ground_truth, annotations, wanted, dataset.area_m))
        warnings += [
            _calibration_misfit(view, f"views.{index}", calibration, size_px, boxes, annotations, wanted)
            for index, (view, calibration, size_px, _, _, boxes) in enumerate(loaded)
        ]
        truth = mot_truth(annotations, wanted, dataset.frame_rate_hz)
    area_m = np.asarray(dataset.area_m)
    recording = MultiViewRecording(dataset.name, views, wanted, dataset.frame_rate_hz, area_m, truth)
    # The experiment checks the map's cost of any recording; a dataset's is checked here too, so that
    # a refused dataset gets its one line alone: the warnings come last, after every error.
    refuse_if_map_too_large(recording, lpom_parameters(parameters_from(dataset.occupancy, OccupancyParameters)))
    _warn_of_unseen_area(dataset.name, area_mm, np.any(seen, axis=0))
    for warning in warnings:
        if warning is not None:
            log.warning(warning)
    return recording


def _truth_outside_area(path: str, annotations: Annotations, frames: int, area_m) -> str | None:
    """The ground truth's rows of the first ``frames`` frames against area_m: a :class:`DatasetError`
    if none lies in it (nothing could be scored: positions in other units or columns, or another
    area's), else a warning line naming the rows outside it (they are not scored), or None."""
    used = annotations.select(annotations.frame < frames)
    assert used.line is not None  # MOTChallenge rows have lines
    outside = outside_area(used.ground_m, area_m)
    if not outside.any():
        return None
    first = int(np.argmax(outside))
    (x_m, y_m), line = used.ground_m[first], used.line[first]
    (x0, y0), (x1, y1) = area_m
    area = f"area_m [[{x0:g}, {y0:g}], [{x1:g}, {y1:g}]]"
    if outside.all():
        raise DatasetError(
            f"{path}: no row of the {frames} frames used lies in {area} (line {line}: ({x_m:g}, {y_m:g}) m); "
            "expected world x, y in metres in columns 8-9"
        )
    return (
        f"{path}: {outside.sum()} of {len(outside)} rows of the {frames} frames used lie outside {area} and "
        f"are not scored (line {line}: ({x_m:g}, {y_m:g}) m)"
    )


def _calibration_misfit(
    view: DatasetView,
    field: str,
    calibration: PinholeCalibration,
    size_px: tuple[int, int] | None,
    boxes: list[np.ndarray] | None,
    annotations: Annotations,
    frames: int,
) -> str | None:
    """A warning line if a view's detections stand a median of more than ``FIT_BOX_HEIGHTS`` box heights
    from the ground truth's people projected into it: the calibration, most likely, is not this view's.

    Each frame's boxes and projected people are paired one to one at the least total distance
    (``scipy.optimize.linear_sum_assignment`` over the feet distances in each box's heights), so that
    the median is over the boxes that exist when a detector finds few of the people (only the nearest),
    and over the people when the boxes are many (people the annotators left out). Over the first
    ``FIT_FRAMES`` of the ``frames`` used, once ``FIT_PEOPLE`` pairs are made; else None."""
    if boxes is None or size_px is None:
        return None
    checked = min(frames, len(boxes), FIT_FRAMES)
    early = annotations.select(annotations.frame < checked)
    points_mm = np.c_[1000.0 * early.ground_m, np.zeros(len(early.frame))]
    seen = in_image(calibration, size_px, points_mm)
    feet_px, frame = project_pinhole(calibration, points_mm[seen]), early.frame[seen]
    misses = []
    for index in np.unique(frame):
        found = boxes[index]
        if len(found):
            box_heights = cdist(feet_px[frame == index], box_feet_px(found)) / found[:, 3]
            people, paired = linear_sum_assignment(box_heights)
            misses.append(box_heights[people, paired])
    pairs = sum(len(miss) for miss in misses)
    if pairs < FIT_PEOPLE:
        return None
    median = float(np.median(np.concatenate(misses)))
    if median <= FIT_BOX_HEIGHTS:
        return None
    return (
        f"{view.calibration}: {field} ({view.name}): its detections stand a median {median:.2g} box heights "
        f"from the ground truth's people projected into it ({pairs} pairs, first {checked} frames; expected under "
        f"{FIT_BOX_HEIGHTS:g}): is this the view's calibration?"
    )


def area_points_mm(area_m) -> np.ndarray:
    """The area [[x0, y0], [x1, y1]] m as AREA_SAMPLES x AREA_SAMPLES ground points (N, 3) mm, its
    edges included."""
    (x0, y0), (x1, y1) = area_m
    x_m, y_m = np.meshgrid(np.linspace(x0, x1, AREA_SAMPLES), np.linspace(y0, y1, AREA_SAMPLES))
    return np.stack([x_m.ravel(), y_m.ravel(), np.zeros(x_m.size)], axis=-1) * 1000.0


def _view_sees_area(
    view: DatasetView, field: str, calibration: PinholeCalibration, size_px: tuple[int, int] | None, area_mm
) -> np.ndarray:
    """Which of the area's points (N, 3) mm the view sees, (N,) bool; a :class:`DatasetError` naming the
    view if it sees none: all behind the camera (camera depth R p + t at most 0), or, with a known
    image size, all outside its image (:func:`~ptztrack.geometry.calibration.in_image`). Without an
    image size (a pinhole JSON, detections only) every point in front counts as seen."""
    label = f"{view.calibration}: {field} ({view.name}) sees none of area_m"
    ahead = area_mm @ calibration.R[2] + calibration.t[2] > 0
    if not ahead.any():
        raise DatasetError(f"{label}: the whole area is behind the camera")
    if size_px is None:
        return ahead
    seen = in_image(calibration, size_px, area_mm)
    if not seen.any():
        raise DatasetError(f"{label}: the whole area projects outside its {size_px[0]}x{size_px[1]} px image")
    return seen


def _warn_of_unseen_area(name: str, area_mm, seen) -> None:
    """A warning line if some of the area's points (N, 3) mm are seen by no view (``seen`` (N,) bool):
    their share and the box around them. Not an error: a dataset's area is a rectangle around where
    people walk, which its cameras rarely cover whole (people there can only be missed, and the
    scores show it); an area that no view sees at all never gets here, since every view must see
    some of it."""
    unseen_m = area_mm[~seen, :2] / 1000.0
    if len(unseen_m) == 0:
        return
    (x0, y0), (x1, y1) = unseen_m.min(axis=0), unseen_m.max(axis=0)
    log.warning(
        f"{name}: {len(unseen_m) / len(seen):.1%} of area_m is seen by no view (all of it within x "
        f"{x0:.1f} to {x1:.1f} m, y {y0:.1f} to {y1:.1f} m); people there can only be missed"
    )
