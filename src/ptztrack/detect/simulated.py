"""Detector models on a simulated camera: visibility, recall against pixel height, occlusion.

Both detectors of the paper are one model, ``p(d=1) = recall(r) * (1 - c)``
for a person whose head and feet are inside the image (0 otherwise), where
``r`` is the person's height in pixels and ``c`` the fraction of its box
hidden by the boxes of people nearer the camera (nearer: closer to the
optical centre, which decides who hides whom along a ray, however the camera
is turned):

* ideal: ``recall(r) = 1``. The issue asks that an occluded person not be
  detected; we read "occluded" through the paper's own linear model
  ``p(d=1 | c) = 1 - c`` (section 4.2), so a fully visible person is always
  detected and a fully hidden one never;
* realistic: ``recall(r) = 1 - exp(-Kd (r - r0))`` for ``r >= r0``, else 0
  (equation 13, HOG on Caltech).
"""

import math
from dataclasses import dataclass

import numba
import numpy as np

from ptztrack.config import Detector
from ptztrack.geometry.ptz import ProjectedPeople, PTZCamera, look_at, person_in_view, project_people


@dataclass(frozen=True)
class Detections:
    """What a detector reports for one image.

    feet_px : (K, 2) feet points in pixels, with noise.
    height_px : (K,) the detected person's true height in pixels (NaN for a false positive).
    person_index : (K,) index of the true person, -1 for a false positive.
    """

    feet_px: np.ndarray
    height_px: np.ndarray
    person_index: np.ndarray

    def __len__(self) -> int:
        return len(self.feet_px)


@numba.vectorize(["float64(float64, float64, float64)"], nopython=True)
def realistic_recall(height_px, recall_kd, recall_r0_px):
    """``1 - exp(-Kd (r - r0))`` for ``r >= r0``, else 0 (a ufunc that compiled code can call too)."""
    if height_px < recall_r0_px:
        return 0.0
    return -math.expm1(-recall_kd * (height_px - recall_r0_px))


def recall(height_px, detector: Detector) -> np.ndarray:
    """Probability of detecting a fully visible person ``height_px`` tall."""
    height_px = np.asarray(height_px, dtype=float)
    if detector.kind == "ideal":
        return np.ones_like(height_px)
    return realistic_recall(height_px, detector.recall_kd, detector.recall_r0_px)


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


def detection_probability(camera: PTZCamera, people: ProjectedPeople, hidden, present, detector: Detector) -> np.ndarray:
    """p(d=1) = recall(r) (1 - c) for every person in view, else 0.

    people : projected at the pose; hidden : occluded fractions ``c``;
    present : bool; all with leading axes (..., N).
    """
    visible = present & person_in_view(camera, people)
    return np.where(visible, recall(people.height_px, detector) * (1.0 - hidden), 0.0)


def detect(
    camera: PTZCamera, people: ProjectedPeople, hidden, present, detector: Detector, rng: np.random.Generator
) -> Detections:
    """Draw one image's detections: hits with feet-pixel noise, plus Poisson false positives.

    people : the (N,) people of this frame projected at the current pose;
    hidden : (N,) their occluded fractions; present : (N,) bool.
    The draws for every person are made whether or not it is in view, in a
    fixed order, so that for one generator state the luck of each person
    does not depend on the pose (common random numbers across policies).
    """
    probability = detection_probability(camera, people, hidden, present, detector)
    luck = rng.random(probability.shape)
    noise_px = rng.normal(0.0, detector.pixel_noise_px, size=people.feet_px.shape)
    index = np.flatnonzero(luck < probability)
    feet_px = people.feet_px[index] + noise_px[index]
    false_count = rng.poisson(detector.false_positives_per_frame)
    false_feet_px = rng.uniform((0, 0), (camera.image_width_px, camera.image_height_px), size=(false_count, 2))
    return Detections(
        feet_px=np.concatenate([feet_px, false_feet_px]),
        height_px=np.concatenate([people.height_px[index], np.full(false_count, np.nan)]),
        person_index=np.concatenate([index, np.full(false_count, -1)]),
    )
