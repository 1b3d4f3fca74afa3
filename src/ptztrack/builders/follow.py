"""The follow camera from a scenario: its trackers ('particle', 'csrt', 'mil') and its policy ('follow').

The scenario's ``follow`` section holds the parameters (rates per second);
here they become the per-step dataclasses of :mod:`ptztrack.follow.particle_filter`,
:mod:`ptztrack.follow.target` and :mod:`ptztrack.follow.controller`. The person
followed is ``follow.target_id``, started from their annotated box at the
first step, moved into the view the camera is at before it.
"""

import numpy as np

from ptztrack.builders.parameters import parameters_from
from ptztrack.builders.recording import recorded_size_px
from ptztrack.camera.recorded import RecordedPTZ
from ptztrack.camera.virtual import virtual_ptz
from ptztrack.config import Actions, Scenario, ScenarioError
from ptztrack.follow.controller import FollowPolicy, FramingParameters, framing_pose
from ptztrack.follow.parameters import FollowParameters
from ptztrack.follow.particle_filter import particle_filter_parameters, smoothing_pole
from ptztrack.follow.target import OpenCVSource, ParticleSource, TargetSource, TargetTracker, opencv_tracker_factory
from ptztrack.geometry.calibration import load_calibration
from ptztrack.geometry.ptz import PTZCamera, aim_at
from ptztrack.loop.steps import World
from ptztrack.names import FOLLOW_TRACKERS
from ptztrack.scene.pets import load_mot_ground_truth


def follow_parameters(scenario: Scenario) -> FollowParameters:
    """The scenario's follow section as the follow camera's parameters."""
    return parameters_from(scenario.follow, FollowParameters)


def framing_parameters(scenario: Scenario, camera: PTZCamera) -> FramingParameters:
    follow = scenario.follow
    target_point_px = follow.target_point_px or (camera.image_width_px / 2, camera.image_height_px / 2)
    if not (0 <= target_point_px[0] <= camera.image_width_px and 0 <= target_point_px[1] <= camera.image_height_px):
        raise ScenarioError(
            f"follow.target_point_px: {list(target_point_px)} lies outside the "
            f"{camera.image_width_px} x {camera.image_height_px} image"
        )
    return FramingParameters(
        follow=follow_parameters(scenario),
        target_point_px=np.asarray(target_point_px, dtype=float),
        person_height_m=scenario.control.person_height_m,
        person_width_m=scenario.people.width_m,
        step_s=1.0 / scenario.frame_rate_hz,
    )


def follow_policy(scenario: Scenario, world: World) -> FollowPolicy:
    return FollowPolicy(world.camera, framing_parameters(scenario, world.camera))


def initial_box(scenario: Scenario, world: World) -> tuple[np.ndarray, np.ndarray]:
    """The followed person's annotated box at the first step, in the view the camera starts at.

    Returns the box (4,) (left, top, width, height) px (the bounding box of the annotated box's
    corners in the view) and that view's pose (3,).
    """
    target_id = scenario.follow.target_id
    if target_id is None:
        raise ScenarioError("the follow camera needs a person to follow (follow.target_id)")
    backend = world.backend
    if not isinstance(backend, RecordedPTZ):
        raise ScenarioError("the follow camera needs a recording seen by the virtual camera (camera.backend 'virtual')")
    annotations = backend.scene.annotations
    first_frame = backend.scene.video_frame[0]
    row = np.flatnonzero((annotations.person_id == target_id) & (annotations.frame == first_frame))
    if len(row) == 0:
        raise ScenarioError(
            f"follow.target_id: person {target_id} is not annotated at the first step (frame {first_frame})"
        )
    left, top, width, height = annotations.box_px[row[0]]
    corners = np.array([[left, top], [left + width, top], [left, top + height], [left + width, top + height]])
    start_pose = world.grid.poses[world.start_action]
    in_view = backend.virtual.recorded_to_virtual(corners, start_pose)
    low, high = in_view.min(axis=0), in_view.max(axis=0)
    return np.r_[low, high - low], start_pose


