"""Camera backend over a recording: a virtual PTZ camera seeing annotated people (paper section 5.2).

With the HOG detector, the virtual view of the step's recorded frame is
rendered and OpenCV's people detector runs on it (:mod:`ptztrack.detect.hog`),
which gives each box's feet and height; nobody knows which person a box is
(``person_index`` -1).

The ideal detector of the paper's Table 3: the annotated boxes of the step's
frame are moved into the virtual view; a person is detected when the whole
box is inside the view and no more than ``occluded_above`` of it is hidden
by the boxes of people nearer the camera (the paper "removes the occluded
ones"; the boxes overlap a little even when nobody is really hidden, hence a
threshold). The feet point is the annotated feet moved into the view, with
the detector's pixel noise.
"""

from dataclasses import dataclass

import numpy as np

from ptztrack.camera.virtual import VirtualPTZ
from ptztrack.config import Detector
from ptztrack.detect.hog import HogPeopleDetector, feet_and_height_px
from ptztrack.detect.simulated import Detections, occluded_fraction
from ptztrack.scene.pets import RecordedScene, RecordedVideo


@dataclass(frozen=True)
class RecordedPTZ:
    """virtual : the camera; scene : the annotated people; video : the frames (needed by HOG only)."""

    virtual: VirtualPTZ
    scene: RecordedScene
    detector: Detector
    occluded_above: float
    video: RecordedVideo | None = None
    hog: HogPeopleDetector | None = None

    def observe(self, step: int, pose, rng: np.random.Generator) -> Detections:
        """Detections (virtual-view feet pixels) of the people of ``step`` seen at ``pose``."""
        if self.hog is not None:
            feet_px, height_px = feet_and_height_px(self.observe_hog_boxes(step, pose))
            return Detections(feet_px=feet_px, height_px=height_px, person_index=np.full(len(feet_px), -1))
        return self.observe_annotations(step, pose, rng)

    def view(self, step: int, pose) -> np.ndarray:
        """The virtual view (h, w, 3) uint8 BGR of ``step``'s recorded frame at ``pose``."""
        return self.virtual.render(self.video.frame(int(self.scene.video_frame[step])), pose)

    def observe_hog_boxes(self, step: int, pose) -> np.ndarray:
        """HOG boxes (K, 4) (left, top, width, height) in the virtual view of ``step`` at ``pose``."""
        return self.hog.detect(self.view(step, pose))[0]

    def observe_annotations(self, step: int, pose, rng: np.random.Generator, pixel_noise: bool = True) -> Detections:
        """The ideal detector: annotated people fully in view and not occluded, feet with the detector's noise."""
        annotations = self.scene.annotations
        people = annotations.select(annotations.frame == self.scene.video_frame[step])
        left, top, width, height = people.box_px.T
        corners = np.stack([[left, top], [left + width, top], [left, top + height], [left + width, top + height]])
        virtual_corners = self.virtual.recorded_to_virtual(corners.transpose(2, 0, 1).reshape(-1, 2), pose)
        virtual_corners = virtual_corners.reshape(-1, 4, 2)
        camera = self.virtual.camera
        inside = np.all(
            (virtual_corners >= 0) & (virtual_corners <= [camera.image_width_px, camera.image_height_px]), axis=(1, 2)
        )
        centre_m = np.asarray(camera.position_m)
        range_m = np.linalg.norm(np.c_[people.ground_m, np.zeros(len(people.frame))] - centre_m, axis=1)
        boxes = np.stack([left, top, left + width, top + height], axis=-1)
        hidden = occluded_fraction(boxes, range_m, np.ones(len(boxes), dtype=bool))
        luck_noise = rng.normal(0.0, self.detector.pixel_noise_px if pixel_noise else 0.0, size=(len(boxes), 2))
        seen = np.flatnonzero(inside & (hidden <= self.occluded_above))
        feet_px = self.virtual.recorded_to_virtual(people.feet_px[seen], pose) + luck_noise[seen]
        heights_px = virtual_corners[seen, 2:, 1].mean(axis=1) - virtual_corners[seen, :2, 1].mean(axis=1)
        return Detections(
            feet_px=feet_px,
            height_px=heights_px,
            person_index=np.searchsorted(self.scene.person_id, people.person_id[seen]),
        )

