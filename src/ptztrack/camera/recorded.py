"""Camera backend over a recording: a virtual PTZ camera inside a calibrated video (paper section 5.2).

Its image at a step and pose is the view of the step's recorded frame
rendered by the virtual camera (:mod:`ptztrack.camera.virtual`), exact or
as a real camera takes it (:mod:`ptztrack.camera.live_view`). It also
knows the annotated people, moved into the view: a person is wholly in view
when the whole annotated box is, and hidden by the fraction of the box that
the boxes of people nearer the camera cover in the recorded frame.
"""

from dataclasses import dataclass, field

import numpy as np

from ptztrack.camera.live_view import recorded_to_live, render_view
from ptztrack.camera.parameters import LiveViewParameters
from ptztrack.camera.virtual import VirtualPTZ
from ptztrack.geometry.occlusion import occluded_fraction
from ptztrack.scene.pets import RecordedScene, RecordedVideo
from ptztrack.types import PeopleInView


@dataclass
class RecordedPTZ:
    """virtual : the camera; scene : the annotated people; video : the frames (None: no images);
    live : how the camera's views depart from the pinhole model (:mod:`ptztrack.camera.live_view`),
    None for exact views. The annotated people are moved into the view through the same lens.

    The last view rendered is kept, so that a detector and a tracker looking at the same step and
    pose share one rendering.
    """

    virtual: VirtualPTZ
    scene: RecordedScene
    video: RecordedVideo | None = None
    live: LiveViewParameters | None = None
    _last_view: tuple = field(default=(None, None, None), init=False, repr=False)

    def image(self, step: int, pose) -> np.ndarray | None:
        """The virtual view (h, w, 3) uint8 BGR of ``step``'s recorded frame at ``pose``."""
        if self.video is None:
            return None
        pose = np.asarray(pose, dtype=float)
        last_step, last_pose, last_view = self._last_view
        if last_step == step and np.array_equal(last_pose, pose):
            return last_view
        view = render_view(self.virtual, self.video.frame(int(self.scene.video_frame[step])), pose, self.live)
        self._last_view = (step, pose.copy(), view)
        return view

    def people(self, step: int, pose) -> PeopleInView:
        """The annotated people of ``step``'s frame, moved into the view at ``pose``."""
        annotations = self.scene.annotations
        people = annotations.select(annotations.frame == self.scene.video_frame[step])
        left, top, width, height = people.box_px.T
        corners = np.stack([[left, top], [left + width, top], [left, top + height], [left + width, top + height]])
        virtual_corners = self._recorded_to_view(corners.transpose(2, 0, 1).reshape(-1, 2), pose)
        virtual_corners = virtual_corners.reshape(-1, 4, 2)
        camera = self.virtual.camera
        inside = np.all(
            (virtual_corners >= 0) & (virtual_corners <= [camera.image_width_px, camera.image_height_px]), axis=(1, 2)
        )
        centre_m = np.asarray(camera.position_m)
        range_m = np.linalg.norm(np.c_[people.ground_m, np.zeros(len(people.frame))] - centre_m, axis=1)
        boxes = np.stack([left, top, left + width, top + height], axis=-1)
        return PeopleInView(
            person_index=np.searchsorted(self.scene.person_id, people.person_id),
            feet_px=self._recorded_to_view(people.feet_px, pose),
            height_px=virtual_corners[:, 2:, 1].mean(axis=1) - virtual_corners[:, :2, 1].mean(axis=1),
            in_view=inside,
            hidden=occluded_fraction(boxes, range_m, np.ones(len(boxes), dtype=bool)),
        )

    def _recorded_to_view(self, recorded_px, pose) -> np.ndarray:
        """Recorded pixels (N, 2) to pixels (N, 2) of the view at ``pose``, through the live lens if any."""
        if self.live is None:
            return self.virtual.recorded_to_virtual(recorded_px, pose)
        return recorded_to_live(self.virtual, recorded_px, pose, self.live)
