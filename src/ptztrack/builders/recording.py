"""One view of a dataset file as a scenario: the recording seen by the virtual PTZ camera.

Everything that depends on the recording comes from its dataset file (docs: dataset files): the
calibration, the video and its image size, the ground truth (the view's own, else the dataset's), the
precomputed boxes, and the frame rate. The experiment brings its protocol (:data:`TABLES_PROTOCOL`,
:data:`FOLLOW_PROTOCOL`): the step rate it asks for, the virtual camera's image width, the action grid,
the detector. From both follow

* the frame step, the whole number of recorded frames nearest to one step of the protocol's rate
  (every frame for a protocol without one); the step rate becomes the recording's frame rate over that
  step, so that the tracker predicts over the time that really passes, and a rate that differs from
  the protocol's is warned of in one line;
* the steps, the annotated frames (up to the last one annotated) at that step;
* the zooms, up to where the virtual view reads the recording at its own resolution
  (:func:`recorded_zooms`, unless the protocol gives them);
* the virtual camera's image, and the image registration reads (``pose_feedback.image_size_px``), each the
  protocol's width at the recording's aspect ratio.

The built-in recording, PETS 2009 S2.L1, is one such file
(:data:`~ptztrack.config.dataset.PETS_DATASET_FILE`).
"""

import logging
import math
from pathlib import Path

from ptztrack.config import (
    PETS_DATASET_FILE,
    DatasetView,
    MultiViewDataset,
    PoseFeedback,
    Recording,
    Scenario,
    ScenarioError,
    pets_dataset,
    scenario_from_dict,
)
from ptztrack.control.parameters import ControlParameters
from ptztrack.geometry.calibration import load_tsai
from ptztrack.names import PetsProtocol
from ptztrack.scene.pets import RecordedVideo, load_mot_ground_truth, refuse_rows_beyond

log = logging.getLogger(__name__)

PETS_VIEW = "View_001"
"""The view of the built-in recording that the PTZ commands run on (the only one with a video)."""

TABLES_PROTOCOL: dict = {
    "frame_rate_hz": 5.0,
    "camera": {"image_size_px": (160, 120)},
    "actions": {
        "pan_deg": {"start": -14.0, "stop": 14.0, "count": 7},
        "tilt_deg": {"start": -10.0, "stop": 10.0, "count": 5},
    },
    # A person's box as the policies see it: the Caltech benchmark's standardised pedestrian aspect
    # ratio, width = 0.41 x height (Dollar et al., "Pedestrian detection: an evaluation of the state
    # of the art", 2012), at the policies' person height.
    "people": {"width_m": 0.41 * ControlParameters.person_height_m},
    # People come and go in a recording (section 5.2): the patrolling term looks for them.
    "control": {"beta": 1.0},
    # The annotated people the camera sees whole (Table 3); hog and detections read the pictures or boxes.
    "detector": {"kind": PetsProtocol.detector},
}
"""The PTZ paper's realistic experiment (section 5.2), the same on every recording: steps at 5 Hz, the
paper's 160-pixel-wide "zoom 1" view of the whole recorded frame, its 7 x 5 pan and tilt grid (offsets
from the whole-frame view, degrees) and the zooms the recording can show (:func:`recorded_zooms`)."""

FOLLOW_PROTOCOL: dict = {
    "frame_rate_hz": None,
    "camera": {"image_size_px": (640, 480)},
    # One action: the view of the whole recorded frame, where the camera starts; the policy commands
    # every other pose itself.
    "actions": {
        "pan_deg": {"start": 0.0, "stop": 0.0, "count": 1},
        "tilt_deg": {"start": 0.0, "stop": 0.0, "count": 1},
        "zoom": (1.0,),
    },
    # The annotations lie about 2 px from the calibrated feet in a 768 px frame (0.5 px at 160 px).
    "detector": {"kind": "ideal", "pixel_noise_px": 0.5},
    # The virtual camera interpolates its sampling map over 8 px, which keeps a view's rendering at a
    # few milliseconds.
    "recording": {"map_grid_px": 8},
}
"""The follow camera (the robot-cameraman paper): every recorded frame, seen by the paper's 640-pixel-wide
camera (section IV); :func:`ptztrack.builders.follow.target_scenario` narrows the steps to the target's
annotated frames."""


