"""Who hides whom: the fraction of each person's box covered by people nearer the camera.

Along a ray, the person nearer the optical centre hides the farther one,
however the camera is turned; boxes in an image measure how much.
"""

import numba
import numpy as np

from ptztrack.geometry.ptz import PTZCamera, look_at, project_people

# The kernels are cached on disk: every simulated step measures occlusion, whatever the policy, and
# compiling them (np.sort above all) cost each command about 3 s of CPU at its start.


@numba.njit(cache=True)
def _covered_area(low, high, count):
    """Area of the union of ``count`` rectangles ``low[k] <= (x, y) < high[k]``, (count, 2) each.

    Cuts the plane along every rectangle edge into at most (2 count - 1)^2
    cells and adds the cells whose centre some rectangle covers.
    """
    edges_x = np.sort(np.concatenate((low[:count, 0], high[:count, 0])))
    edges_y = np.sort(np.concatenate((low[:count, 1], high[:count, 1])))
    area = 0.0
    for a in range(2 * count - 1):
        width = edges_x[a + 1] - edges_x[a]
        if width <= 0:
            continue
        mid_x = 0.5 * (edges_x[a] + edges_x[a + 1])
        for b in range(2 * count - 1):
            height = edges_y[b + 1] - edges_y[b]
            if height <= 0:
                continue
            mid_y = 0.5 * (edges_y[b] + edges_y[b + 1])
            for k in range(count):
                if low[k, 0] <= mid_x < high[k, 0] and low[k, 1] <= mid_y < high[k, 1]:
                    area += width * height
                    break
    return area


@numba.njit(cache=True)
def _occluded_fraction(box_px, depth_m, valid):
    frames, count = depth_m.shape
    hidden = np.zeros((frames, count))
    low = np.empty((count, 2))
    high = np.empty((count, 2))
    for frame in range(frames):
        box = box_px[frame]
        for target in range(count):
            box_area = (box[target, 2] - box[target, 0]) * (box[target, 3] - box[target, 1])
            if not (valid[frame, target] and box_area > 0):
                continue
            # only the nearer people whose boxes overlap the target's, clipped to it
            occluders = 0
            for other in range(count):
                if other == target or not valid[frame, other] or not depth_m[frame, other] < depth_m[frame, target]:
                    continue
                low_x, low_y = max(box[other, 0], box[target, 0]), max(box[other, 1], box[target, 1])
                high_x, high_y = min(box[other, 2], box[target, 2]), min(box[other, 3], box[target, 3])
                if high_x > low_x and high_y > low_y:
                    low[occluders, 0], low[occluders, 1] = low_x, low_y
                    high[occluders, 0], high[occluders, 1] = high_x, high_y
                    occluders += 1
            if occluders:
                hidden[frame, target] = min(max(_covered_area(low, high, occluders) / box_area, 0.0), 1.0)
    return hidden


def occluded_fraction(box_px, depth_m, valid) -> np.ndarray:
    """Exact fraction of each box covered by the union of the boxes of nearer people.

    box_px : (..., N, 4) (left, top, right, bottom); depth_m : (..., N) the
    distance that orders people (nearer hides farther);
    valid : (..., N) bool, people that exist and are in front of the camera.
    Returns (..., N) in [0, 1], 0 for a person not valid. The union over the
    k boxes that overlap a person's is measured exactly by cutting it along
    their edges into at most (2k - 1)^2 cells, not along the edges of all N
    boxes, which would cost O(N^4) per frame in time and memory.
    """
    box_px = np.asarray(box_px, dtype=float)
    left, depth_m, valid = np.broadcast_arrays(
        box_px[..., 0], np.asarray(depth_m, dtype=float), np.asarray(valid, dtype=bool)
    )
    if left.size == 0:
        return np.zeros(left.shape)
    count = left.shape[-1]
    hidden = _occluded_fraction(
        np.broadcast_to(box_px, left.shape + (4,)).reshape(-1, count, 4),
        depth_m.reshape(-1, count),
        valid.reshape(-1, count),
    )
    return hidden.reshape(left.shape)


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
