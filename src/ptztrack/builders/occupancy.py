"""The occupancy-map experiment's inputs: a dataset file, the synthetic room or the synthetic plaza made into a
:class:`~ptztrack.occupancy.multiview.MultiViewRecording`."""

import functools
import logging
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from scipy.optimize import linear_sum_assignment
from scipy.spatial.distance import cdist

from ptztrack.builders.budget import available_memory_bytes
from ptztrack.builders.parameters import parameters_from
from ptztrack.config import MAX_DATASET_FRAMES, DatasetView, MultiViewDataset, pets_dataset
from ptztrack.geometry.calibration import (
    PinholeCalibration,
    in_image,
    load_pinhole,
    load_tsai,
    pinhole_from_tsai,
    project_pinhole,
)
from ptztrack.occupancy.detectors import LpomParameters, lpom_parameters
from ptztrack.occupancy.lpom import GroundGrid, disc_reach, kernel_reach, most_modes
from ptztrack.occupancy.multiview import (
    CameraView,
    ImageFolder,
    MultiViewRecording,
    load_mot_detections,
    mot_truth,
    outside_area,
)
from ptztrack.occupancy.parameters import ForegroundParameters, OccupancyParameters
from ptztrack.occupancy.plaza import PlazaLayout, plaza_stage, plaza_truth
from ptztrack.occupancy.room import RoomLayout, RoomRenderer, room_truth
from ptztrack.scene.pets import (
    FIT_BOX_HEIGHTS,
    Annotations,
    DatasetError,
    RecordedVideo,
    box_feet_px,
    load_mot_ground_truth,
    refuse_rows_beyond,
)
from ptztrack.scene.render import SceneRenderer

log = logging.getLogger(__name__)

# What the occupancy map's parts cost, measured on this code (maps of 180 to 1500 cells a side):
# the loci of points off the tables' grid (a box's outline), per locus point (60-210 ns, 66-79
# bytes: its position, weight, cell and their temporaries, all of a view's points at once);
# SciPy's Gaussian filter per cell and kernel tap, both passes counted (0.23-0.37 ns with long
# kernels); its maximum filter per cell and cell of the separation disc's square (0.38-0.48 ns);
# map_modes' windows per mode and cell of a window's square (110-250 ns, 52-80 bytes); building a
# disc: two int64 offset grids, their float64 distances and a bool per cell of its square.
LOCUS_S_PER_POINT = 200e-9
LOCUS_BYTES_PER_POINT = 80.0
SMOOTHING_S_PER_CELL_TAP = 0.4e-9
MAXIMA_S_PER_CELL_OFFSET = 0.5e-9
WINDOW_S_PER_MODE_CELL = 250e-9
WINDOW_BYTES_PER_MODE_CELL = 80.0
DISC_BYTES_PER_CELL = 25.0
FRAME_S_MAX = 2.0
"""The longest a frame's map and its modes may take: SciPy's filters and NumPy's sums see Ctrl-C only
once they end, and a recording has hundreds of frames."""
FIT_FRAMES = 100
"""The frames that check looks at: people enough for a median, at a cost that does not grow with the
recording."""
FIT_PEOPLE = 20
"""The fewest projected people that median is taken over."""
ROOM_AREA_M = ((0.0, 0.0), (5.0, 6.0))
AREA_SAMPLES = 256
"""Points per side of the grid on which a dataset's area is checked against its views."""
PLAZA_WALKED_PERCENT = 90.0
"""The share of S2.L1's annotated positions, along each axis, inside the plaza's area (a priori: the
band people walk in, without the few positions in the corners)."""
PLAZA_LEAD_IN_FRAMES = ForegroundParameters().history // 2
"""The plaza's lead-in, rendered before its first frame for the background models alone (a priori: the
frames after which MOG2's learning rate, ``1 / min(2 n, history)``, has reached its steady ``1 / history``)."""
# 20 s at 15 Hz per sequence (the paper's were 3.5 and 7 minutes long).
ROOM = RoomLayout()


