"""ptztrack's own implementations of the roles, by name (:mod:`ptztrack.registry` points here).

Policies and trackers are made from a scenario and its :class:`~ptztrack.loop.steps.World`;
camera backends and detectors from a scenario and its :class:`~ptztrack.builders.world.BuiltScene`.
"""

import math
from functools import partial

from ptztrack.builders.parameters import parameters_from
from ptztrack.builders.registration import live_view_model
from ptztrack.builders.world import recall_model
from ptztrack.camera.recorded import RecordedPTZ
from ptztrack.camera.simulated import SimulatedPTZ
from ptztrack.config import MAX_DATASET_FRAMES, Scenario, ScenarioError
from ptztrack.control.baselines import FixPolicy, PatrolPolicy, RandomPolicy, patrol_route, widest_view_action
from ptztrack.control.exploration import exploration_map
from ptztrack.control.information_gain import expected_detection_probability
from ptztrack.control.information_policy import InformationGainPolicy, InformationMethod
from ptztrack.detect.hog import GroundSearch, HogPeopleDetector
from ptztrack.detect.published import PublishedDetections
from ptztrack.detect.simulated import AnnotationDetector, RecallCurve, RecallDetector, RecallModel
from ptztrack.loop.steps import World
from ptztrack.occupancy.multiview import load_mot_detections
from ptztrack.track.parameters import TrackerParameters
from ptztrack.track.pixel_noise import pixel_noise_covariance
from ptztrack.track.templates import TemplateTracker
from ptztrack.track.tracker import DetectionModel, EkfTracker


def expected_model(scenario: Scenario, world: World) -> RecallCurve:
    """The detector model the tracker expects: the world's (its posterior mode as the run goes), or for
    a world built without one the scenario's curve."""
    return world.detector_model if world.detector_model is not None else recall_model(scenario)


def planning_model(scenario: Scenario, world: World) -> RecallCurve:
    """The detector model the policies plan with: the world's latest draw, or the scenario's curve."""
    return world.detector_model.planner() if world.detector_model is not None else recall_model(scenario)


def pixel_noise(scenario: Scenario):
    """``V`` (2, 2) px^2 of the scenario's detector."""
    return pixel_noise_covariance(scenario.detector.pixel_noise_px)


def people_can_leave(scenario: Scenario) -> bool:
    """A recording's people and replayed trajectories come and go; the synthetic walkers only with
    ``people.enter_leave``."""
    return scenario.recording is not None or scenario.people.trajectories is not None or scenario.people.enter_leave


def tracker_parameters(scenario: Scenario) -> TrackerParameters:
    """The tracker's parameters; uncertainty deletes a track only where people can leave."""
    if people_can_leave(scenario):
        return parameters_from(scenario.tracker, TrackerParameters)
    return parameters_from(scenario.tracker, TrackerParameters, max_position_sigma_m=math.inf)


def detection_model(scenario: Scenario, world: World) -> DetectionModel:
    """What the tracker expects the detector to find: the policies' own model of it."""
    return partial(
        expected_detection_probability,
        world.camera,
        expected_model(scenario, world),
        pixel_noise(scenario),
        scenario.control.person_height_m,
        scenario.people.width_m,
    )


def fix_policy(scenario: Scenario, world: World) -> FixPolicy:
    return FixPolicy(widest_view_action(world.camera, world.grid, world.area_polygon_m))


def patrol_policy(scenario: Scenario, world: World) -> PatrolPolicy:
    return PatrolPolicy(world.grid, patrol_route(world.camera, world.grid, world.area_polygon_m))


def random_policy(scenario: Scenario, world: World) -> RandomPolicy:
    return RandomPolicy()


def information_policy(scenario: Scenario, world: World, method: InformationMethod) -> InformationGainPolicy:
    """The information-gain policy ``method`` ('intg' or 'smpl') of the camera of ``world``."""
    control, recall = scenario.control, planning_model(scenario, world)
    exploration = None
    if control.beta > 0:
        exploration = exploration_map(
            world.camera,
            world.grid.poses,
            world.area_polygon_m,
            recall,
            control.person_height_m,
            control.exploration_cell_m,
            control.prior_untracked_people,
            control.arrival_rate_per_s,
            1.0 / scenario.frame_rate_hz,
        )
    return InformationGainPolicy(
        world.camera,
        world.grid,
        recall,
        pixel_noise(scenario),
        control.person_height_m,
        scenario.people.width_m,
        method,
        control.samples,
        control.beta,
        exploration,
    )


