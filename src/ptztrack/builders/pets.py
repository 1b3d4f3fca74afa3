"""The protocols of the PETS 2009 tables (the paper's section 5.2): nothing learnt from the frames a table scores.

* ``a-priori``: every parameter as fixed before looking at S2.L1: the
  scenario's defaults, the paper's Caltech recall curve (Kd 0.0098, r0
  21.29 px) for the policies' model of HOG, and the walkable area from the
  calibrated view (:func:`ptztrack.builders.world.visible_ground_m`).
* ``two-fold``: the recording split in two halves by time; the detector's
  model is fitted on one half and the table scored on the other, then the
  other way round. Fitted on the training half: the detector's pixel noise
  (the spread of its feet around the pixel of each person's true ground
  point), for a detector with a recall curve its Kd and r0 by maximum
  likelihood (:mod:`ptztrack.detect.recall_fit`), and people's width (the
  annotated boxes' median width / height, at the policies' person height).
  Everything else stays a priori.
"""

import math
from dataclasses import dataclass

import numpy as np

from ptztrack.builders.world import build_world
from ptztrack.config import Scenario, scenario_from_dict
from ptztrack.detect.recall_fit import detection_trials, fit_recall
from ptztrack.names import PROTOCOLS
from ptztrack.scene.pets import load_mot_ground_truth

# The fit looks at every 20th step of the training half, at every zoom of the grid's views within 2 pan
# and 1 tilt steps of the whole-frame view (people are fully visible there, at every size the policies
# meet).
FIT_EVERY_STEPS = 20
FIT_POSE_SPAN = (2, 1)


@dataclass(frozen=True)
class Fold:
    """One scoring of a table: the scenario it runs and what was fitted for it.

    index : the fold (None under the a-priori protocol); scenario : restricted to the frames scored;
    fitted : {field: value} fitted on the other frames (empty a priori): the detector's
    ``pixel_noise_px``, ``recall_kd``, ``recall_r0_px`` and the people's ``width_m``.
    """

    index: int | None
    scenario: Scenario
    fitted: dict


def halves(scenario: Scenario) -> tuple[tuple[int, int], tuple[int, int]]:
    """The recording's annotated frames cut in two by time, [first, stop) each, both starting on a
    frame the experiment steps through."""
    recording = scenario.required_recording("the two-fold protocol")
    stop = int(load_mot_ground_truth(recording.ground_truth).frame.max()) + 1
    middle = recording.frame_step * math.ceil(stop / 2 / recording.frame_step)
    return (0, middle), (middle, stop)


PEOPLE_FIELDS = ("width_m",)


def with_frames(scenario: Scenario, frame_range: tuple[int, int], fields: dict) -> Scenario:
    """The scenario on the frames ``frame_range``, with ``fields`` of the detector and the people set;
    validated like a scenario file, so that a fitted value out of its field's range is refused."""
    overrides = {f"{'people' if name in PEOPLE_FIELDS else 'detector'}.{name}": value for name, value in fields.items()}
    return scenario_from_dict(scenario.model_dump(), "fold", **{"recording.frame_range": frame_range, **overrides})


def fit_detector(scenario: Scenario, frame_range: tuple[int, int]) -> dict:
    """The models fitted on the frames ``frame_range`` of the recording: ``pixel_noise_px``, for a
    detector other than the ideal one ``recall_kd`` and ``recall_r0_px``, and ``width_m``."""
    noiseless = with_frames(scenario, frame_range, {"pixel_noise_px": 0.0})
    world = build_world(noiseless, np.random.default_rng(0))
    grid = world.grid
    centre = grid.axis_indices[world.start_action, :2]
    near = np.all(np.abs(grid.axis_indices[:, :2] - centre) <= FIT_POSE_SPAN, axis=1)
    steps = range(0, world.truth.positions_m.shape[0], FIT_EVERY_STEPS)
    occluded_above = scenario.required_recording("fitting a detector").occluded_above
    trials = detection_trials(
        world.backend, world.detector, world.camera, world.truth, grid.poses[near], steps, occluded_above
    )
    boxes_px = annotated_boxes_px(noiseless)
    width_m = float(np.median(boxes_px[:, 2] / boxes_px[:, 3])) * scenario.control.person_height_m
    fitted = {"pixel_noise_px": trials.pixel_noise_px, "width_m": width_m}
    if scenario.detector.kind != "ideal":
        fitted["recall_kd"], fitted["recall_r0_px"] = fit_recall(trials.height_px, trials.detected)
    return fitted


def annotated_boxes_px(scenario: Scenario) -> np.ndarray:
    """The annotated boxes (K, 4) (left, top, width, height) px of the scenario's frames."""
    recording = scenario.required_recording("the annotations")
    annotations = load_mot_ground_truth(recording.ground_truth)
    first, stop = recording.frame_range or (0, int(annotations.frame.max()) + 1)
    return annotations.box_px[(annotations.frame >= first) & (annotations.frame < stop)]


def protocol_folds(scenario: Scenario, protocol: str) -> list[Fold]:
    """The scorings of a PETS table under ``protocol`` (see the module's docstring)."""
    if protocol == "a-priori":
        return [Fold(None, scenario, {})]
    if protocol != "two-fold":
        raise ValueError(f"unknown protocol {protocol!r}; expected one of {', '.join(PROTOCOLS)}")
    first, second = halves(scenario)
    folds = []
    for index, (fitted_on, scored) in enumerate(((first, second), (second, first))):
        fitted = fit_detector(scenario, fitted_on)
        folds.append(Fold(index, with_frames(scenario, scored, fitted), fitted))
    return folds
