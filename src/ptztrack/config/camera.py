"""The scenario's camera sections: the PTZ camera, how a real one departs from its model (pose
error, live views), which pose the tracker maps detections with, and the action grid."""

from typing import Annotated, Literal

import numpy as np
from pydantic import Field, model_validator

from ptztrack.camera.parameters import LandingErrorParameters, LiveViewParameters
from ptztrack.config.fields import (
    Degrees,
    NonNegativeFloat,
    Options,
    Pixels,
    PositiveFloat,
    _Coordinate,
    _registered,
    _Strict,
    _Zoom,
    at_most,
    at_most_items,
)


class PoseError(_Strict):
    """How far a real PTZ camera lands from the pose it was sent to (backlash, zoom curves): each time the
    command changes, the camera lands at a pose drawn as below and stays there while the command does not
    change. The defaults are :class:`~ptztrack.camera.parameters.LandingErrorParameters`'s: a perfect camera.

    pan_tilt_bias_deg : (pan, tilt) degrees added to the commanded pan and tilt; pan_tilt_sigma_deg : the
    standard deviation in degrees of the independent Gaussian errors added to them as well.
    zoom_bias : the factor on the commanded zoom; zoom_sigma : the standard deviation of the relative
    Gaussian error e of the zoom: the camera lands at zoom ``commanded x zoom_bias x (1 + e)``.
    """

    pan_tilt_sigma_deg: Annotated[NonNegativeFloat, at_most(90, "degrees")] = LandingErrorParameters.pan_tilt_sigma_deg
    pan_tilt_bias_deg: tuple[Degrees, Degrees] = LandingErrorParameters.pan_tilt_bias_deg
    zoom_sigma: Annotated[float, Field(ge=0, lt=0.5)] = LandingErrorParameters.zoom_sigma
    zoom_bias: Annotated[PositiveFloat, at_most(10, "a factor on the zoom")] = LandingErrorParameters.zoom_bias


_Gain = Annotated[PositiveFloat, at_most(100, "a factor on the contrast")]


class LiveView(_Strict):
    """How a real PTZ camera's views depart from the pinhole model (:mod:`ptztrack.camera.live_view`);
    the defaults (:class:`~ptztrack.camera.parameters.LiveViewParameters`'s) are the realistic model of the
    registration experiment.

    Each view is rolled by up to ``roll_max_deg`` (uniform), its principal point is off the centre
    by up to ``principal_offset_max_px`` (uniform over the disc; pixels of the registered image,
    ``pose_feedback.image_size_px``, scaled for other sizes), its lens distorts radially by k1
    (normalised coordinates) from ``k1_wide`` at zoom 1 linearly to ``k1_tele`` at ``tele_zoom``,
    its contrast is multiplied by a ``gain`` in [low, high] and its brightness moved by up to
    ``brightness_max`` grey levels (uniform), and it is JPEG-compressed at ``jpeg_quality``. A
    view's values are fixed by ``seed`` (the camera unit) and its pose.
    """

    roll_max_deg: Annotated[NonNegativeFloat, at_most(45, "degrees: a mount rolled further is not level")] = (
        LiveViewParameters.roll_max_deg
    )
    principal_offset_max_px: Annotated[NonNegativeFloat, at_most(1000, "pixels")] = (
        LiveViewParameters.principal_offset_max_px
    )
    k1_wide: Annotated[float, Field(gt=-1, lt=1)] = LiveViewParameters.k1_wide
    k1_tele: Annotated[float, Field(gt=-1, lt=1)] = LiveViewParameters.k1_tele
    tele_zoom: Annotated[float, Field(gt=1), at_most(100, "a PTZ camera's optical zoom")] = LiveViewParameters.tele_zoom
    gain: tuple[_Gain, _Gain] = LiveViewParameters.gain
    brightness_max: Annotated[NonNegativeFloat, at_most(255, "grey levels")] = LiveViewParameters.brightness_max
    jpeg_quality: int = Field(LiveViewParameters.jpeg_quality, ge=1, le=100)
    seed: int = Field(LiveViewParameters.seed, ge=0, lt=2**63)

    @model_validator(mode="after")
    def _gain_ordered(self):
        if self.gain[1] < self.gain[0]:
            raise ValueError(f"gain must be [low, high] with low <= high (got {list(self.gain)})")
        return self