def intg_policy(scenario: Scenario, world: World) -> InformationGainPolicy:
    return information_policy(scenario, world, "intg")


def smpl_policy(scenario: Scenario, world: World) -> InformationGainPolicy:
    return information_policy(scenario, world, "smpl")


def _simulated_detector(scenario: Scenario, scene, recall: RecallModel):
    detector = scenario.detector
    size = (scene.camera.image_width_px, scene.camera.image_height_px)
    return RecallDetector(recall, detector.pixel_noise_px, detector.false_positives_per_frame, size)


def ideal_detector(scenario: Scenario, scene):
    """The synthetic scene: recall 1, occluded people missed in proportion; a recording: the annotated
    people wholly in view and hidden at most ``recording.occluded_above``."""
    if scene.recording is not None:
        occluded_above = scenario.required_recording("the ideal detector of a recording").occluded_above
        return AnnotationDetector(scenario.detector.pixel_noise_px, occluded_above)
    return _simulated_detector(scenario, scene, recall_model(scenario))


def realistic_detector(scenario: Scenario, scene):
    """The recall curve of the scenario (equation 13), occluded people missed in proportion."""
    return _simulated_detector(scenario, scene, recall_model(scenario))


def hog_detector(scenario: Scenario, scene) -> HogPeopleDetector:
    """OpenCV's HOG; with ``hog_search`` 'ground', only where the scene's camera can show a standing person
    on its walkable area; on the pictures' luma only where ``hog_luma`` says so."""
    detector = scenario.detector
    search = None
    if detector.hog_search == "ground":
        search = GroundSearch(scene.camera, scene.area_polygon_m, detector.hog_person_height_m)
    return HogPeopleDetector(
        detector.hog_upsample, detector.hog_hit_threshold, detector.hog_nms_iou, search, bool(detector.hog_luma)
    )


def detections_detector(scenario: Scenario, scene) -> PublishedDetections:
    """A recording's precomputed boxes (``recording.detections``, a dataset view's ``detections``) of each
    step's frame, scored at least ``detector.box_min_score``, carried into the virtual PTZ camera's image
    at its pose; those whose feet and head fall inside it."""
    recording = scenario.required_recording("detector.kind 'detections'")
    if recording.detections is None or scene.virtual is None or scene.recording is None:
        raise ScenarioError(
            "detector.kind 'detections' needs the recorded view's boxes (recording.detections; a dataset view's "
            "detections)"
        )
    boxes = load_mot_detections(recording.detections, MAX_DATASET_FRAMES, scene.virtual.recorded_size_px)
    return PublishedDetections(
        scene.camera, scene.virtual.recording, boxes, scene.recording.video_frame, scenario.detector.box_min_score, True
    )


def simulated_camera(scenario: Scenario, scene) -> SimulatedPTZ:
    return SimulatedPTZ(scene.camera, scene.truth)


def virtual_camera(scenario: Scenario, scene) -> RecordedPTZ:
    """The virtual PTZ camera over the scenario's recording (images only if it names a video)."""
    scenario.required_recording("camera.backend 'virtual'")
    return RecordedPTZ(scene.virtual, scene.recording, scene.video, live_view_model(scenario, scene.calibration))


def ekf_tracker(scenario: Scenario, world: World) -> EkfTracker | TemplateTracker:
    """One EKF per person on the ground (``tracker.association``), measured by the detector or, with
    ``tracker.measurement_source`` 'spatiogram', by colour templates between detector steps."""
    config = scenario.tracker
    parameters, model = tracker_parameters(scenario), detection_model(scenario, world)
    learned = world.detector_model
    tracker = EkfTracker(
        world.camera,
        1.0 / scenario.frame_rate_hz,
        pixel_noise(scenario),
        parameters,
        model,
        learner=None if learned is None else learned.observe,
        clutter_per_view=None if learned is None or not learned.learning else lambda: learned.clutter_per_view,
        area_polygon_m=world.area_polygon_m if parameters.keep_within_area and not people_can_leave(scenario) else None,
    )
    if config.measurement_source == "detector":
        return tracker
    height_m, width_m = scenario.control.person_height_m, scenario.people.width_m
    return TemplateTracker(tracker, config.detector_every_steps, height_m, width_m)
