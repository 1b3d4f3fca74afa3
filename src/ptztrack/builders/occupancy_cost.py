"""What an occupancy map over a recording would cost, estimated before any work is done.

Its peak memory (bytes: the locus tables, the loci of a frame's box outlines, every frame's map, the
separation disc, the modes' windows) and a frame's time (seconds: the outline loci, the smoothing, the
maxima, the windows), each as :class:`Cost` parts computed from the recording's views and the map's
parameters with coefficients measured on this code; :func:`refuse_if_map_too_large` refuses a map beyond
the memory free or ``FRAME_S_MAX`` a frame, naming its largest part and the parameters that shrink it.
"""

from dataclasses import dataclass

import numpy as np

from ptztrack.builders.budget import available_memory_bytes
from ptztrack.occupancy.detectors import LpomParameters
from ptztrack.occupancy.lpom import GroundGrid, disc_reach, kernel_reach, most_modes
from ptztrack.occupancy.multiview import MultiViewRecording
from ptztrack.scene.pets import DatasetError

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