def dataset_view(dataset: MultiViewDataset, name: str | None, label: str) -> tuple[int, DatasetView]:
    """The view ``name`` of ``dataset`` and its index (None: the first view with a video); a
    :class:`ScenarioError` starting with ``label`` and naming the views there are when there is no such view."""
    for index, view in enumerate(dataset.views):
        if view.name == name or (name is None and view.video is not None):
            return index, view
    names = ", ".join(view.name for view in dataset.views)
    wanted = f"no view {name!r}" if name is not None else "no view with a video"
    raise ScenarioError(f"{label}: {wanted} (views: {names})")


def stated_size_px(stated_px, calibration: str) -> tuple[int, int] | None:
    """A recording's frames' (width, height) px as its files state them: ``stated_px`` (a scenario's
    ``recorded_size_px``, a dataset view's ``image_size_px``), else a Tsai calibration's; None where only
    the frames tell."""
    if stated_px is not None:
        return (int(stated_px[0]), int(stated_px[1]))
    if Path(calibration).suffix.lower() == ".xml":
        return load_tsai(calibration).image_size_px
    return None


def frames_size_px(stated_px, calibration: str, video: str | None) -> tuple[int, int]:
    """A recording's frames' (width, height) px: :func:`stated_size_px`, else the ``video``'s first frame's."""
    size_px = stated_size_px(stated_px, calibration)
    if size_px is not None:
        return size_px
    if video is None:
        raise ScenarioError(
            f"{calibration}: a pinhole calibration states no image size: give the recording's image size or a video"
        )
    return _frame_size_px(RecordedVideo(video))


def _frame_size_px(video: RecordedVideo) -> tuple[int, int]:
    first = video.frame(0)
    return (int(first.shape[1]), int(first.shape[0]))


def recorded_size_px(recording: Recording) -> tuple[int, int]:
    """A scenario's recorded frames' (width, height) px (:func:`frames_size_px` of its recording)."""
    return frames_size_px(recording.recorded_size_px, recording.calibration, recording.video)


