"""Who hides whom: the fraction of each person's box covered by people nearer the camera.

Along a ray, the person nearer the optical centre hides the farther one,
however the camera is turned; boxes in an image measure how much.
"""

import numpy as np

from ptztrack.geometry.ptz import PTZCamera, look_at, project_people


def occluded_fraction(box_px, depth_m, valid) -> np.ndarray:
    """Exact fraction of each box covered by the union of the boxes of nearer people.

    box_px : (..., N, 4) (left, top, right, bottom); depth_m : (..., N) the
    distance that orders people (nearer hides farther);
    valid : (..., N) bool, people that exist and are in front of the camera.
    Returns (..., N) in [0, 1]. The union is measured exactly by cutting each
    box along every occluder edge into at most (2N - 1)^2 cells.
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
    covered_area = np.einsum("...ab,...a,...b->...", covered, width_x, width_y)
    box_area = (box_px[..., 2] - box_px[..., 0]) * (box_px[..., 3] - box_px[..., 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(box_area > 0, np.clip(covered_area / box_area, 0.0, 1.0), 0.0)


def occlusion_in_centred_views(camera: PTZCamera, ground_xy, height_m, width_m, present) -> np.ndarray:
    """The occluded fraction ``c`` of each person (N,), measured in the zoom-1 view centred on it.

    Who hides whom is decided by the rays through the optical centre, so any
    pose gives the same answer in principle; but a bounding box is a fair
    outline of a person only near the optical axis (a person seen at a
    grazing angle projects to a box thousands of pixels wide). Centring the
    view on the person keeps every box that can touch its own near the axis.
    ground_xy : (N, 2); height_m, width_m, present : (N,).
    """
    ground_xy = np.asarray(ground_xy, dtype=float)
    centred = look_at(camera, ground_xy, 1.0)
    people = project_people(camera, centred, ground_xy, height_m, width_m)
    hidden = occluded_fraction(people.box_px, people.range_m, present & people.in_front)
    return np.diagonal(hidden).copy()
