"""A camera's calibration file as the camera layer's objects: its spaces and its poses' timeline."""

from ptztrack.camera.onvif_spaces import CameraSpaces, MoveTimes
from ptztrack.camera.pose_timeline import PoseTimeline
from ptztrack.config import CameraCalibrationFile


def camera_spaces(calibration: CameraCalibrationFile) -> CameraSpaces:
    """The mapping of the camera's normalised ONVIF spaces to the model's pose that the file gives."""
    return CameraSpaces(
        calibration.pan_deg, calibration.tilt_deg, tuple((float(z), float(f)) for z, f in calibration.zoom_curve)
    )


def pose_timeline(calibration: CameraCalibrationFile) -> PoseTimeline:
    """The timeline of a camera's poses with its calibrated move times and capture times' uncertainty."""
    move_times = MoveTimes(calibration.move_times.pan, calibration.move_times.tilt, calibration.move_times.zoom)
    return PoseTimeline(move_times, calibration.capture_time_sd_s)
