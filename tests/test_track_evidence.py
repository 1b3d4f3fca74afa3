"""The tracker's evidence about its detector reads no truth.

The detector model learned online (:mod:`ptztrack.detect.detector_model`) is told which tracks a detection
confirmed and which it missed (:func:`ptztrack.track.evidence.tracker_evidence`), and nothing else: a deployed
camera knows no annotation. So a closed-loop run whose detections are given, whatever the people are, is
the same run whatever the ground truth holds.
"""

from dataclasses import dataclass, replace

import numpy as np

from ptztrack.builders.episode import episode_world, run_episode
from ptztrack.camera.simulated import SimulatedPTZ
from ptztrack.config import scenario_from_dict
from ptztrack.detect.simulated import RecallDetector, RecallModel
from ptztrack.types import Detections, GroundTruth

SEED = 4


@dataclass(frozen=True)
class GivenDetections:
    """A detector whose detections are fixed in advance, as published detections are: what the realistic
    detector finds among the people of its own ``backend``, whatever the camera it is given shows."""

    detector: RecallDetector
    backend: SimulatedPTZ

    def detect(self, camera, step: int, pose, rng: np.random.Generator, believed_pose=None) -> Detections:
        return self.detector.detect(self.backend, step, pose, rng)


def world_with_given_detections(scenario, truth_of):
    """The episode's world with :class:`GivenDetections` over all its people, its truth (the world's and
    its camera's) replaced by ``truth_of(truth)``."""
    world = episode_world(scenario, SEED)
    assert isinstance(world.backend, SimulatedPTZ)
    detector = scenario.detector
    given = GivenDetections(
        RecallDetector(
            RecallModel(detector.recall_kd, detector.recall_r0_px),
            detector.pixel_noise_px,
            detector.false_positives_per_frame,
            (world.camera.image_width_px, world.camera.image_height_px),
        ),
        world.backend,
    )
    truth = truth_of(world.truth)
    return replace(world, truth=truth, backend=replace(world.backend, truth=truth), detector=given)


def every_other_person(truth: GroundTruth) -> GroundTruth:
    return GroundTruth(truth.positions_m[:, ::2], truth.heights_m[::2], truth.widths_m[::2], truth.frame_rate_hz)


def test_a_run_with_given_detections_learns_and_moves_the_same_whatever_the_truth_holds():
    """Halving the truth's people changes nothing of a run whose detections are given: not the detector
    model it learns (which the tracker and the policy read), not where the camera looks, not the tracks (their
    ids, places and existence)."""
    scenario = scenario_from_dict({"frames": 14, "detector": {"kind": "realistic", "model": "online"}})
    full = world_with_given_detections(scenario, lambda truth: truth)
    halved = world_with_given_detections(scenario, every_other_person)
    assert halved.truth.positions_m.shape[1] < full.truth.positions_m.shape[1]
    assert full.detector_model is not None and full.detector_model.learning

    seen, told_less = (run_episode(scenario, "intg", SEED, world) for world in (full, halved))

    # The model learned from established tracks, some confirmed and some missed.
    learned, learned_too = full.detector_model, halved.detector_model
    assert learned.trials.sum() > 0 and 0 < learned.successes.sum() < learned.trials.sum()
    np.testing.assert_array_equal(seen.actions, told_less.actions)
    np.testing.assert_array_equal(seen.poses, told_less.poses)
    # Looking at the same places, the camera was given the same detections.
    for given, again in zip(seen.detections, told_less.detections, strict=True):
        np.testing.assert_array_equal(given.feet_px, again.feet_px)
    for tracks, same in zip(seen.tracks, told_less.tracks, strict=True):
        np.testing.assert_array_equal(tracks.ids, same.ids)
        np.testing.assert_array_equal(tracks.mean, same.mean)
        np.testing.assert_array_equal(tracks.existence, same.existence)
    np.testing.assert_array_equal(learned.trials, learned_too.trials)
    np.testing.assert_array_equal(learned.successes, learned_too.successes)
    assert learned.planning_curve == learned_too.planning_curve
