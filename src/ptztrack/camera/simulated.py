"""Simulated PTZ camera: the synthetic scene seen through the camera model and a detector model."""

from dataclasses import dataclass

import numpy as np

from ptztrack.config import Detector
from ptztrack.detect.simulated import Detections, detect, occlusion_in_centred_views
from ptztrack.geometry.ptz import PTZCamera, project_people
from ptztrack.scene.synthetic import GroundTruth


@dataclass(frozen=True)
class SimulatedPTZ:
    """A camera backend that renders detections, not images."""

    camera: PTZCamera
    truth: GroundTruth
    detector: Detector

    def observe(self, frame: int, pose, rng: np.random.Generator) -> Detections:
        """Detections (feet pixels) of the people present at ``frame`` seen at ``pose`` (3,)."""
        present = self.truth.present[frame]
        positions_m = np.where(present[:, None], self.truth.positions_m[frame], 0.0)
        heights_m, widths_m = self.truth.heights_m, self.truth.widths_m
        people = project_people(self.camera, pose, positions_m, heights_m, widths_m)
        hidden = occlusion_in_centred_views(self.camera, positions_m, heights_m, widths_m, present)
        return detect(self.camera, people, hidden, present, self.detector, rng)
