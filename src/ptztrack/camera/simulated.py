"""Simulated PTZ camera: the synthetic scene seen through the camera model and a detector model."""

from dataclasses import dataclass

import numpy as np

from ptztrack.config import Detector
from ptztrack.detect.simulated import Detections, detect
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
        people = project_people(self.camera, pose, positions_m, self.truth.heights_m, self.truth.widths_m)
        return detect(self.camera, people, present, self.detector, rng)
