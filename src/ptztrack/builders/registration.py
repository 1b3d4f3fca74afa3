"""Registration of a recording scenario's live views: its camera at the registration resolution, how
its views depart from the pinhole model, its reference index and the registered pose source
(:mod:`ptztrack.camera.pose_feedback`)."""

import numpy as np

from ptztrack.builders.parameters import parameters_from
from ptztrack.builders.recording import recorded_size_px
from ptztrack.camera.live_view import k1_at_zoom
from ptztrack.camera.parameters import LiveViewParameters
from ptztrack.camera.pose_feedback import RegisteredPose, build_reference_index, cached_reference_index, reference_poses
from ptztrack.camera.virtual import VirtualPTZ, virtual_ptz
from ptztrack.config import Scenario, ScenarioError
from ptztrack.geometry.calibration import PinholeCalibration, load_calibration
from ptztrack.geometry.lens import corner_radius2, distortion_invertible
from ptztrack.geometry.registration import ReferenceIndex
from ptztrack.scene.pets import RecordedVideo

# The reference views are taken in a sweep, one every REFERENCE_FRAME_STEP frames from
# REFERENCE_FIRST_FRAME: the odd frames 1, 3, ..., which the recording scenarios' closed loop (every
# 2nd frame from 0) never shows, so no live view is ever of a reference view's frame.
REFERENCE_FIRST_FRAME = 1
REFERENCE_FRAME_STEP = 2
LIVE_GAP_S = 30.0
"""The registration experiment's live views are of frames at least this long after the last reference
view's: people have moved on, and the light has changed."""
# The stream that draws how roughly the reference views' poses are known: one for all runs and seeds,
# so that they share one reference index.
REFERENCE_SEED = 20091


def registration_camera(
    scenario: Scenario, calibration: PinholeCalibration | None = None
) -> tuple[VirtualPTZ, np.ndarray]:
    """The recording scenario's virtual camera at ``pose_feedback.image_size_px``, and its whole-frame pose.

    calibration : the recording's, when the caller has read it already.
    """
    recording = scenario.required_recording("registration")
    calibration = calibration or load_calibration(recording.calibration, recording.view)
    return virtual_ptz(
        calibration,
        recorded_size_px(recording),
        scenario.pose_feedback.image_size_px,
    )


def live_view_model(scenario: Scenario, calibration: PinholeCalibration | None = None) -> LiveViewParameters | None:
    """The scenario's ``camera.live_view`` as the camera layer's model; None for exact pinhole views.
    Its principal point offset is in pixels of the registered image. calibration : the recording's,
    when the caller has read it already."""
    live_view = scenario.camera.live_view
    if live_view is None:
        return None
    model = parameters_from(
        live_view, LiveViewParameters, offset_image_width_px=scenario.pose_feedback.image_size_px[0]
    )
    camera = registration_camera(scenario, calibration)[0].camera
    for zoom in np.linspace(1.0, max(max(scenario.actions.zoom), model.tele_zoom), 50):
        if not distortion_invertible(k1_at_zoom(model, zoom), corner_radius2(camera, zoom)):
            raise ScenarioError(
                f"camera.live_view: k1 {k1_at_zoom(model, zoom):g} at zoom {zoom:.2f} bends the image corners "
                f"back towards the centre (k1_wide {model.k1_wide:g}, k1_tele {model.k1_tele:g})"
            )
    return model


def reference_frames(views: int) -> np.ndarray:
    """(views,) the recorded frame of each reference view, in the order of the sweep."""
    return REFERENCE_FIRST_FRAME + REFERENCE_FRAME_STEP * np.arange(views)


def scenario_reference_poses(scenario: Scenario, whole_frame_pose) -> np.ndarray:
    """(L, 3) the reference views' poses: ``pose_feedback``'s grid over the action grid's pan and tilt range."""
    feedback = scenario.pose_feedback
    pan_deg, tilt_deg = scenario.actions.pan_deg.values(), scenario.actions.tilt_deg.values()
    return reference_poses(
        whole_frame_pose,
        (pan_deg.min(), pan_deg.max()),
        (tilt_deg.min(), tilt_deg.max()),
        feedback.reference_pan_steps,
        feedback.reference_tilt_steps,
        feedback.reference_zooms,
    )


def reference_index(
    scenario: Scenario, camera: tuple[VirtualPTZ, np.ndarray] | None = None, video: RecordedVideo | None = None
) -> ReferenceIndex:
    """The reference index of a recording scenario: views over its action grid's pan and tilt range,
    rendered from the frames of :func:`reference_frames`. Read from ``pose_feedback.index`` when that
    file exists; built otherwise (about a minute), and written there when a path is given.

    camera : ``registration_camera(scenario)``, video : the recording's video, when the caller has them.
    """
    recording, feedback = scenario.required_recording("registration"), scenario.pose_feedback
    video_path = scenario.required_video("registration")
    virtual, whole_frame_pose = camera or registration_camera(scenario)
    poses = scenario_reference_poses(scenario, whole_frame_pose)

    def build():
        numbers = reference_frames(len(poses))
        source = video or RecordedVideo(
            video_path,
            recorded_size_px(recording),
            int(numbers[-1]) + 1,
        )
        frames = [source.frame(int(frame)) for frame in numbers]
        rng = np.random.default_rng(REFERENCE_SEED)
        return build_reference_index(
            virtual, frames, poses, feedback.reference_pose_sigma_deg, feedback.reference_zoom_spread, rng
        )

    return cached_reference_index(feedback.index, build)


def registered_pose_source(
    scenario: Scenario, video_frame: np.ndarray, calibration: PinholeCalibration, video: RecordedVideo
) -> RegisteredPose:
    """The registered pose source of a recording scenario whose step ``t`` shows frame ``video_frame[t]``
    of ``video``; it registers the views of ``camera.live_view``. calibration : the recording's."""
    camera = registration_camera(scenario, calibration)
    index = reference_index(scenario, camera, video)
    return RegisteredPose(camera[0], index, video, video_frame, live_view_model(scenario, calibration))
