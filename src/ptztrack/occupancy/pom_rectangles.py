"""The POM's working resolution: each cell's person rectangle in each view, and the views' masks.

A person is a vertical cylinder ``height_m`` tall and ``width_m`` across standing on a cell's centre; its
rectangle ``A_k^c`` in view ``c`` bounds the cylinder's projection through the view's calibration
(:func:`person_box_px`, (left, top, right, bottom) px), snapped to blocks of ``block_px`` pixels
(:class:`PersonBoxes`, (views, cells, 4) blocks). A mask is averaged over the same blocks, a fraction of
foreground per block (:func:`working_mask`). A view without video gets the union of its detector's boxes
as its mask (:func:`boxes_mask`), and its rectangles may be scaled about their feet to the size its
detector draws a person (:func:`fitted_box_scales`, (views, 2) width and height factors).
"""

from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np
from scipy.optimize import linear_sum_assignment
from scipy.spatial.distance import cdist

from ptztrack.geometry.calibration import PinholeCalibration, imaged_radius, project_pinhole
from ptztrack.occupancy.lpom import GroundGrid
from ptztrack.occupancy.multiview import MultiViewRecording
from ptztrack.occupancy.parameters import PomParameters
from ptztrack.scene.pets import box_feet_px

RIM_POINTS = (
    64  # points around each of the cylinder's circles (the bound is short by r (1 - cos(pi / 64)), 0.3 mm at 0.25 m)
)
RIM_LEVELS = 5  # circles from the feet to the top of the head (a distorting lens bends the sides)
MIN_DEPTH_M = 0.01  # a person's point closer to the camera's plane than this: no rectangle


BOX_CHUNK_CELLS = 1024
# A view's box scales (:func:`fitted_box_scales`): a box is a person's when its feet lie within a quarter
# of the model box's height of the model's (a person's width, so two people side by side are told
# apart), and a view's scales need some matches to be more than one person's.
SCALE_GATE_HEIGHTS = 0.25
MIN_SCALE_MATCHES = 20
UNMATCHED_PX = 1e9


def person_box_px(calibration: PinholeCalibration, ground_m, height_m: float, width_m: float) -> np.ndarray:
    """The image bounding box of a person standing at each ground point: (K, 4) (left, top, right, bottom) px.

    The person is a vertical cylinder ``height_m`` tall and ``width_m`` across, standing on the ground
    point (K, 2) m; the box bounds the projections (through the calibration, lens distortion included)
    of ``RIM_LEVELS`` circles of ``RIM_POINTS`` points from its base to its top. NaN where a point of the
    cylinder is not in front of the camera (the projection has no bound) or lies beyond the radius where
    the lens's distortion folds back (:func:`~ptztrack.geometry.calibration.imaged_radius`; its projection
    would land anywhere, the image's middle included).
    """
    folding_radius = imaged_radius(calibration)
    ground_m = np.asarray(ground_m, dtype=float).reshape(-1, 2)
    angle = np.linspace(0.0, 2 * np.pi, RIM_POINTS, endpoint=False)
    ring = 0.5 * width_m * np.stack([np.cos(angle), np.sin(angle), np.zeros_like(angle)], axis=-1)
    levels = np.linspace(0.0, height_m, RIM_LEVELS)[:, None, None] * np.array([0.0, 0.0, 1.0])
    offsets_m = (ring[None, :, :] + levels).reshape(-1, 3)  # (RIM_LEVELS * RIM_POINTS, 3)
    boxes = np.empty((len(ground_m), 4))
    # In chunks of cells: a large area's points would otherwise take gigabytes at once.
    for start in range(0, len(ground_m), BOX_CHUNK_CELLS):
        chunk = ground_m[start : start + BOX_CHUNK_CELLS]
        feet_m = np.concatenate([chunk, np.zeros((len(chunk), 1))], axis=-1)
        points_m = feet_m[:, None, :] + offsets_m[None, :, :]
        camera_m = points_m @ calibration.R.T + calibration.t / 1000.0
        depth_m = camera_m[..., 2]
        ahead = depth_m > MIN_DEPTH_M
        radius = np.hypot(camera_m[..., 0], camera_m[..., 1]) / np.where(ahead, depth_m, 1.0)
        projected = np.all(ahead & (radius < folding_radius), axis=1)
        pixels = project_pinhole(calibration, 1000.0 * points_m.reshape(-1, 3)).reshape(len(chunk), -1, 2)
        box = np.concatenate([pixels.min(axis=1), pixels.max(axis=1)], axis=-1)
        boxes[start : start + len(chunk)] = np.where(projected[:, None], box, np.nan)
    return boxes


