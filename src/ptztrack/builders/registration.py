"""Registration of a recording scenario's live views: its camera at the registration resolution, its
reference index and the registered pose source (:mod:`ptztrack.camera.pose_feedback`)."""

import numpy as np

from ptztrack.camera.pose_feedback import RegisteredPose, build_reference_index, cached_reference_index, reference_poses
from ptztrack.camera.virtual import VirtualPTZ, virtual_ptz
from ptztrack.config import Scenario
from ptztrack.geometry.calibration import load_calibration
from ptztrack.geometry.registration import ReferenceIndex
from ptztrack.scene.pets import RecordedVideo

# The reference views are rendered from this frame of the recording; live views come from later frames,
# where people have moved.
REFERENCE_FRAME = 0
# The stream that draws how roughly the reference views' poses are known: one for all runs and seeds,
# so that they share one reference index.
REFERENCE_SEED = 20091


def registration_camera(scenario: Scenario) -> tuple[VirtualPTZ, np.ndarray]:
    """The recording scenario's virtual camera at ``pose_feedback.image_size_px``, and its whole-frame pose."""
    recording = scenario.required_recording("registration")
    calibration = load_calibration(recording.calibration, recording.view)
    return virtual_ptz(calibration, recording.recorded_size_px, scenario.pose_feedback.image_size_px)


def reference_index(scenario: Scenario, camera: tuple[VirtualPTZ, np.ndarray] | None = None) -> ReferenceIndex:
    """The reference index of a recording scenario: views over its action grid's pan and tilt range,
    rendered from the recording's frame ``REFERENCE_FRAME``. Read from ``pose_feedback.index`` when
    that file exists; built otherwise (about a minute), and written there when a path is given.

    camera : ``registration_camera(scenario)``, when the caller has it already.
    """
    recording, feedback = scenario.required_recording("registration"), scenario.pose_feedback
    video_path = scenario.required_video("registration")
    virtual, whole_frame_pose = camera or registration_camera(scenario)
    pan_deg, tilt_deg = scenario.actions.pan_deg.values(), scenario.actions.tilt_deg.values()
    poses = reference_poses(
        whole_frame_pose,
        (pan_deg.min(), pan_deg.max()),
        (tilt_deg.min(), tilt_deg.max()),
        feedback.reference_pan_steps,
        feedback.reference_tilt_steps,
        feedback.reference_zooms,
    )

    def build():
        frame = RecordedVideo(video_path, recording.recorded_size_px).frame(REFERENCE_FRAME)
        rng = np.random.default_rng(REFERENCE_SEED)
        return build_reference_index(
            virtual, frame, poses, feedback.reference_pose_sigma_deg, feedback.reference_zoom_spread, rng
        )

    return cached_reference_index(feedback.index, build)


def registered_pose_source(scenario: Scenario, video_frame: np.ndarray) -> RegisteredPose:
    """The registered pose source of a recording scenario whose step ``t`` shows frame ``video_frame[t]``."""
    recording = scenario.required_recording("registration")
    camera = registration_camera(scenario)
    video = RecordedVideo(scenario.required_video("registration"), recording.recorded_size_px)
    return RegisteredPose(camera[0], reference_index(scenario, camera), video, video_frame)