class Camera(_Strict):
    """The PTZ camera.

    position_m : its optical centre (x, y, z) in metres on the ground's axes, z its height above the
    ground. image_size_px : (width, height) of its pictures in pixels (for a recording, of the virtual
    camera's view). f_min_px : its focal length in pixels at zoom 1, the widest view (at zoom z:
    ``z x f_min_px``). With a recording, the position and the focal length come from its calibration.
    pose_error : how far it lands from the pose it is sent to (section ``camera.pose_error``).
    backend : a registered camera backend; by default 'simulated' for the
    synthetic scene and 'virtual' (the virtual PTZ camera) for a recording. live_view : how a
    recording's views depart from the pinhole model (None: exact pinhole views); the detector, the
    templates and registration all see the same views. options : the parameters of another package's
    camera backend, passed to its factory unread (ptztrack's own backends take none).
    """

    position_m: tuple[_Coordinate, _Coordinate, Annotated[PositiveFloat, at_most(10_000, "metres")]] = (7.5, -6.0, 2.5)
    image_size_px: tuple[Pixels, Pixels] = (640, 480)
    f_min_px: Annotated[PositiveFloat, at_most(1e6, "pixels")] = 325.0
    pose_error: PoseError = PoseError()
    live_view: LiveView | None = None
    backend: Annotated[str | None, _registered("cameras")] = None
    options: Options = Field(default_factory=dict)


_REFERENCE_TIME = "time: every reference view is rendered and its SIFT features indexed"


class PoseFeedback(_Strict):
    """Which pose the tracker maps detections with (the scale-invariant tracking paper, section 3).

    source : 'commanded' (what the camera was sent to), 'oracle' (where it really looks; for
    experiments) or 'registered' (found from its image by SIFT registration against reference views,
    :mod:`ptztrack.camera.pose_feedback`; needs a recording with a video). A view that cannot be
    registered falls back to the commanded pose.
    image_size_px : the resolution of the image registered (the detector may see a smaller one).
    reference_zooms, reference_pan_steps, reference_tilt_steps : the reference views, a grid over the
    action grid's pan and tilt range at each zoom. reference_pose_sigma_deg : how roughly the reference
    views' poses are known before bundle adjustment: the standard deviation in degrees of the Gaussian
    error on each one's pan and tilt (all but the first, the anchor). reference_zoom_spread : the same for
    their zoom: each one's zoom is off by a factor uniform in [1 - spread, 1 + spread].
    index : a file caching the reference index: read when it exists, written when it does not.
    """

    source: Literal["commanded", "oracle", "registered"] = "commanded"
    image_size_px: tuple[Pixels, Pixels] = (640, 480)
    reference_zooms: Annotated[tuple[_Zoom, ...], at_most_items(20, _REFERENCE_TIME)] = (1.0, 2.0, 3.2)
    reference_pan_steps: Annotated[int, Field(ge=1), at_most(50, _REFERENCE_TIME)] = 5
    reference_tilt_steps: Annotated[int, Field(ge=1), at_most(50, _REFERENCE_TIME)] = 3
    reference_pose_sigma_deg: Annotated[NonNegativeFloat, at_most(90, "degrees")] = 0.5
    reference_zoom_spread: Annotated[float, Field(ge=0, lt=0.5)] = 0.03
    index: str | None = None


class AxisRange(_Strict):
    """The values of one axis of the action grid: ``count`` evenly spaced angles from ``start`` to
    ``stop``, both included.

    start, stop : the first and the last value, degrees; count : how many values (1: ``start`` alone).
    """

    start: Degrees
    stop: Degrees
    count: Annotated[int, Field(ge=1), at_most(1000, "time: the policies score every action")]

    def values(self) -> np.ndarray:
        return np.linspace(self.start, self.stop, self.count)


_GridSteps = Annotated[int, Field(ge=0), at_most(1000, "steps of the action grid")]


class Actions(_Strict):
    """The action grid (:class:`~ptztrack.camera.actions.ActionGrid`): every combination of a pan, a tilt
    and a zoom is a pose the policies can choose, within ``max_steps`` of the current one.

    pan_deg : the pan values in degrees (section ``actions.pan_deg``); 0 looks along the ground's +y axis and
    a positive pan turns towards +x. For a recording, pan and tilt are offsets from the pose that shows the
    whole recorded frame; for a network's camera, pan is an offset from the bearing of the area's centre.
    tilt_deg : the tilt values in degrees below the horizon (positive looks down), increasing, within
    (-90, 90). zoom : the zoom values (focal length over the widest one), increasing.
    max_steps : (pan, tilt, zoom) how many grid values each axis may move in one step.
    """

    pan_deg: AxisRange = AxisRange(start=-45.0, stop=45.0, count=7)
    tilt_deg: AxisRange = AxisRange(start=0.0, stop=24.0, count=10)
    zoom: Annotated[tuple[_Zoom, ...], at_most_items(100, "time: the policies score every action")] = (
        1.0,
        2.0,
        3.0,
        4.0,
    )
    max_steps: tuple[_GridSteps, _GridSteps, _GridSteps] = (2, 2, 1)

    @model_validator(mode="after")
    def _zoom_increasing(self):
        if len(self.zoom) == 0 or np.any(np.diff(self.zoom) <= 0):
            raise ValueError(f"zoom must be a non-empty increasing list (got {list(self.zoom)})")
        if not -90 < self.tilt_deg.start <= self.tilt_deg.stop < 90:
            raise ValueError("tilt_deg must run upwards within (-90, 90)")
        return self