def covered_span(low, high) -> tuple[np.ndarray, np.ndarray]:
    """The pixels (or blocks) ``[first, stop)`` whose centres ``i + 0.5`` lie in ``[low, high)`` (unit-sized)."""
    return np.ceil(np.asarray(low) - 0.5).astype(np.int64), np.ceil(np.asarray(high) - 0.5).astype(np.int64)


@dataclass(frozen=True)
class PersonBoxes:
    """Each cell's person rectangle in each view, at the working resolution.

    boxes : (views, cells, 4) int32 (left, top, right, bottom) in blocks, the rectangle covering blocks
    ``[left, right) x [top, bottom)``; visible : (views, cells) bool, whether the cell has a rectangle in
    the view (not behind the camera, not wholly outside its image); shapes : per view, the working image's
    (rows, columns); block_px : pixels per block side.
    """

    boxes: np.ndarray
    visible: np.ndarray
    shapes: tuple[tuple[int, int], ...]
    block_px: int


def person_boxes(
    views: Sequence[tuple[PinholeCalibration, tuple[int, int]]],
    grid: GroundGrid,
    height_m: float,
    width_m: float,
    block_px: int,
    box_scales=None,
) -> PersonBoxes:
    """:class:`PersonBoxes` of the grid's cells in views given as (calibration, image size (width, height) px).

    A rectangle covers the blocks whose centres lie in the person's box (:func:`person_box_px`, scaled
    by :func:`scaled_about_feet` with the view's row of ``box_scales`` (views, 2), ones where not given),
    clipped to the working image of ``(height // block_px, width // block_px)`` blocks.
    """
    boxes_px = cell_boxes_px([calibration for calibration, _ in views], grid, height_m, width_m)
    return blocked_boxes(boxes_px, [size_px for _, size_px in views], block_px, box_scales)


def cell_boxes_px(
    calibrations: Sequence[PinholeCalibration], grid: GroundGrid, height_m: float, width_m: float
) -> list[np.ndarray]:
    """Per view, the :func:`person_box_px` (cells, 4) of a person standing at each of the grid's cell centres."""
    rows, columns = np.mgrid[0 : grid.shape[0], 0 : grid.shape[1]]
    centres_m = grid.centre_of(rows.ravel(), columns.ravel())
    return [person_box_px(calibration, centres_m, height_m, width_m) for calibration in calibrations]


def scaled_about_feet(boxes_px, scale) -> np.ndarray:
    """Boxes (K, 4) (left, top, right, bottom) px scaled about their feet (the bottom centre) by
    ``scale`` (width factor, height factor): the bottom centre stays, the width and height are multiplied."""
    boxes_px = np.asarray(boxes_px, dtype=float)
    width_scale, height_scale = scale
    centre_px = 0.5 * (boxes_px[:, 0] + boxes_px[:, 2])
    half_width_px = 0.5 * width_scale * (boxes_px[:, 2] - boxes_px[:, 0])
    bottom_px = boxes_px[:, 3]
    top_px = bottom_px - height_scale * (bottom_px - boxes_px[:, 1])
    return np.stack([centre_px - half_width_px, top_px, centre_px + half_width_px, bottom_px], axis=-1)


