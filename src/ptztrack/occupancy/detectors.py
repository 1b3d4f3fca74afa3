"""People on the ground of a multi-view recording, frame by frame: the LPOM detector and the clustering baseline.

:class:`LpomDetector` builds each frame's occupancy map
(:mod:`ptztrack.occupancy.lpom`) from every view's motion pixels: motion
edges where the view has video (:func:`ptztrack.occupancy.motion_edges.motion_edges`,
against the previous frame), else the outlines of its detector's boxes.
:class:`LpomForegroundDetector` takes instead the edges of a background
model's foreground silhouettes (:mod:`ptztrack.occupancy.foreground`).
:class:`ClusteringDetector` clusters the views' box feet on the ground
(:mod:`ptztrack.occupancy.clustering`), with blob boxes for views that have
only video. Both are fed the frames in order.
"""

from dataclasses import dataclass

import numpy as np

from ptztrack.occupancy.clustering import BlobBoxes, Clusters, cluster_feet, grounded_feet, view_feet_on_ground
from ptztrack.occupancy.foreground import ViewForeground
from ptztrack.occupancy.locus import PERSON, ConeModel
from ptztrack.occupancy.lpom import (
    GroundGrid,
    LocusSampling,
    LocusTable,
    Modes,
    locus_table,
    map_modes,
    occupancy_map,
    points_map,
    sampled_heights,
    table_map,
)
from ptztrack.occupancy.motion_edges import box_outline_points, motion_edges
from ptztrack.occupancy.multiview import CameraView, MultiViewRecording
from ptztrack.occupancy.parameters import MotionEdgeParameters, OccupancyParameters


@dataclass(frozen=True)
class LpomParameters:
    """sampling : the person model and its heights; cell_m : the ground grid's cells;
    kernel_sigma_m : the density kernel; separation_m : the closest two modes may be;
    window_m : radius of the disc a mode's mean and covariance are taken over;
    candidate_strength : modes weaker than this fraction of the strongest are not even candidates;
    block_px : pixels per side of the blocks the locus tables are kept for;
    edges : the motion edges; outline_points_per_box : box outline points per box;
    min_box_score : boxes of lower score are ignored (by the baseline too)."""

    sampling: LocusSampling
    cell_m: float
    kernel_sigma_m: float
    separation_m: float
    window_m: float
    candidate_strength: float
    block_px: int
    edges: MotionEdgeParameters
    outline_points_per_box: int
    min_box_score: float


def lpom_parameters(parameters: OccupancyParameters) -> LpomParameters:
    """The occupancy map's parameters from the detector's (the person a cone of ``width_m``)."""
    model = ConeModel(PERSON.height_fraction, PERSON.radius_fraction, parameters.width_m)
    heights = sampled_heights(parameters.min_height_m, parameters.max_height_m, parameters.height_step_m)
    edges = MotionEdgeParameters(
        parameters.canny_low, parameters.canny_high, parameters.difference_threshold, parameters.dilation_px
    )
    return LpomParameters(
        sampling=LocusSampling(model, heights, parameters.samples_per_height),
        cell_m=parameters.cell_m,
        kernel_sigma_m=parameters.kernel_sigma_m,
        separation_m=parameters.separation_m,
        window_m=parameters.window_m,
        candidate_strength=parameters.candidate_strength,
        block_px=parameters.block_px,
        edges=edges,
        outline_points_per_box=parameters.outline_points_per_box,
        min_box_score=parameters.min_box_score,
    )


def scored_boxes(view: CameraView, frame: int, min_score: float) -> np.ndarray:
    """The view's boxes (K, 5) at ``frame`` with a score of at least ``min_score``."""
    assert view.boxes is not None
    boxes = view.boxes[frame]
    return boxes[boxes[:, 4] >= min_score]