def target_source(scenario: Scenario, tracker: str, rng: np.random.Generator) -> TargetSource:
    """The source of a follow tracker by name: 'particle' (drawing from ``rng``), 'csrt' or 'mil'."""
    if tracker == "particle":
        return ParticleSource(particle_filter_parameters(follow_parameters(scenario), scenario.frame_rate_hz), rng)
    if tracker in ("csrt", "mil"):
        return OpenCVSource(opencv_tracker_factory(tracker))
    raise ScenarioError(f"no follow tracker {tracker!r}; expected one of {', '.join(FOLLOW_TRACKERS)}")


def _target_tracker(scenario: Scenario, world: World, tracker: str) -> TargetTracker:
    box_px, start_pose = initial_box(scenario, world)
    # A world built without the episode's tracker stream (build_world called directly) draws from seed 0.
    rng = np.random.default_rng(world.tracker_seed if world.tracker_seed is not None else 0)
    return TargetTracker(
        world.camera,
        target_source(scenario, tracker, rng),
        box_px,
        start_pose,
        scenario.control.person_height_m,
        smoothing_pole(scenario.follow.smoothing_cutoff_hz, scenario.frame_rate_hz),
        1.0 / scenario.frame_rate_hz,
    )


def particle_tracker(scenario: Scenario, world: World) -> TargetTracker:
    """The robot-cameraman paper's particle filter, drawing from the episode's tracker stream."""
    return _target_tracker(scenario, world, "particle")


def csrt_tracker(scenario: Scenario, world: World) -> TargetTracker:
    """OpenCV's CSRT tracker (discriminative correlation filter with channel and spatial reliability)."""
    return _target_tracker(scenario, world, "csrt")


def mil_tracker(scenario: Scenario, world: World) -> TargetTracker:
    """OpenCV's MIL tracker (multiple-instance learning)."""
    return _target_tracker(scenario, world, "mil")


def refuse_unknown_people(ground_truth: str, annotated_ids, wanted) -> None:
    """A :class:`ScenarioError` naming every id of ``wanted`` that ``ground_truth`` does not annotate
    (``annotated_ids``: the ids it does, repeated or not)."""
    known = np.unique(annotated_ids)
    missing = [int(person) for person in wanted if person not in known]
    if missing:
        people = ", ".join(str(person) for person in known)
        names = f"person {missing[0]}" if len(missing) == 1 else f"people {', '.join(map(str, missing))}"
        raise ScenarioError(f"{ground_truth}: no {names} (the people are {people})")


def target_scenario(scenario: Scenario, target_id: int) -> Scenario:
    """The scenario narrowed to one person.

    ``follow.target_id`` is set; the steps run from the person's first annotated frame to their last
    (``recording.frame_range``; ``frames``, at most the scenario's); and the action grid becomes the
    one pose that frames the person at their first annotated position, where the camera starts (as a
    camera operator would hand a framed shot over to the controller; the policy commands every later
    pose itself).
    """
    recording = scenario.required_recording("the follow camera")
    annotations = load_mot_ground_truth(recording.ground_truth)
    refuse_unknown_people(recording.ground_truth, annotations.person_id, [target_id])
    rows = np.flatnonzero(annotations.person_id == target_id)
    rows = rows[np.argsort(annotations.frame[rows])]
    first, last = int(annotations.frame[rows[0]]), int(annotations.frame[rows[-1]])
    calibration = load_calibration(recording.calibration, recording.view)
    virtual, whole_frame_pose = virtual_ptz(
        calibration,
        recorded_size_px(recording),
        scenario.camera.image_size_px,
    )
    position_m = annotations.ground_m[rows[0]]
    parameters = framing_parameters(scenario, virtual.camera)
    middle_m = np.r_[position_m, parameters.person_height_m / 2]
    centred = aim_at(virtual.camera, middle_m, virtual.camera.principal_point_px, 1.0)
    start = framing_pose(virtual.camera, position_m, centred, parameters) - [*whole_frame_pose[:2], 0.0]
    actions = {
        "pan_deg": {"start": start[0], "stop": start[0], "count": 1},
        "tilt_deg": {"start": start[1], "stop": start[1], "count": 1},
        "zoom": (start[2],),
    }
    return scenario.model_copy(
        update={
            "frames": min(scenario.frames, (last - first) // recording.frame_step + 1),
            "actions": Actions.model_validate(actions),
            "follow": scenario.follow.model_copy(update={"target_id": target_id}),
            "recording": recording.model_copy(update={"frame_range": (first, last + 1)}),
        }
    )