def locus_table_bytes(recording: MultiViewRecording, parameters: LpomParameters) -> float:
    """An upper bound on the locus tables' memory: 8 bytes (a float32 value and its int32 column) for
    each block's points, two per tangent height and person height (the room's four views: 300 MB
    estimated, 78 MB measured, as points that fall in one cell are summed)."""
    sampling = parameters.sampling
    points_per_block = 2 * len(sampling.heights_m) * sampling.samples_per_height
    blocks = sum(
        (view.image_size_px[0] // parameters.block_px) * (view.image_size_px[1] // parameters.block_px)
        for view in recording.views
        if view.frames is not None and view.image_size_px is not None
    )
    return 8.0 * points_per_block * blocks


@dataclass(frozen=True)
class Cost:
    """What one part of the occupancy map costs: ``amount`` (bytes or seconds), ``what`` it is, and
    which parameters make it ``smaller``."""

    amount: float
    what: str
    smaller: str


def outline_loci(recording: MultiViewRecording, parameters: LpomParameters) -> list[int]:
    """Per view whose loci come from its boxes' outlines (a view without frames), the most locus points
    a frame of it has: two per outline point (``outline_points_per_box`` per box of at least
    ``min_box_score``), person height and tangent height."""
    sampling = parameters.sampling
    per_ray = 2 * len(sampling.heights_m) * sampling.samples_per_height
    return [
        per_ray
        * parameters.outline_points_per_box
        * max(int(np.sum(boxes[:, 4] >= parameters.min_box_score)) for boxes in view.boxes)
        for view in recording.views
        if view.frames is None and view.boxes is not None
    ]


def _outline_sampling(parameters: LpomParameters) -> str:
    sampling = parameters.sampling
    return (
        f"{parameters.outline_points_per_box} points a box, {len(sampling.heights_m)} heights of "
        f"{sampling.samples_per_height} samples"
    )


def memory_costs(recording: MultiViewRecording, parameters: LpomParameters) -> list[Cost]:
    """The occupancy map's estimated peak memory over ``recording``, in bytes, by part."""
    grid = GroundGrid.covering(recording.area_m, parameters.cell_m)
    separation = 2 * disc_reach(parameters.separation_m, parameters.cell_m) + 1
    window = 2 * disc_reach(parameters.window_m, parameters.cell_m) + 1
    modes = most_modes(grid, parameters.separation_m)
    return [
        Cost(
            locus_table_bytes(recording, parameters),
            "the locus tables",
            "make occupancy.block_px larger or samples_per_height smaller",
        ),
        Cost(
            LOCUS_BYTES_PER_POINT * max(outline_loci(recording, parameters), default=0),
            f"the loci of a frame's box outlines ({_outline_sampling(parameters)})",
            "make occupancy.outline_points_per_box or samples_per_height smaller",
        ),
        Cost(
            float(recording.frames * grid.cells),
            f"the maps of {recording.frames} frames of {grid.cells} cells, kept",
            "use fewer frames or a larger occupancy.cell_m",
        ),
        Cost(
            DISC_BYTES_PER_CELL * separation**2,
            f"occupancy.separation_m {parameters.separation_m:g} m's disc of {separation} x {separation} cells",
            "make separation_m smaller or cell_m larger",
        ),
        Cost(
            (DISC_BYTES_PER_CELL + WINDOW_BYTES_PER_MODE_CELL * modes) * window**2,
            f"occupancy.window_m {parameters.window_m:g} m's windows of {window} x {window} cells, for up to "
            f"{modes} modes",
            "make window_m smaller or cell_m larger",
        ),
    ]


def frame_costs(recording: MultiViewRecording, parameters: LpomParameters) -> list[Cost]:
    """The estimated time of a frame's map and its modes over ``recording``, in seconds, by part."""
    grid = GroundGrid.covering(recording.area_m, parameters.cell_m)
    taps = 2 * kernel_reach(parameters.kernel_sigma_m, parameters.cell_m) + 1
    separation = 2 * disc_reach(parameters.separation_m, parameters.cell_m) + 1
    window = 2 * disc_reach(parameters.window_m, parameters.cell_m) + 1
    modes = most_modes(grid, parameters.separation_m)
    return [
        Cost(
            LOCUS_S_PER_POINT * sum(outline_loci(recording, parameters)),
            f"the loci of its box outlines ({_outline_sampling(parameters)})",
            "make occupancy.outline_points_per_box or samples_per_height smaller",
        ),
        Cost(
            SMOOTHING_S_PER_CELL_TAP * grid.cells * 2 * taps,
            f"occupancy.kernel_sigma_m {parameters.kernel_sigma_m:g} m's smoothing, a kernel of {taps} cells a side",
            "make kernel_sigma_m smaller or cell_m larger",
        ),
        Cost(
            MAXIMA_S_PER_CELL_OFFSET * grid.cells * separation**2,
            f"occupancy.separation_m {parameters.separation_m:g} m's maxima over {separation} x {separation} cells",
            "make separation_m smaller or cell_m larger",
        ),
        Cost(
            WINDOW_S_PER_MODE_CELL * modes * window**2,
            f"occupancy.window_m {parameters.window_m:g} m's windows of {window} x {window} cells, for up to "
            f"{modes} modes",
            "make window_m smaller or cell_m larger",
        ),
    ]


def refuse_if_map_too_large(
    recording: MultiViewRecording, parameters: LpomParameters, available_bytes: float | None = None
) -> None:
    """A :class:`DatasetError` before any work if the occupancy map over ``recording`` would need more
    memory than is available (``available_bytes``, by default what the machine has free now,
    :func:`memory_costs`) or a frame would take longer than ``FRAME_S_MAX`` (:func:`frame_costs`);
    the line names the largest part and the parameters that make it smaller."""
    memory = memory_costs(recording, parameters)
    needed = sum(cost.amount for cost in memory)
    available = available_memory_bytes() if available_bytes is None else available_bytes
    if needed > available:
        largest = max(memory, key=lambda cost: cost.amount)
        raise DatasetError(
            f"{recording.name}: the occupancy map needs an estimated {needed / 1e9:.3g} GB, more than the "
            f"{available / 1e9:.3g} GB available, most of it for {largest.what}: {largest.smaller}"
        )
    frame = frame_costs(recording, parameters)
    seconds = sum(cost.amount for cost in frame)
    if seconds > FRAME_S_MAX:
        largest = max(frame, key=lambda cost: cost.amount)
        raise DatasetError(
            f"{recording.name}: a frame's occupancy map would take an estimated {seconds:.3g} s, at most "
            f"{FRAME_S_MAX:g} s (Ctrl-C waits for it), most of it for {largest.what}: {largest.smaller}"
        )


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


def room_recording(people: int, frames: int, seed: int, layout: RoomLayout = ROOM) -> MultiViewRecording:
    """The synthetic room with ``people`` walking for ``frames`` frames, rendered on demand."""
    renderer = RoomRenderer(layout, room_truth(layout, people, frames, seed), seed)
    names = [f"camera_{index + 1}" for index in range(len(renderer.cameras))]
    return rendered_recording(f"room-{people}", names, renderer, ROOM_AREA_M, layout.frame_rate_hz)


def plaza_layout() -> PlazaLayout:
    """The plaza where the built-in PETS 2009 S2.L1 dataset's people walk, at its frame rate.

    The area is the central ``PLAZA_WALKED_PERCENT`` of S2.L1's annotated ground positions along each
    axis: its annotators marked the people View_001 sees, who walk in a band that three to seven of the
    seven views see; the dataset's whole area reaches corners that one view sees, or none.
    """
    pets = pets_dataset()
    assert pets.ground_truth is not None  # the built-in dataset has its annotations
    positions_m = load_mot_ground_truth(pets.ground_truth).ground_m
    tail = (100.0 - PLAZA_WALKED_PERCENT) / 2
    low_m, high_m = np.percentile(positions_m, [tail, 100.0 - tail], axis=0)
    area_m = ((float(low_m[0]), float(low_m[1])), (float(high_m[0]), float(high_m[1])))
    return PlazaLayout(area_m=area_m, frame_rate_hz=pets.frame_rate_hz)


def plaza_renderer(people: int, frames: int, seed: int) -> SceneRenderer:
    """The synthetic plaza's renderer (:mod:`ptztrack.occupancy.plaza`): PETS 2009 S2.L1's seven views
    (the built-in dataset's, in its order), each through its official Tsai calibration
    (``View_00N.xml`` beside the dataset file, which states the image size: 768 x 576 or 720 x 576 px),
    watching ``people`` walk for ``frames`` frames."""
    layout = plaza_layout()
    cameras, sizes_px = [], []
    for view in pets_dataset().views:
        tsai = load_tsai(Path(view.calibration).with_name(f"{view.name}.xml"))
        cameras.append(pinhole_from_tsai(tsai))
        sizes_px.append(tsai.image_size_px)
    truth = plaza_truth(layout, people, frames, seed)
    return SceneRenderer(cameras, sizes_px, plaza_stage(layout, cameras), truth, seed)


def plaza_recording(
    people: int, frames: int, seed: int, lead_in_frames: int = PLAZA_LEAD_IN_FRAMES
) -> MultiViewRecording:
    """The synthetic plaza with ``people`` walking for ``frames`` frames at PETS's frame rate over its
    area, rendered on demand (:func:`plaza_renderer`); every view has frames and no detector's boxes.

    The walk starts ``lead_in_frames`` frames before the first frame: the recording's lead-in, which the
    background models learn and nothing scores (a fixed camera has watched its scene before any frame a
    table counts)."""
    layout = plaza_layout()
    names = [view.name for view in pets_dataset().views]
    renderer = plaza_renderer(people, lead_in_frames + frames, seed)
    return rendered_recording(f"plaza-{people}", names, renderer, layout.area_m, layout.frame_rate_hz, lead_in_frames)


def rendered_recording(
    name: str, view_names: list[str], renderer: SceneRenderer, area_m, frame_rate_hz: float, lead_in_frames: int = 0
) -> MultiViewRecording:
    """The recording of a renderer's views (named ``view_names``), its frames rendered on demand, every
    frame of its truth after the first ``lead_in_frames`` (the recording's lead-in: its frames -lead_in_frames
    to -1); area_m : [[x0, y0], [x1, y1]] the ground scored."""
    views = tuple(
        CameraView(view_name, camera, size_px, _view_frames(renderer, index, lead_in_frames), None)
        for index, (view_name, camera, size_px) in enumerate(
            zip(view_names, renderer.cameras, renderer.image_sizes_px, strict=True)
        )
    )
    truth = replace(renderer.truth, positions_m=renderer.truth.positions_m[lead_in_frames:])
    return MultiViewRecording(
        name, views, truth.positions_m.shape[0], frame_rate_hz, np.asarray(area_m), truth, lead_in_frames
    )


def _view_frames(renderer: SceneRenderer, view: int, lead_in_frames: int) -> Callable[[int], np.ndarray]:
    """The view's frames from ``-lead_in_frames``, the last two kept: both detectors ask for each frame, LPOM
    for the one before too."""
    image = functools.lru_cache(maxsize=2)(functools.partial(renderer.image, view))
    return lambda frame: image(frame + lead_in_frames)
