"""Motion pixels of a view: the evidence the occupancy map (:mod:`ptztrack.occupancy.lpom`) is built from.

The LPOM paper extracts "motion edges" with the SUSAN edge detector. Here a
motion edge is an edge of the current frame (OpenCV's Canny detector on the
grey image) that lies where the frame differs from the previous one (the
absolute grey difference above a threshold, dilated so that the edges
bounding a moving region count). For a view without video, the outlines of
a detector's boxes stand in (:func:`box_outline_points`): the left and right
sides of a box are where the person's silhouette touches the rays, as the
locus's touch constraint assumes, which the box's interior is not.
"""

import cv2
import numpy as np

from ptztrack.occupancy.parameters import MotionEdgeParameters


def motion_edges(previous_bgr, current_bgr, parameters: MotionEdgeParameters) -> np.ndarray:
    """Motion edges of ``current_bgr``: (height, width) bool. Both frames (height, width, 3) uint8 BGR."""
    previous = cv2.cvtColor(previous_bgr, cv2.COLOR_BGR2GRAY)
    current = cv2.cvtColor(current_bgr, cv2.COLOR_BGR2GRAY)
    moving = (cv2.absdiff(current, previous) > parameters.difference_threshold).astype(np.uint8)
    size = 2 * parameters.dilation_px + 1
    moving = cv2.dilate(moving, np.ones((size, size), np.uint8))
    edges = cv2.Canny(current, parameters.canny_low, parameters.canny_high)
    return (edges > 0) & (moving > 0)


def box_outline_points(boxes_px, points_per_box: int) -> np.ndarray:
    """Points evenly spaced along the outline of each box: (K * points_per_box, 2) px.

    boxes_px : (K, 4) as (left, top, width, height). Every box gets the same number of points, so
    that a near person's large box weighs no more than a far person's small one.
    """
    boxes_px = np.asarray(boxes_px, dtype=float).reshape(-1, 4)
    left, top, width, height = boxes_px.T
    perimeter = 2 * (width + height)
    s = perimeter[:, None] * (np.arange(points_per_box) + 0.5) / points_per_box  # arc length from the top-left
    w, h = width[:, None], height[:, None]
    x = np.select([s < w, s < w + h, s < 2 * w + h], [s, w, 2 * w + h - s], 0.0)
    y = np.select([s < w, s < w + h, s < 2 * w + h], [0.0, s - w, h], perimeter[:, None] - s)
    return np.stack([left[:, None] + x, top[:, None] + y], axis=-1).reshape(-1, 2)
