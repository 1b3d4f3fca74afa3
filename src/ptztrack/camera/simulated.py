"""Simulated PTZ camera: the synthetic scene seen through the camera model.

It renders no images: a simulated detector draws its detections from the
people it knows to be in view (:class:`~ptztrack.types.PeopleInView`).
"""

from dataclasses import dataclass

import numpy as np

from ptztrack.geometry.occlusion import occlusion_in_centred_views
from ptztrack.geometry.ptz import PTZCamera, person_in_view, project_people
from ptztrack.types import GroundTruth, PeopleInView


@dataclass(frozen=True)
class SimulatedPTZ:
    """A camera backend over simulated people: everybody of ``truth``, seen by ``camera`` at a pose."""

    camera: PTZCamera
    truth: GroundTruth

    def image(self, step: int, pose) -> None:
        return None

    def people(self, step: int, pose) -> PeopleInView:
        """All N people of the scene at ``step``, absent ones included (never in view), so that a
        detector can draw for each person in a fixed order."""
        present = self.truth.present[step]
        positions_m = np.where(present[:, None], self.truth.positions_m[step], 0.0)
        heights_m, widths_m = self.truth.heights_m, self.truth.widths_m
        people = project_people(self.camera, pose, positions_m, heights_m, widths_m)
        hidden = occlusion_in_centred_views(self.camera, positions_m, heights_m, widths_m, present)
        return PeopleInView(
            person_index=np.arange(len(present)),
            feet_px=people.feet_px,
            height_px=people.height_px,
            in_view=present & person_in_view(self.camera, people),
            hidden=hidden,
        )
