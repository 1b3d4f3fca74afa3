"""The "detector and clustering" baseline of multi-view detection: box feet on the ground, clustered across views.

Each view's boxes give their feet (the bottom centre) on the ground plane,
back-projected through the view's calibration; the ground points of all
views are clustered by complete-linkage hierarchical clustering (SciPy) cut
at ``linkage_m``, so that no two points of a cluster lie farther apart than
that; each cluster's mean is a detection, supported by the number of
distinct views among its points. Views without a detector's boxes get
boxes from their video: OpenCV's MOG2 background subtractor, opened and
closed, and the bounding boxes of its connected regions (a blob detector).
"""

from dataclasses import dataclass

import cv2
import numpy as np
from scipy.cluster.hierarchy import fcluster, linkage

from ptztrack.geometry.calibration import PinholeCalibration, pixel_rays
from ptztrack.occupancy.multiview import CameraView
from ptztrack.scene.pets import box_feet_px

# Blob boxes from MOG2: morphological opening removes speckle, closing joins a body's parts.
OPEN_PX, CLOSE_PX = 3, 9


def feet_on_ground(calibration: PinholeCalibration, boxes_px) -> np.ndarray:
    """Ground points (K, 2) m of the bottom centres of boxes (K, 4+) (left, top, width, height, ...);
    NaN where the ray does not go down to the ground."""
    boxes_px = np.asarray(boxes_px, dtype=float)
    if len(boxes_px) == 0:
        return np.zeros((0, 2))
    centre_m, direction = pixel_rays(calibration, box_feet_px(boxes_px))
    t_m = -centre_m[2] / direction[:, 2]
    ground_m = centre_m[:2] + t_m[:, None] * direction[:, :2]
    return np.where((t_m > 0)[:, None], ground_m, np.nan)


def grounded_feet(calibration: PinholeCalibration, boxes_px) -> np.ndarray:
    """:func:`feet_on_ground` of the boxes whose ray reaches the ground, the others left out: (K', 2) m."""
    feet_m = feet_on_ground(calibration, boxes_px)
    return feet_m[~np.isnan(feet_m[:, 0])]


def view_feet_on_ground(view: CameraView, frame: int, min_box_score: float) -> np.ndarray:
    """The :func:`grounded_feet` (K, 2) m of the view's boxes at ``frame`` with a score of at least
    ``min_box_score``."""
    assert view.boxes is not None
    boxes = view.boxes[frame]
    return grounded_feet(view.calibration, boxes[boxes[:, 4] >= min_box_score])


@dataclass(frozen=True)
class Clusters:
    """Detections of the baseline: position_m (K, 2) the clusters' means; views (K,) the distinct
    views that support each."""

    position_m: np.ndarray
    views: np.ndarray

    def select(self, keep) -> "Clusters":
        return Clusters(self.position_m[keep], self.views[keep])


def cluster_feet(ground_m, view_index, linkage_m: float) -> Clusters:
    """Complete-linkage clusters of ground points (P, 2) m seen by views ``view_index`` (P,)."""
    ground_m, view_index = np.asarray(ground_m, dtype=float).reshape(-1, 2), np.asarray(view_index)
    if len(ground_m) < 2:
        return Clusters(ground_m.copy(), np.ones(len(ground_m), dtype=int))
    label = fcluster(linkage(ground_m, method="complete"), t=linkage_m, criterion="distance")
    labels = np.unique(label)
    position_m = np.stack([ground_m[label == value].mean(axis=0) for value in labels])
    views = np.array([len(np.unique(view_index[label == value])) for value in labels])
    return Clusters(position_m, views)


class BlobBoxes:
    """Boxes of moving regions in a view's frames, by OpenCV's MOG2 background subtractor (shadows off).

    Feed the frames in order: the subtractor learns the background from them. min_area_px : smaller
    regions are dropped.
    """

    def __init__(self, min_area_px: int):
        self.subtractor = cv2.createBackgroundSubtractorMOG2(detectShadows=False)
        self.min_area_px = min_area_px

    def learn(self, image_bgr) -> None:
        """Learn a frame (height, width, 3) uint8 BGR into the background without finding its boxes."""
        self.subtractor.apply(image_bgr)

    def boxes(self, image_bgr) -> np.ndarray:
        """(K, 5) boxes (left, top, width, height, score 1) of the moving regions of the next frame."""
        foreground = self.subtractor.apply(image_bgr)
        foreground = cv2.morphologyEx(foreground, cv2.MORPH_OPEN, np.ones((OPEN_PX, OPEN_PX), np.uint8))
        foreground = cv2.morphologyEx(foreground, cv2.MORPH_CLOSE, np.ones((CLOSE_PX, CLOSE_PX), np.uint8))
        _, _, stats, _ = cv2.connectedComponentsWithStats((foreground > 0).astype(np.uint8))
        regions = stats[1:][stats[1:, cv2.CC_STAT_AREA] >= self.min_area_px]
        boxes = regions[:, [cv2.CC_STAT_LEFT, cv2.CC_STAT_TOP, cv2.CC_STAT_WIDTH, cv2.CC_STAT_HEIGHT]]
        return np.concatenate([boxes.astype(float), np.ones((len(boxes), 1))], axis=1)