class LpomDetector:
    """The occupancy map and its modes for each frame of ``recording``, in order (``detect(frame)``).

    The locus tables of the views with video are computed on construction (``tables``), unless
    another detector's of the same recording and parameters are given (they are read, never changed).
    """

    def __init__(
        self,
        recording: MultiViewRecording,
        parameters: LpomParameters,
        tables: dict[int, LocusTable] | None = None,
    ):
        self.recording, self.parameters = recording, parameters
        self.grid = GroundGrid.covering(recording.area_m, parameters.cell_m)
        self.tables: dict[int, LocusTable] = (
            tables
            if tables is not None
            else {
                index: locus_table(
                    view.calibration, view.image_size_px, self.grid, parameters.sampling, parameters.block_px
                )
                for index, view in enumerate(recording.views)
                if view.frames is not None
            }
        )
        self._previous: dict[int, tuple[int, np.ndarray]] = {}

    def view_loci(self, index: int, frame: int) -> np.ndarray:
        """The summed loci (cells,) of view ``index`` at ``frame``."""
        view, parameters = self.recording.views[index], self.parameters
        if view.frames is None:
            outline = box_outline_points(
                scored_boxes(view, frame, parameters.min_box_score)[:, :4], parameters.outline_points_per_box
            )
            return points_map(view.calibration, outline, self.grid, parameters.sampling)
        pixels = self.motion_pixels(index, frame)
        if pixels is None:
            return np.zeros(self.grid.cells)
        return table_map(self.tables[index], pixels)

    def motion_pixels(self, index: int, frame: int) -> np.ndarray | None:
        """The motion edges (height, width) bool of view ``index`` (one with video) at ``frame``, against
        the frame before; None on the first frame or after a jump (no motion to see)."""
        frames = self.recording.views[index].frames
        assert frames is not None
        image = frames(frame)
        previous_frame, previous = self._previous.get(index, (-1, image))
        self._previous[index] = (frame, image)
        if previous_frame != frame - 1:
            return None
        return motion_edges(previous, image, self.parameters.edges)

    def detect(self, frame: int) -> tuple[np.ndarray, Modes]:
        """The occupancy map (rows, columns) at ``frame`` and its candidate modes."""
        parameters = self.parameters
        loci = [self.view_loci(index, frame) for index in range(len(self.recording.views))]
        weights = [view.weight for view in self.recording.views]
        pom = occupancy_map(loci, weights, self.grid, parameters.kernel_sigma_m)
        modes = map_modes(pom, self.grid, parameters.separation_m, parameters.window_m, parameters.candidate_strength)
        return pom, modes


class LpomForegroundDetector(LpomDetector):
    """LPOM whose video views' pixels are the edges of their foreground silhouettes, not motion edges.

    Each view with video has a background model (:class:`~ptztrack.occupancy.foreground.ViewForeground`,
    learned online on the frames before each), whose silhouettes' boundary pixels feed the view's loci;
    views without video give their boxes' outlines, as in :class:`LpomDetector`, and the map and its
    modes are :class:`LpomDetector`'s.

    Parameters
    ----------
    recording : the views, their frames or boxes.
    parameters : the map's (its ``edges``, the motion edges' settings, go unused).
    foregrounds : the views' background models by view index
        (:func:`~ptztrack.occupancy.foreground.view_foregrounds`, shared with other methods).
    tables : the locus tables of an :class:`LpomDetector` of the same recording and parameters.
    """

    def __init__(
        self,
        recording: MultiViewRecording,
        parameters: LpomParameters,
        foregrounds: dict[int, ViewForeground],
        tables: dict[int, LocusTable] | None = None,
    ):
        super().__init__(recording, parameters, tables)
        self.foreground = foregrounds

    def motion_pixels(self, index: int, frame: int) -> np.ndarray | None:
        """The edges (height, width) bool of view ``index``'s silhouettes at ``frame`` (none on frame 0)."""
        return self.foreground[index].edges(frame)


class ClusteringDetector:
    """The baseline's clusters for each frame of ``recording``, in order (``detect(frame)``).

    linkage_m : the clustering's cut; min_box_score : as LPOM's; blob_min_area_px : the blob
    boxes' smallest region, for views without a detector's boxes. The blob boxes' background models
    learn the recording's lead-in frames on construction, as the other methods' do before frame 0.
    """

    def __init__(self, recording: MultiViewRecording, linkage_m: float, min_box_score: float, blob_min_area_px: int):
        self.recording, self.linkage_m, self.min_box_score = recording, linkage_m, min_box_score
        self.blobs = {
            index: BlobBoxes(blob_min_area_px) for index, view in enumerate(recording.views) if view.boxes is None
        }
        for index, blobs in self.blobs.items():
            frames = recording.views[index].frames
            assert frames is not None
            for frame in range(-recording.lead_in_frames, 0):
                blobs.learn(frames(frame))

    def detect(self, frame: int) -> Clusters:
        ground, views = [], []
        for index, view in enumerate(self.recording.views):
            if view.boxes is not None:
                feet_m = view_feet_on_ground(view, frame, self.min_box_score)
            else:
                assert view.frames is not None
                feet_m = grounded_feet(view.calibration, self.blobs[index].boxes(view.frames(frame)))
            ground.append(feet_m)
            views.append(np.full(len(feet_m), index))
        return cluster_feet(np.concatenate(ground), np.concatenate(views), self.linkage_m)
