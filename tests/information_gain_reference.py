"""Plain NumPy references for the information-gain rewards (paper equations 7, 8, 9 and 19).

For now the occluded fraction only, measured by cutting every box along the
edges of all the others: the tests check the kernel against it.
"""

import numpy as np


def occluded_fraction_by_cells(box_px, depth_m, valid) -> np.ndarray:
    """:func:`ptztrack.geometry.occlusion.occluded_fraction` with every box cut along the edges of all others.

    box_px : (..., N, 4); depth_m, valid : (..., N). Each target box is cut
    along the clipped edges of all N boxes (those that do not hide it
    collapse to a point) into (2N - 1)^2 cells, and a cell counts when its
    centre lies in a nearer, valid box: O(N^4) per frame.
    """
    box_px = np.asarray(box_px, dtype=float)
    depth_m = np.asarray(depth_m, dtype=float)
    valid = np.asarray(valid, dtype=bool)
    count = box_px.shape[-2]
    target = box_px[..., :, None, :]
    occluder = box_px[..., None, :, :]
    occludes = (
        valid[..., None, :]
        & valid[..., :, None]
        & (depth_m[..., None, :] < depth_m[..., :, None])
        & ~np.eye(count, dtype=bool)
    )
    low = np.maximum(occluder[..., :2], target[..., :2])
    high = np.minimum(occluder[..., 2:], target[..., 2:])
    high = np.where(occludes[..., None], np.maximum(high, low), low)

    def cells(axis):
        edges = np.sort(np.concatenate([low[..., axis], high[..., axis]], axis=-1), axis=-1)
        return 0.5 * (edges[..., 1:] + edges[..., :-1]), np.diff(edges, axis=-1)

    mid_x, width_x = cells(0)
    mid_y, width_y = cells(1)
    inside_x = (low[..., None, :, 0] <= mid_x[..., :, None]) & (mid_x[..., :, None] < high[..., None, :, 0])
    inside_y = (low[..., None, :, 1] <= mid_y[..., :, None]) & (mid_y[..., :, None] < high[..., None, :, 1])
    covered = np.any(inside_x[..., :, None, :] & inside_y[..., None, :, :], axis=-1)
    with np.errstate(invalid="ignore"):
        covered_area = np.einsum("...ab,...a,...b->...", covered, width_x, width_y)
    box_area = (box_px[..., 2] - box_px[..., 0]) * (box_px[..., 3] - box_px[..., 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        fraction = np.where(box_area > 0, np.clip(covered_area / box_area, 0.0, 1.0), 0.0)
    return np.where(valid, fraction, 0.0)