def blocked_boxes(boxes_px: Sequence[np.ndarray], sizes_px, block_px: int, box_scales=None) -> PersonBoxes:
    """:class:`PersonBoxes` from each view's person boxes (cells, 4) px (:func:`person_box_px`, NaN where
    the cell has none) and image size (width, height) px, each view's boxes scaled about their feet by
    its row of ``box_scales`` (views, 2) (width factor, height factor; ones where not given)."""
    scales = np.ones((len(boxes_px), 2)) if box_scales is None else np.asarray(box_scales, dtype=float)
    boxes, visible, shapes = [], [], []
    for box_px, (width_px, height_px), scale in zip(boxes_px, sizes_px, scales, strict=True):
        shape = (height_px // block_px, width_px // block_px)
        seen = ~np.isnan(box_px[:, 0])
        # Clipped to just outside the image before the blocks' integers: a strong distortion sends far
        # points beyond int64's range.
        limit_px = np.array([width_px, height_px, width_px, height_px]) + block_px
        box_px = np.clip(np.where(seen[:, None], scaled_about_feet(box_px, scale), 0.0), -block_px, limit_px)
        left, right = covered_span(box_px[:, 0] / block_px, box_px[:, 2] / block_px)
        top, bottom = covered_span(box_px[:, 1] / block_px, box_px[:, 3] / block_px)
        box = np.stack(
            [
                np.clip(left, 0, shape[1]),
                np.clip(top, 0, shape[0]),
                np.clip(right, 0, shape[1]),
                np.clip(bottom, 0, shape[0]),
            ],
            axis=-1,
        )
        seen &= (box[:, 2] > box[:, 0]) & (box[:, 3] > box[:, 1])
        boxes.append(np.where(seen[:, None], box, 0).astype(np.int32))
        visible.append(seen)
        shapes.append(shape)
    return PersonBoxes(np.stack(boxes), np.stack(visible), tuple(shapes), block_px)


def boxes_mask(boxes, image_size_px, min_score: float) -> np.ndarray:
    """The union of a detector's boxes (K, 5) (left, top, width, height, score) px whose score is at least
    ``min_score``, as a (height, width) bool mask of the pixels whose centres they hold."""
    width_px, height_px = image_size_px
    mask = np.zeros((height_px, width_px), bool)
    boxes = np.asarray(boxes, dtype=float).reshape(-1, 5)
    boxes = boxes[boxes[:, 4] >= min_score]
    left, right = covered_span(boxes[:, 0], boxes[:, 0] + boxes[:, 2])
    top, bottom = covered_span(boxes[:, 1], boxes[:, 1] + boxes[:, 3])
    for x0, y0, x1, y1 in zip(left, top, right, bottom, strict=True):
        mask[max(y0, 0) : max(y1, 0), max(x0, 0) : max(x1, 0)] = True
    return mask


def working_mask(mask, block_px: int) -> np.ndarray:
    """The fraction of foreground (rows // block_px, columns // block_px) float32 in each block of a
    (rows, columns) mask (bool or 0/1; the last partial blocks are dropped)."""
    rows, columns = mask.shape[0] // block_px, mask.shape[1] // block_px
    cropped = np.asarray(mask[: rows * block_px, : columns * block_px], dtype=np.float32)
    # Area interpolation by a whole factor is the blocks' mean (OpenCV's is some ten times NumPy's speed).
    return cv2.resize(cropped, (columns, rows), interpolation=cv2.INTER_AREA)


def fitted_box_scales(recording: MultiViewRecording, truth_m, frames, parameters: PomParameters, views) -> np.ndarray:
    """How much wider and taller than a person's rectangle each view's detector draws its boxes: (views, 2)
    (width factor, height factor), ones for the views not in ``views`` or with fewer than
    ``MIN_SCALE_MATCHES`` matches.

    For each annotated person of ``frames`` (truth_m (T, N, 2) m, NaN where absent) seen by a view in
    ``views``, the model's box (:func:`person_box_px`, ``height_m`` by ``width_m``) is matched one to one
    (Hungarian, per frame) to the view's boxes of at least ``min_box_score`` by the distance between
    their feet (bottom centres), within ``SCALE_GATE_HEIGHTS`` of the model box's height; a factor is the
    median over the matches of the box's width (height) over the model box's. It takes up what the
    calibration and the detector make of a person that the cylinder does not: a focal length or a
    distance a few per cent off, a detector's box around the arms.
    """
    truth_m = np.asarray(truth_m, dtype=float)
    scales = np.ones((len(recording.views), 2))
    for index in views:
        view = recording.views[index]
        assert view.boxes is not None
        ratios = []
        for frame in frames:
            people_m = truth_m[frame][~np.isnan(truth_m[frame][:, 0])]
            found = view.boxes[frame][view.boxes[frame][:, 4] >= parameters.min_box_score]
            model = person_box_px(view.calibration, people_m, parameters.height_m, parameters.width_m)
            model = model[~np.isnan(model[:, 0])]
            if len(model) == 0 or len(found) == 0:
                continue
            model_feet = np.stack([0.5 * (model[:, 0] + model[:, 2]), model[:, 3]], axis=-1)
            found_feet = box_feet_px(found)
            model_height = model[:, 3] - model[:, 1]
            distance_px = cdist(model_feet, found_feet)
            allowed = distance_px <= SCALE_GATE_HEIGHTS * model_height[:, None]
            rows, columns = linear_sum_assignment(np.where(allowed, distance_px, UNMATCHED_PX))
            keep = allowed[rows, columns]
            rows, columns = rows[keep], columns[keep]
            ratios.append(
                np.stack(
                    [found[columns, 2] / (model[rows, 2] - model[rows, 0]), found[columns, 3] / model_height[rows]],
                    axis=-1,
                )
            )
        matched = np.concatenate(ratios) if ratios else np.zeros((0, 2))
        if len(matched) >= MIN_SCALE_MATCHES:
            scales[index] = np.median(matched, axis=0)
    return scales