def recorded_zooms(recorded_width_px: int, view_width_px: int) -> tuple[float, ...]:
    """The zooms 1, 2, ... up to the largest at which the virtual view still reads the recording at its own
    resolution or coarser, ``recorded_width_px // view_width_px`` (at least 1): the paper's 4 steps on
    PETS (768 // 160), more where the recording has the pixels, so that a zoomed view never shows more
    detail than was recorded."""
    return tuple(float(zoom) for zoom in range(1, max(1, recorded_width_px // view_width_px) + 1))


def frame_step(frame_rate_hz: float, step_rate_hz: float | None) -> int:
    """The recorded frames between two steps: the whole number of frames whose duration is nearest a
    step of ``step_rate_hz``, a tie to the shorter step, at least 1 (None: every frame)."""
    if step_rate_hz is None:
        return 1
    return max(1, math.ceil(frame_rate_hz / step_rate_hz - 0.5))


def dataset_scenario(
    dataset: MultiViewDataset,
    view: str | None = None,
    protocol: dict | None = None,
    dataset_file: str | Path | None = None,
    **overrides,
) -> Scenario:
    """The scenario of ``view`` of ``dataset`` (None: its first view with a video) under ``protocol``
    (a scenario mapping; default :data:`TABLES_PROTOCOL`, whose ``frame_rate_hz`` is the step rate asked),
    with scenario ``overrides`` (``"section.field": value``) applied last; see the module's docstring.

    dataset_file : the file ``dataset`` was read from, kept as ``recording.dataset`` (its other views are
    a camera network's fixed cameras). Refused in one line before any work: a view without a video, a
    recording without ground truth, frames of another size than the file states, and ground truth of
    frames the video lacks.
    """
    protocol = TABLES_PROTOCOL if protocol is None else protocol
    label = dataset.name if dataset_file is None else str(dataset_file)
    index, chosen = dataset_view(dataset, view, label)
    field = f"views.{index} ({chosen.name})"
    if chosen.video is None:
        raise ScenarioError(
            f"{label}: {field} has no video: the virtual PTZ camera renders its views from one "
            "(an images folder is read by the occupancy map only)"
        )
    ground_truth = chosen.ground_truth or dataset.ground_truth
    if ground_truth is None:
        raise ScenarioError(f"{label}: {field} has no ground truth (ground_truth, of the dataset or the view)")
    # The video is opened once: it checks a stated size against its frames, or gives the size.
    video = RecordedVideo(chosen.video, stated_size_px(chosen.image_size_px, chosen.calibration))
    size_px = _frame_size_px(video)
    annotations = load_mot_ground_truth(ground_truth)
    refuse_rows_beyond(
        ground_truth,
        annotations.frame,
        annotations.line,
        video.frame_count,
        f"the {video.frame_count} frames of {video.path}",
    )
    step_rate_hz = protocol.get("frame_rate_hz")
    step = frame_step(dataset.frame_rate_hz, step_rate_hz)
    rate_hz = dataset.frame_rate_hz / step
    if step_rate_hz is not None and not math.isclose(rate_hz, step_rate_hz, rel_tol=1e-9):
        log.warning(
            f"{label}: its {dataset.frame_rate_hz:g} fps give steps of {rate_hz:.4g} Hz (every {step} "
            f"frame{'s' if step > 1 else ''}), not the protocol's {step_rate_hz:g} Hz; the tracker predicts "
            f"{1 / rate_hz:.3g} s a step"
        )
    recorded_width_px, recorded_height_px = size_px
    view_width_px = protocol.get("camera", {}).get("image_size_px", TABLES_PROTOCOL["camera"]["image_size_px"])[0]
    registered_width_px = protocol.get("pose_feedback", {}).get("image_size_px", PoseFeedback().image_size_px)[0]
    calibration_view = chosen.calibration_view or chosen.name
    recording = {
        **protocol.get("recording", {}),
        "ground_truth": ground_truth,
        "calibration": chosen.calibration,
        "view": None if Path(chosen.calibration).suffix.lower() == ".xml" else calibration_view,
        "video": chosen.video,
        "recorded_size_px": size_px,
        "frame_step": step,
        "detections": chosen.detections,
        "dataset": None if dataset_file is None else str(dataset_file),
        "dataset_view": chosen.name,
        "tracking_area_m": dataset.tracking_area_m,
        "name": f"{dataset.name} {chosen.name}",
    }
    actions = protocol.get("actions", {})
    if "zoom" not in actions:
        actions = {**actions, "zoom": recorded_zooms(recorded_width_px, view_width_px)}
    data = {
        **protocol,
        "actions": actions,
        "frames": protocol.get("frames") or math.ceil((int(annotations.frame.max()) + 1) / step),
        "frame_rate_hz": rate_hz,
        "camera": {
            **protocol.get("camera", {}),
            "image_size_px": (view_width_px, round(view_width_px * recorded_height_px / recorded_width_px)),
        },
        "pose_feedback": {
            **protocol.get("pose_feedback", {}),
            "image_size_px": (registered_width_px, round(registered_width_px * recorded_height_px / recorded_width_px)),
        },
        "recording": recording,
    }
    return scenario_from_dict(data, f"{dataset.name} {chosen.name}", **overrides)


def pets_scenario(detector: str = "ideal", **overrides) -> Scenario:
    """The built-in PETS 2009 S2.L1 scenario: the paper's realistic experiment (section 5.2) on View_001,
    every parameter fixed a priori (:func:`ptztrack.experiments.ptz_tables.protocol_folds` fits the
    detector's model on frames a table does not score). detector : any registered detector ('ideal': the
    annotated boxes, 'hog': OpenCV's people detector on the view, 'detections': the shipped boxes)."""
    return dataset_scenario(
        pets_dataset(), PETS_VIEW, TABLES_PROTOCOL, PETS_DATASET_FILE, **{"detector.kind": detector, **overrides}
    )


def pets_follow_scenario(tracker: str = "particle", **overrides) -> Scenario:
    """The follow camera on PETS 2009 S2.L1's View_001 (:data:`FOLLOW_PROTOCOL`). tracker : 'particle',
    'csrt' or 'mil'. The person is ``follow.target_id``."""
    return dataset_scenario(
        pets_dataset(), PETS_VIEW, FOLLOW_PROTOCOL, PETS_DATASET_FILE, **{"tracker.kind": tracker, **overrides}
    )
