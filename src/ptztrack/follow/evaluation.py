"""How well a camera follows one person, and how well a tracker keeps them on a still video.

Closed loop (:func:`follow_metrics`), over the steps where the person is
annotated, from their true box moved into each step's view
(:func:`target_in_views`):

* ``in_view_fraction``: steps whose true box centre is inside the image;
* ``target_point_error``: the mean distance of the true box centre from
  (x*, y*), divided by the image diagonal (Chen et al., "Reproducible
  evaluation of pan-tilt-zoom tracking", ICIP 2015; out-of-view steps count
  with their distance too, wherever the centre projects);
* ``losses``, ``recoveries``, ``lost_steps``: losses the tracker declared,
  how many it came back from, and the steps it spent lost;
* ``height_sd_ratio``: the standard deviation of the true image height over
  its mean (0: the zoom holds the person's size perfectly);
* ``jitter_deg``: the mean absolute second difference of the commanded pan
  and tilt (both together), degrees per step squared.

One-pass evaluation (OTB, Wu, Lim and Yang, CVPR 2013): a tracker
initialised on the first annotated box runs over every later frame without
re-initialisation; ``success_auc`` is the area under the success plot (the
fraction of frames whose box overlaps the annotated one by more than a
threshold, over 21 thresholds 0, 0.05, ..., 1, averaged), ``precision_20px``
the fraction of frames whose box centre lies within 20 px of the annotated
one. The box is whatever the tracker reports, also while it reports a
failure (its last box).
"""

import numpy as np

from ptztrack.camera.virtual import VirtualPTZ
from ptztrack.scene.pets import box_iou

SUCCESS_THRESHOLDS = np.linspace(0.0, 1.0, 21)
PRECISION_PX = 20.0


def target_in_views(virtual: VirtualPTZ, boxes_px, poses) -> tuple[np.ndarray, np.ndarray]:
    """The person's true box centre (T, 2) px and height (T,) px in the view of every step.

    boxes_px : (T, 4) annotated (left, top, width, height) in the recording's pixels, NaN where the
    person is not annotated; poses : (T, 3) the views' poses. The centre is the annotated centre
    moved into the view; the height is the distance between the moved top and bottom centres.
    NaN where not annotated.
    """
    boxes_px = np.asarray(boxes_px, dtype=float)
    left, top, width, height = boxes_px.T
    middle = left + width / 2
    points = np.stack([[middle, top + height / 2], [middle, top], [middle, top + height]], axis=1)  # (2, 3, T)
    centres, heights = np.full((len(boxes_px), 2), np.nan), np.full(len(boxes_px), np.nan)
    for step in np.flatnonzero(np.all(np.isfinite(boxes_px), axis=1)):
        centre, head, feet = virtual.recorded_to_virtual(points[:, :, step].T, poses[step])
        centres[step], heights[step] = centre, np.linalg.norm(feet - head)
    return centres, heights


def follow_metrics(centres_px, heights_px, commanded, lost, image_size_px, target_point_px) -> dict:
    """The closed-loop figures of one run (see the module).

    centres_px : (T, 2), heights_px : (T,) the true box in each step's view, NaN where not
    annotated; commanded : (T, 3) the commanded poses; lost : (T,) bool, the tracker lost at the
    step; image_size_px : (width, height); target_point_px : (2,) (x*, y*).
    """
    centres_px, heights_px = np.asarray(centres_px, dtype=float), np.asarray(heights_px, dtype=float)
    lost = np.asarray(lost, dtype=bool)
    annotated = np.isfinite(centres_px[:, 0])
    width, height = image_size_px
    inside = (centres_px[:, 0] >= 0) & (centres_px[:, 0] <= width) & (centres_px[:, 1] >= 0)
    inside &= centres_px[:, 1] <= height
    distance = np.linalg.norm(centres_px[annotated] - target_point_px, axis=1) / np.hypot(width, height)
    changes = np.diff(lost.astype(int))
    second_difference = np.abs(np.diff(np.asarray(commanded, dtype=float)[:, :2], n=2, axis=0))
    heights = heights_px[annotated]
    return {
        "in_view_fraction": float(inside[annotated].mean()),
        "target_point_error": float(distance.mean()),
        "losses": int(np.sum(changes == 1) + lost[0]),
        "recoveries": int(np.sum(changes == -1)),
        "lost_steps": int(lost.sum()),
        "jitter_deg": float(second_difference.mean()) if len(second_difference) else 0.0,
        "height_sd_ratio": float(heights.std() / heights.mean()),
        "annotated_steps": int(annotated.sum()),
    }


def one_pass_scores(tracked_px, annotated_px) -> dict:
    """``success_auc`` and ``precision_20px`` of boxes (T, 4) against the annotated ones (T, 4) (see the module)."""
    tracked_px, annotated_px = np.asarray(tracked_px, dtype=float), np.asarray(annotated_px, dtype=float)
    overlap = box_iou(tracked_px, annotated_px)
    success = (overlap[None, :] > SUCCESS_THRESHOLDS[:, None]).mean(axis=1)
    centre_error_px = np.linalg.norm(
        tracked_px[:, :2] + tracked_px[:, 2:] / 2 - annotated_px[:, :2] - annotated_px[:, 2:] / 2, axis=1
    )
    return {
        "success_auc": float(success.mean()),
        "precision_20px": float(np.mean(centre_error_px <= PRECISION_PX)),
        "frames": len(overlap),
    }
