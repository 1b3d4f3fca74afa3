"""A real (or virtual) ONVIF PTZ camera's calibration file (docs: real cameras): its model, read and
written."""

from pathlib import Path
from typing import Annotated

import numpy as np
import pydantic
import yaml
from pydantic import Field, model_validator

from ptztrack.config.fields import (
    Degrees,
    NonNegativeFloat,
    PositiveFloat,
    _Coordinate,
    _Strict,
    _Zoom,
    at_most,
    at_most_items,
)
from ptztrack.config.reading import FILE_KINDS, ScenarioError, _first_error_line, read_yaml, refuse_another_kind
from ptztrack.files import write_atomically

_MoveTime = tuple[
    Annotated[NonNegativeFloat, at_most(60, "seconds")], Annotated[NonNegativeFloat, at_most(60, "seconds per unit")]
]


class MoveTimesSection(_Strict):
    """How long the camera's moves take, ``intercept_s + slope x distance`` per axis (Frigate's model); a
    move takes its slowest axis's time, an axis that does not move none. ``ptztrack camera calibrate``
    measures them.

    pan, tilt : [intercept_s, slope] of the pan and of the tilt, seconds and seconds per degree.
    zoom : [intercept_s, slope] of the zoom, seconds and seconds per unit of zoom factor.
    """

    pan: _MoveTime = (0.0, 0.0)
    tilt: _MoveTime = (0.0, 0.0)
    zoom: _MoveTime = (0.0, 0.0)


class GroundViewSection(_Strict):
    """Where the camera saw the ground points (``camera calibrate --geometry``): a preset of the camera at
    its widest zoom, and the world pose there, found from the points.

    preset : the token of the camera's ONVIF preset the points were seen from, at its widest zoom.
    pan_deg, tilt_deg : the world pose there, degrees in the model's sense: the bearing from the ground's
    +y axis towards +x, and the depression below the horizon. roll_deg : how far the mount leans about the
    optical axis, degrees (the model takes a level mount). reprojection_error_px : the points'
    root-mean-square error in pixels through the fitted camera.
    """

    preset: Annotated[str, Field(min_length=1, max_length=64)]
    pan_deg: Degrees
    tilt_deg: Degrees
    roll_deg: Degrees = 0.0
    reprojection_error_px: Annotated[NonNegativeFloat, at_most(1e4, "pixels")] = 0.0


class CameraCalibrationFile(_Strict):
    """How a camera's normalised ONVIF spaces map to the camera model, and how long its moves take.

    pan_deg, tilt_deg : the degrees at normalised -1 and +1; zoom_curve : [[normalised, zoom factor], ...]
    both increasing, from the widest view (zoom factor 1); position_m : the optical centre (x, y, z) on the
    ground plane's axes, metres, and f_min_px : the focal length at zoom 1 (null: the scenario's camera);
    move_times : see :class:`MoveTimesSection`; image_delay_s : how long after the camera stands still
    its images show where it stands (a frame interval and the stream's latency; 0.1 s: a 10 fps stream);
    capture_time_sd_s : how uncertain a picture's capture time is (0.02 s, half a frame at 25 fps, until
    ``ptztrack camera calibrate`` measures it: the spread of its delays).
    zoom_curve_sd : the standard deviation of each zoom_curve point's zoom factor (as measured by
    ``camera calibrate --geometry``; null: not measured); positions : whether the camera reports its
    position (false: its ground view's preset stands at normalised 0, pan_deg and tilt_deg are the world
    degrees that relative moves of -1 and +1 from there reach, and the camera is moved by relative moves);
    ground_view : see
    :class:`GroundViewSection` (null: not measured).
    """

    pan_deg: tuple[Degrees, Degrees]
    tilt_deg: tuple[Degrees, Degrees]
    zoom_curve: Annotated[
        list[tuple[Annotated[float, Field(ge=0, le=1)], _Zoom]], Field(min_length=2), at_most_items(1000, "a table")
    ]
    position_m: tuple[_Coordinate, _Coordinate, _Coordinate] | None = None
    f_min_px: Annotated[PositiveFloat, at_most(1e6, "pixels")] | None = None
    move_times: MoveTimesSection = MoveTimesSection()
    image_delay_s: Annotated[NonNegativeFloat, at_most(10, "seconds")] = 0.1
    capture_time_sd_s: Annotated[NonNegativeFloat, at_most(1, "seconds")] = 0.02
    zoom_curve_sd: (
        Annotated[list[Annotated[NonNegativeFloat, at_most(100, "a zoom factor")]], at_most_items(1000, "a table")]
        | None
    ) = None
    positions: bool = True
    ground_view: GroundViewSection | None = None

    @model_validator(mode="after")
    def _monotonic(self):
        if self.pan_deg[0] == self.pan_deg[1] or self.tilt_deg[0] == self.tilt_deg[1]:
            raise ValueError("pan_deg and tilt_deg must each span a range (two different ends)")
        curve = np.asarray(self.zoom_curve, dtype=float)
        if np.any(np.diff(curve, axis=0) <= 0):
            raise ValueError("zoom_curve must increase in both columns, point after point")
        if self.zoom_curve_sd is not None and len(self.zoom_curve_sd) != len(self.zoom_curve):
            raise ValueError(f"zoom_curve_sd has {len(self.zoom_curve_sd)} values for {len(self.zoom_curve)} points")
        if not self.positions and self.ground_view is None:
            raise ValueError("a camera without positions (positions: false) needs its ground_view's preset")
        return self


FILE_KINDS["camera calibration"] = CameraCalibrationFile


def load_camera_calibration(path: str | Path) -> CameraCalibrationFile:
    """Read and validate a camera calibration YAML file; a :class:`ScenarioError` of one line if it is not one."""
    data = read_yaml(path, "camera calibration", ScenarioError)
    if not isinstance(data, dict):
        raise ScenarioError(f"{path}: expected a mapping of camera calibration fields (got {type(data).__name__})")
    refuse_another_kind(path, data, "camera calibration")
    try:
        return CameraCalibrationFile.model_validate(data)
    except pydantic.ValidationError as error:
        raise ScenarioError(_first_error_line(error, str(path))) from None


# The virtual ONVIF camera of `ptztrack serve-camera` over PETS: spaces wider than the PETS grid, as a
# real camera's are, and the zoom range of the virtual camera. Its tilt is ONVIF's (normalised +1 looks
# up): the model's depression is 45 degrees at -1 and -45 at +1.
VIRTUAL_CAMERA_CALIBRATION = {
    "pan_deg": (-90.0, 90.0),
    "tilt_deg": (45.0, -45.0),
    "zoom_curve": [(0.0, 1.0), (1.0, 8.0)],
}


def write_camera_calibration(path: str | Path, calibration: CameraCalibrationFile) -> None:
    """Write a camera calibration as YAML, atomically (comments of an earlier file are not kept)."""
    text = yaml.safe_dump(calibration.model_dump(mode="json"), sort_keys=False)
    write_atomically(Path(path), text.encode())
