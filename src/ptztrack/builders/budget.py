"""What a run will need in memory, estimated from its scenario before it starts, and a refusal when
the machine does not have it.

The terms are the arrays that grow with the scenario's sizes, with coefficients measured on this
code (peak resident memory of ``run_episode`` at growing sizes, 2 steps unless said):

* the interpreter and libraries: 320 MB (a 2-step synthetic run of ``fix``: 317 MB);
* the history of a run and its scoring: 1 kB per person and step (decisions page);
* the simulated detector's occlusion, each person measured in the view centred on them: 160 N^2
  bytes for N people (1000 people: +159 MB);
* ``smpl``'s joint draws and their boxes: 230 bytes per sample and track (4000 samples of 400
  tracks: +362 MB, from the rewards of one decision);
* the exploration map (``control.beta`` > 0): 160 bytes per action and cell (a 300 m square at
  1 m cells and 280 actions: 4.1 GB; 600 m: 15.7 GB);
* a view and its upsampled copy for HOG: 12 bytes per pixel, times the upsampling squared.
"""

import math

import numpy as np
import psutil

from ptztrack.config import Scenario, ScenarioError
from ptztrack.scene.pets import load_mot_ground_truth
from ptztrack.scene.trajectories import read_trajectories

INTERPRETER_BYTES = 320e6
HISTORY_BYTES_PER_PERSON_STEP = 1e3
DETECTOR_OCCLUSION_BYTES_PER_PERSON_PAIR = 160.0
SMPL_BYTES_PER_SAMPLE_TRACK = 230.0
EXPLORATION_BYTES_PER_ACTION_CELL = 160.0
IMAGE_BYTES_PER_PIXEL = 12.0
# The ground of a recording is known only once its calibration is read: a 100 m square bounds
# what one camera's view covers in the recordings we know (PETS's View_001 sees about 40 x 30 m).
RECORDING_AREA_M2 = 100.0 * 100.0
INFORMATION_POLICIES = ("intg", "smpl")


def people_at_once(scenario: Scenario) -> int:
    """The most people a scenario's scene holds at once: a recording's or a trajectory file's most in one
    frame, else the synthetic crowd's count."""
    if scenario.recording is not None:
        frame = load_mot_ground_truth(scenario.recording.ground_truth).frame
    elif scenario.people.trajectories is not None and scenario.people.trajectories_frame_rate_hz is not None:
        frame = read_trajectories(scenario.people.trajectories, scenario.people.trajectories_frame_rate_hz).frame
    else:
        return scenario.people.count
    return int(np.bincount(frame - frame.min()).max())


def estimated_memory_bytes(scenario: Scenario, policies: tuple[str, ...]) -> dict[str, float]:
    """The estimated peak memory of one episode of ``scenario`` under the worst of ``policies``, by term."""
    people = people_at_once(scenario)
    actions = scenario.actions.pan_deg.count * scenario.actions.tilt_deg.count * len(scenario.actions.zoom)
    terms = {
        "interpreter": INTERPRETER_BYTES,
        "history": HISTORY_BYTES_PER_PERSON_STEP * people * scenario.frames,
        "detector occlusion": DETECTOR_OCCLUSION_BYTES_PER_PERSON_PAIR * people**2
        if scenario.recording is None
        else 0.0,
    }
    if "smpl" in policies:
        terms["smpl samples"] = SMPL_BYTES_PER_SAMPLE_TRACK * scenario.control.samples * people
    if scenario.control.beta > 0 and set(policies) & set(INFORMATION_POLICIES):
        area_m2 = scenario.area_m[0] * scenario.area_m[1] if scenario.recording is None else RECORDING_AREA_M2
        cells = math.ceil(area_m2 / scenario.control.exploration_cell_m**2)
        terms["exploration map"] = EXPLORATION_BYTES_PER_ACTION_CELL * actions * cells
    width_px, height_px = scenario.camera.image_size_px
    upsample = scenario.detector.hog_upsample if scenario.detector.kind == "hog" else 1.0
    terms["views"] = IMAGE_BYTES_PER_PIXEL * width_px * height_px * (1.0 + upsample**2)
    return terms


def refuse_if_too_large(
    scenario: Scenario, policies: tuple[str, ...], runs_at_once: int = 1, available_bytes: float | None = None
) -> None:
    """A :class:`ScenarioError` before any work if ``runs_at_once`` episodes would need more memory than
    is available (``available_bytes``, by default what the machine has free now)."""
    terms = estimated_memory_bytes(scenario, policies)
    needed = runs_at_once * sum(terms.values())
    available = available_memory_bytes() if available_bytes is None else available_bytes
    if needed > available:
        largest = max(terms, key=lambda name: terms[name])
        at_once = f" x {runs_at_once} runs at once" if runs_at_once > 1 else ""
        raise ScenarioError(
            f"scenario: a run needs an estimated {needed / 1e9:.3g} GB{at_once} (most of it {largest}, "
            f"{terms[largest] / 1e9:.3g} GB), more than the {available / 1e9:.3g} GB available; "
            "make the scene, the action grid or control.samples smaller"
        )


def available_memory_bytes() -> float:
    """The memory the machine can give now without swapping (psutil's ``available``), bytes."""
    return psutil.virtual_memory().available
