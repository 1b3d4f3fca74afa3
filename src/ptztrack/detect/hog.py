"""OpenCV's HOG people detector (Dalal and Triggs) on small PTZ views.

The default detector scans 64 x 128 px windows. A virtual view is only
160 x 120 px, where a person at the edge of detectability (r0 = 21.29 px, the
recall model of the paper) is about 21 px tall, so the view is upsampled by
``upsample`` (default 6 = 128 / 21.29, rounded) before detection: then such
a person fills the window. Boxes are merged by non-maximum suppression and
returned in view pixels.

The model was trained on windows where the person stands with a 16 px
margin above and below (96 of 128 px), so the feet are 1/8 of a box's height
above its bottom edge and the person is 3/4 of it tall. On the PETS test
excerpt the feet taken that way lie a median 1.6 px (at zoom 1) from the
annotated feet, against 4.5 px for the bottom edge; 1.6 px at 160 px wide is
about 0.3 m on the ground at 20 m.
"""

from dataclasses import dataclass, field

import cv2
import numpy as np

from ptztrack.roles import CameraBackend
from ptztrack.types import Detections

PERSON_IN_WINDOW = 96 / 128  # of the box height
FEET_ABOVE_BOTTOM = 16 / 128  # of the box height


@dataclass
class HogPeopleDetector:
    """The HOG + linear SVM people detector of OpenCV, with its default model.

    upsample : factor applied to the view before detection.
    hit_threshold : SVM score below which a window is not a detection.
    nms_iou : boxes overlapping more than this (intersection over union) are merged.
    """

    upsample: float = 6.0
    hit_threshold: float = 0.0
    nms_iou: float = 0.4
    _hog: cv2.HOGDescriptor = field(init=False, repr=False)

    def __post_init__(self):
        self._hog = cv2.HOGDescriptor()
        self._hog.setSVMDetector(cv2.HOGDescriptor.getDefaultPeopleDetector())

    def detect(self, camera: CameraBackend, step: int, pose, rng: np.random.Generator) -> Detections:
        """People in the camera's view at ``pose``: feet and heights from the boxes, SVM scores."""
        image = camera.image(step, pose)
        if image is None:
            raise RuntimeError("the HOG detector needs a camera backend that renders images")
        boxes, scores = self.boxes(image)
        feet_px, height_px = feet_and_height_px(boxes)
        return Detections(feet_px, height_px, np.full(len(feet_px), -1), scores)

    def boxes(self, image) -> tuple[np.ndarray, np.ndarray]:
        """People in a BGR image: boxes (K, 4) as (left, top, width, height) px and SVM scores (K,)."""
        enlarged = cv2.resize(image, None, fx=self.upsample, fy=self.upsample, interpolation=cv2.INTER_LINEAR)
        found, weights = self._hog.detectMultiScale(
            enlarged, hitThreshold=self.hit_threshold, winStride=(8, 8), padding=(8, 8), scale=1.05
        )
        if len(found) == 0:
            return np.zeros((0, 4)), np.zeros(0)
        boxes, scores = np.asarray(found, dtype=float), np.ravel(weights).astype(float)
        keep = np.ravel(cv2.dnn.NMSBoxes(boxes.tolist(), scores.tolist(), self.hit_threshold, self.nms_iou))
        return boxes[keep] / self.upsample, scores[keep]


def feet_and_height_px(boxes) -> tuple[np.ndarray, np.ndarray]:
    """The feet points (K, 2) and person heights (K,) of HOG boxes (K, 4) (left, top, width, height)."""
    boxes = np.asarray(boxes, dtype=float).reshape(-1, 4)
    feet_px = np.stack([boxes[:, 0] + boxes[:, 2] / 2, boxes[:, 1] + (1 - FEET_ABOVE_BOTTOM) * boxes[:, 3]], axis=-1)
    return feet_px, PERSON_IN_WINDOW * boxes[:, 3]
