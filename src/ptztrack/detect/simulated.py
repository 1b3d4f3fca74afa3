"""Simulated detectors: detections drawn from the people a simulated camera knows to be in view.

Both detectors of the paper are one model, ``p(d=1) = recall(r) * (1 - c)``
for a person whose head and feet are inside the image (0 otherwise), where
``r`` is the person's height in pixels and ``c`` the fraction of its box
hidden by the boxes of people nearer the camera (nearer: closer to the
optical centre, which decides who hides whom along a ray, however the camera
is turned):

* ideal: ``recall(r) = 1``, and an occluded person is not detected; we
  read "occluded" through the paper's own linear model
  ``p(d=1 | c) = 1 - c`` (section 4.2), so a fully visible person is always
  detected and a fully hidden one never;
* realistic: ``recall(r) = 1 - exp(-Kd (r - r0))`` for ``r >= r0``, else 0
  (equation 13, HOG on Caltech).

The ideal detector of a recording (the paper's Table 3) is another rule:
:class:`AnnotationDetector` reports every annotated person wholly in view and
not more than a threshold hidden.
"""

import math
from dataclasses import dataclass
from typing import Protocol

import numba
import numpy as np

from ptztrack.roles import CameraBackend
from ptztrack.types import Detections, PeopleInView


@numba.vectorize(["float64(float64, float64, float64)"], nopython=True)
def realistic_recall(height_px, recall_kd, recall_r0_px):
    """``1 - exp(-Kd (r - r0))`` for ``r >= r0``, else 0 (a ufunc that compiled code can call too)."""
    if height_px < recall_r0_px:
        return 0.0
    return -math.expm1(-recall_kd * (height_px - recall_r0_px))


class RecallCurve(Protocol):
    """What the policies and the tracker read of a detector model: the curve of :class:`RecallModel`
    (a learned model, :class:`ptztrack.detect.detector_model.OnlineDetectorModel`, reads as its current one)."""

    @property
    def kd_per_px(self) -> float: ...

    @property
    def r0_px(self) -> float: ...

    @property
    def perfect(self) -> bool: ...

    @property
    def plateau(self) -> float: ...

    def __call__(self, height_px) -> np.ndarray: ...


@dataclass(frozen=True)
class RecallModel:
    """The probability of detecting a fully visible person by pixel height (the paper's equation 13).

    kd_per_px, r0_px, plateau : ``recall(r) = plateau (1 - exp(-kd (r - r0)))`` for ``r >= r0``, else 0;
        the plateau (1 in the paper) is the share of people a detector finds however large they look.
    perfect : recall does not depend on the height: the plateau at every height (1: the ideal detector;
        :meth:`constant`); kd and r0 are then not used.
    """

    kd_per_px: float
    r0_px: float
    perfect: bool = False
    plateau: float = 1.0

    def __call__(self, height_px) -> np.ndarray:
        height_px = np.asarray(height_px, dtype=float)
        if self.perfect:
            return np.full_like(height_px, self.plateau)
        return self.plateau * realistic_recall(height_px, self.kd_per_px, self.r0_px)

    @staticmethod
    def constant(recall: float) -> "RecallModel":
        """Recall ``recall`` for every person wholly in the image, whatever their size."""
        return RecallModel(0.0, 0.0, perfect=True, plateau=recall)


def detection_probability(people: PeopleInView, recall: RecallModel) -> np.ndarray:
    """p(d=1) = recall(r) (1 - c) for every person in view, else 0; (N,)."""
    return np.where(people.in_view, recall(people.height_px) * (1.0 - people.hidden), 0.0)


def _need_people(camera: CameraBackend, step: int, pose) -> PeopleInView:
    people = camera.people(step, pose)
    if people is None:
        raise RuntimeError("a simulated detector needs a camera backend that knows who is in view (a simulation)")
    return people


@dataclass(frozen=True)
class RecallDetector:
    """The paper's simulated detector: hits with feet-pixel noise, plus Poisson false positives.

    recall : the recall model; pixel_noise_px : 1-sigma Gaussian noise of the feet per axis;
    false_positives_per_frame : the mean of the Poisson count of false positives, uniform over
    an image of ``image_size_px`` (width, height).
    """

    recall: RecallModel
    pixel_noise_px: float
    false_positives_per_frame: float
    image_size_px: tuple[int, int]

    def detect(
        self, camera: CameraBackend, step: int, pose, rng: np.random.Generator, believed_pose=None
    ) -> Detections:
        """The draws for every person are made whether or not it is in view, in a fixed order, so that
        for one generator state the luck of each person does not depend on the pose (common random
        numbers across policies)."""
        people = _need_people(camera, step, pose)
        probability = detection_probability(people, self.recall)
        luck = rng.random(probability.shape)
        noise_px = rng.normal(0.0, self.pixel_noise_px, size=people.feet_px.shape)
        index = np.flatnonzero(luck < probability)
        feet_px = people.feet_px[index] + noise_px[index]
        false_count = rng.poisson(self.false_positives_per_frame)
        false_feet_px = rng.uniform((0, 0), self.image_size_px, size=(false_count, 2))
        return Detections(
            feet_px=np.concatenate([feet_px, false_feet_px]),
            height_px=np.concatenate([people.height_px[index], np.full(false_count, np.nan)]),
            person_index=np.concatenate([people.person_index[index], np.full(false_count, -1)]),
        )


@dataclass(frozen=True)
class AnnotationDetector:
    """The ideal detector of a recording: every person wholly in view and hidden no more than
    ``occluded_above`` (the paper "removes the occluded ones"; annotated boxes overlap a little even
    when nobody is really hidden, hence a threshold), feet with ``pixel_noise_px`` of noise."""

    pixel_noise_px: float
    occluded_above: float

    def detect(
        self, camera: CameraBackend, step: int, pose, rng: np.random.Generator, believed_pose=None
    ) -> Detections:
        people = _need_people(camera, step, pose)
        noise_px = rng.normal(0.0, self.pixel_noise_px, size=people.feet_px.shape)
        seen = np.flatnonzero(people.in_view & (people.hidden <= self.occluded_above))
        return Detections(
            feet_px=people.feet_px[seen] + noise_px[seen],
            height_px=people.height_px[seen],
            person_index=people.person_index[seen],
        )
