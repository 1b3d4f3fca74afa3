"""One validated configuration object per run, loadable from YAML.

The defaults are the synthetic scene of the paper's section 5.1 with the
camera mounting chosen in :mod:`ptztrack.scene.synthetic`.
"""

from collections.abc import Hashable
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import pydantic
import yaml
from pydantic import AfterValidator, BaseModel, ConfigDict, Field, model_validator

from ptztrack import registry
from ptztrack.files import SHOWN_CHARACTERS, InputError, read_text, shown, write_atomically

PositiveFloat = Annotated[float, Field(gt=0)]
NonNegativeFloat = Annotated[float, Field(ge=0)]
SCENARIO_MAX_BYTES = 1_000_000
YAML_MAX_VALUES = 100_000
"""How many values a scenario may hold once YAML's aliases are expanded (a 'billion laughs' holds 10^9)."""


class ScenarioError(InputError):
    """A scenario that cannot be run; the message is one line naming the field and value."""


def at_most(limit: float, why: str):
    """A bound on a size, count or rate, with the reason for it (memory, time, physics) in the message."""

    def check(value):
        if value > limit:
            raise ValueError(f"must be at most {limit:g} ({why})")
        return value

    return AfterValidator(check)


def at_most_items(limit: int, why: str):
    """A bound on the length of a list, with the reason for it."""

    def check(values):
        if len(values) > limit:
            raise ValueError(f"must have at most {limit} items ({why})")
        return values

    return AfterValidator(check)


_MAX_FRAMES = 100_000
Pixels = Annotated[int, Field(gt=0), at_most(8192, "memory: an 8192 x 8192 colour image is 200 MB")]
Degrees = Annotated[float, Field(ge=-360), at_most(360, "an angle in degrees")]


def _registered(kind: str):
    """A field that names an implementation registered under ``kind`` (:mod:`ptztrack.registry`)."""

    def check(name: str | None) -> str | None:
        if name is not None and name not in registry.names(kind):
            raise ValueError(f"expected one of {', '.join(registry.names(kind))}")
        return name

    return AfterValidator(check)


Options = dict[str, Any]
"""Parameters of an implementation registered by another package, passed to its factory unread."""


class _Strict(BaseModel):
    # Every float is finite: no field gives infinity a meaning.
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


_Speed = Annotated[PositiveFloat, at_most(15, "metres per second: faster than anyone runs")]
_Height = Annotated[PositiveFloat, at_most(3, "metres: taller than anyone")]
_Stay = Annotated[PositiveFloat, at_most(86_400, "seconds: a day")]


class People(_Strict):
    """The synthetic crowd (:mod:`ptztrack.scene.synthetic`). paired_fraction : the share of the
    ``count`` people who walk in pairs, side by side ``pair_spacing_m`` apart (pairs: the fraction
    of count / 2, rounded)."""

    count: Annotated[int, Field(ge=0), at_most(1000, "time: the policies score every person under every action")] = 7
    speed_m_s: tuple[_Speed, _Speed] = (1.0, 1.5)
    height_m: tuple[_Height, _Height] = (1.6, 1.9)
    width_m: Annotated[PositiveFloat, at_most(3, "metres: a person's width")] = 0.62
    turn_rate_sigma_deg_s: Annotated[NonNegativeFloat, at_most(3600, "degrees per second")] = 40.0
    enter_leave: bool = False
    stay_s: tuple[_Stay, _Stay] = (8.0, 20.0)
    paired_fraction: float = Field(0.85, ge=0, le=1)
    pair_spacing_m: Annotated[PositiveFloat, at_most(10, "metres between two people walking together")] = 0.75

    @model_validator(mode="after")
    def _intervals_ordered(self):
        for name in ("speed_m_s", "height_m", "stay_s"):
            low, high = getattr(self, name)
            if high < low:
                raise ValueError(f"{name} must be [low, high] with low <= high (got {[low, high]})")
        return self

    @property
    def pairs(self) -> int:
        """How many pairs walk side by side (never more than there are people for)."""
        return min(round(self.paired_fraction * self.count / 2), self.count // 2)


class PoseError(_Strict):
    """How far a real PTZ camera lands from the pose it was sent to (backlash, zoom curves).

    Each time the command changes, the camera lands at the commanded pan and tilt plus
    ``pan_tilt_bias_deg`` plus independent Gaussian errors of ``pan_tilt_sigma_deg``, and at the
    commanded zoom times ``zoom_bias`` times (1 + a Gaussian error of ``zoom_sigma``); it stays there
    while the command does not change. The defaults are a perfect camera.
    """

    pan_tilt_sigma_deg: Annotated[NonNegativeFloat, at_most(90, "degrees")] = 0.0
    pan_tilt_bias_deg: tuple[Degrees, Degrees] = (0.0, 0.0)
    zoom_sigma: Annotated[float, Field(ge=0, lt=0.5)] = 0.0
    zoom_bias: Annotated[PositiveFloat, at_most(10, "a factor on the zoom")] = 1.0


_Coordinate = Annotated[float, Field(ge=-10_000), at_most(10_000, "metres: the ground a camera can see")]


_Gain = Annotated[PositiveFloat, at_most(100, "a factor on the contrast")]


class LiveView(_Strict):
    """How a real PTZ camera's views depart from the pinhole model (:mod:`ptztrack.camera.live_view`);
    the defaults are the realistic model of the registration experiment.

    Each view is rolled by up to ``roll_max_deg`` (uniform), its principal point is off the centre
    by up to ``principal_offset_max_px`` (uniform over the disc; pixels of the registered image,
    ``pose_feedback.image_size_px``, scaled for other sizes), its lens distorts radially by k1
    (normalised coordinates) from ``k1_wide`` at zoom 1 linearly to ``k1_tele`` at ``tele_zoom``,
    its contrast is multiplied by a ``gain`` in [low, high] and its brightness moved by up to
    ``brightness_max`` grey levels (uniform), and it is JPEG-compressed at ``jpeg_quality``. A
    view's values are fixed by ``seed`` (the camera unit) and its pose.
    """

    roll_max_deg: Annotated[NonNegativeFloat, at_most(45, "degrees: a mount rolled further is not level")] = 2.0
    principal_offset_max_px: Annotated[NonNegativeFloat, at_most(1000, "pixels")] = 10.0
    # The PETS camera's own lens over the field of our zoom-1 view (its calibration's k1).
    k1_wide: Annotated[float, Field(gt=-1, lt=1)] = -0.15
    k1_tele: Annotated[float, Field(gt=-1, lt=1)] = 0.0
    tele_zoom: Annotated[float, Field(gt=1), at_most(100, "a PTZ camera's optical zoom")] = 4.0
    gain: tuple[_Gain, _Gain] = (0.7, 1.3)
    brightness_max: Annotated[NonNegativeFloat, at_most(255, "grey levels")] = 20.0
    jpeg_quality: int = Field(75, ge=1, le=100)
    seed: int = Field(0, ge=0, lt=2**63)

    @model_validator(mode="after")
    def _gain_ordered(self):
        if self.gain[1] < self.gain[0]:
            raise ValueError(f"gain must be [low, high] with low <= high (got {list(self.gain)})")
        return self


class Camera(_Strict):
    """The PTZ camera. backend : a registered camera backend; by default 'simulated' for the
    synthetic scene and 'virtual' (the virtual PTZ camera) for a recording. live_view : how a
    recording's views depart from the pinhole model (None: exact pinhole views); the detector, the
    templates and registration all see the same views."""

    position_m: tuple[_Coordinate, _Coordinate, Annotated[PositiveFloat, at_most(10_000, "metres")]] = (7.5, -6.0, 2.5)
    image_size_px: tuple[Pixels, Pixels] = (640, 480)
    f_min_px: Annotated[PositiveFloat, at_most(1e6, "pixels")] = 325.0
    pose_error: PoseError = PoseError()
    live_view: LiveView | None = None
    backend: Annotated[str | None, _registered("cameras")] = None
    options: Options = Field(default_factory=dict)


_Zoom = Annotated[float, Field(ge=1), at_most(100, "a PTZ camera's optical zoom")]
_REFERENCE_TIME = "time: every reference view is rendered and its SIFT features indexed"


class PoseFeedback(_Strict):
    """Which pose the tracker maps detections with (the scale-invariant tracking paper, section 3).

    source : 'commanded' (what the camera was sent to), 'oracle' (where it really looks; for
    experiments) or 'registered' (found from its image by SIFT registration against reference views,
    :mod:`ptztrack.camera.pose_feedback`; needs a recording with a video). A view that cannot be
    registered falls back to the commanded pose.
    image_size_px : the resolution of the image registered (the detector may see a smaller one).
    reference_zooms, reference_pan_steps, reference_tilt_steps : the reference views, a grid over the
    action grid's pan and tilt range at each zoom; reference_pose_sigma_deg and
    reference_zoom_spread : how roughly their poses are known before bundle adjustment.
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
    start: Degrees
    stop: Degrees
    count: Annotated[int, Field(ge=1), at_most(1000, "time: the policies score every action")]

    def values(self) -> np.ndarray:
        return np.linspace(self.start, self.stop, self.count)


_GridSteps = Annotated[int, Field(ge=0), at_most(1000, "steps of the action grid")]


class Actions(_Strict):
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


# How the policies and the tracker know the detector: its prior curve fixed, learned from the run, or the
# simulation's own curve (for comparison only); anything else names a detector_model.json to start from.
DETECTOR_MODELS = ("a-priori", "online", "true")


class Detector(_Strict):
    """The detector: simulated (ideal, realistic), OpenCV's HOG on a recording's virtual view, or any
    detector registered by another package (``options`` are its parameters).

    The policies plan with recall 1 for 'ideal'; for every other kind they start from the recall
    curve ``recall_kd``, ``recall_r0_px`` (the paper's equation 13), its r0 shifted by
    ``prior_shift_px``, and with ``model`` 'online' (the default) learn the curve as the camera runs
    (:mod:`ptztrack.detect.detector_model`); 'a-priori' keeps the prior, 'true' plans with the
    simulation's own curve, and a file path starts from what an earlier run learned.

    hog_search : 'ground' scans only the windows where a standing person ``hog_person_height_m``
    (shortest, tallest) tall could be seen on the walkable area, at their sizes; 'image' scans every
    window of the pyramid, as OpenCV's ``detectMultiScale`` (:mod:`ptztrack.detect.hog`).
    """

    kind: Annotated[str, _registered("detectors")] = "realistic"
    options: Options = Field(default_factory=dict)
    recall_kd: Annotated[PositiveFloat, at_most(100, "per pixel")] = 0.0098
    recall_r0_px: Annotated[NonNegativeFloat, at_most(10_000, "pixels")] = 21.29
    pixel_noise_px: Annotated[NonNegativeFloat, at_most(10_000, "pixels")] = 2.0
    false_positives_per_frame: Annotated[
        NonNegativeFloat, at_most(1000, "time and memory: every detection is kept and associated")
    ] = 0.0
    hog_upsample: Annotated[PositiveFloat, at_most(16, "memory: the view is upsampled this much each way")] = 6.0
    hog_hit_threshold: float = 0.0
    hog_nms_iou: float = Field(0.4, gt=0, le=1)
    hog_search: Literal["ground", "image"] = "ground"
    hog_person_height_m: tuple[_Height, _Height] = (1.5, 2.0)
    model: str = "online"
    prior_shift_px: Annotated[float, Field(ge=-1000, le=1000)] = 0.0

    @model_validator(mode="after")
    def _heights_ordered(self):
        low, high = self.hog_person_height_m
        if high < low:
            raise ValueError(f"hog_person_height_m must be [low, high] with low <= high (got {[low, high]})")
        return self

    @model_validator(mode="after")
    def _model_known(self):
        if self.model in DETECTOR_MODELS:
            if self.model == "true" and self.kind not in ("ideal", "realistic"):
                raise ValueError(
                    f"model 'true' (the simulation's own curve) needs a simulated detector, not kind {self.kind!r}"
                )
            return self
        if not Path(self.model).is_file():
            raise ValueError(
                f"model {self.model!r} is neither one of {', '.join(DETECTOR_MODELS)} nor a detector model file"
            )
        return self


class Tracker(_Strict):
    """The ground-plane tracker: by default (``kind`` 'ekf') one EKF per person, and its data association.

    association : 'hungarian' (one detection per track, assigned on the
    Mahalanobis distance) or 'cjpdaf' (Fitzgerald's Cheap JPDAF, equation 6
    of Lisanti et al.: every track is updated with all detections in its
    gate, weighted by association probabilities; :mod:`ptztrack.track.jpdaf`).
    clutter_density_per_px2 : the CJPDAF's constant C, which competes with
    the detections' Gaussian likelihoods p (1/px^2): with one track and one
    detection, beta = p / (p + C). It is the parametric PDA's
    lambda (1 - P_D P_G) / P_D, lambda the density of false detections
    per px^2, P_D the recall, P_G the gate probability. The default 0 is
    that value for the simulated detectors, which report no false positives
    (a positive C there only discounts true detections of uncertain tracks:
    1e-6 costs `intg` and `smpl` 2 MOTA points on the synthetic realistic
    table, 2e-5 costs 9); the PETS scenario with HOG sets it (see
    ``PETS_HOG_TRACKER``). The Hungarian association ignores it.
    measurement_source : 'detector' (every step) or 'spatiogram' (the scale-invariant paper's
    section 5: the detector runs every ``detector_every_steps`` steps, to start tracks and retake
    each detected track's colour spatiogram; in between, each track is measured by searching for
    its spatiogram around its prediction, at the scale the head/feet homology gives;
    :mod:`ptztrack.track.templates`). Needs a recording with a video.
    kind : a registered tracker (another package's, with ``options`` its parameters).
    existence_at_birth, existence_when_detected, existence_to_delete : the track lifecycle, by the
    probability that a track's person exists (:mod:`ptztrack.track.tracker`); existence_update 'bayes'
    weighs each detection against the clutter (the learned rate where the detector model learns,
    else ``clutter_density_per_px2``) and reports tracks of existence ``existence_to_report`` or more;
    'fixed' sets it to ``existence_when_detected`` at every detection and reports every track.
    max_position_sigma_m : where people can leave the scene (a recording, or ``people.enter_leave``),
    a track this uncertain is deleted; where they never leave, uncertainty deletes nobody.
    report_position_sigma_m : a track more uncertain than this is kept but not reported.
    """

    kind: Annotated[str, _registered("trackers")] = "ekf"
    options: Options = Field(default_factory=dict)
    acceleration_sigma_m_s2: Annotated[PositiveFloat, at_most(100, "metres per second squared")] = 1.5
    initial_speed_sigma_m_s: Annotated[PositiveFloat, at_most(100, "metres per second")] = 0.9
    gate_probability: float = Field(0.99, gt=0, lt=1)
    existence_at_birth: float = Field(0.5, gt=0, lt=1)
    existence_when_detected: float = Field(0.99, gt=0, lt=1)
    existence_to_delete: float = Field(0.1, gt=0, lt=1)
    max_position_sigma_m: Annotated[PositiveFloat, at_most(10_000, "metres")] = 2.0
    confirmation_hits: Annotated[int, Field(ge=1), at_most(_MAX_FRAMES, "steps")] = 1
    report_position_sigma_m: Annotated[PositiveFloat, at_most(10_000, "metres")] = 1.0
    existence_update: Literal["bayes", "fixed"] = "bayes"
    existence_to_report: float = Field(0.5, gt=0, lt=1)
    association: Literal["hungarian", "cjpdaf"] = "hungarian"
    clutter_density_per_px2: Annotated[NonNegativeFloat, at_most(1, "detections per pixel")] = 0.0
    measurement_source: Literal["detector", "spatiogram"] = "detector"
    detector_every_steps: Annotated[int, Field(ge=1), at_most(_MAX_FRAMES, "steps")] = 5


class Control(_Strict):
    """Parameters of the information-gain policies (paper sections 4 and 4.4)."""

    samples: Annotated[int, Field(ge=1), at_most(10_000, "time: smpl scores every sample under every action")] = 100
    beta: Annotated[NonNegativeFloat, at_most(1e6, "a weight")] = 0.0
    person_height_m: _Height = 1.75
    exploration_cell_m: Annotated[float, Field(ge=0.05), at_most(1000, "metres")] = 1.0
    prior_untracked_people: Annotated[NonNegativeFloat, at_most(10_000, "people")] = 1.0
    arrival_rate_per_s: Annotated[NonNegativeFloat, at_most(1000, "people per second")] = 0.1


_VideoFrame = Annotated[int, Field(ge=0), at_most(10_000_000, "video frames: 4 days at 30 Hz")]


_Polygon = Annotated[tuple[tuple[_Coordinate, _Coordinate], ...], at_most_items(1000, "corners of a polygon")]


class Recording(_Strict):
    """A calibrated recording with ground truth, seen through a virtual PTZ camera (paper section 5.2).

    With a recording, the camera's position and focal length come from the
    calibration (``camera.image_size_px`` sets the virtual view), and the
    action grid's pan and tilt are offsets from the pose that shows the whole
    recorded frame. Relative paths in a scenario file are relative to it.
    frame_range : [first, stop) video frames (0-based) to run on; default all.
    area_m : the walkable area, a polygon of [x, y] points in metres; default the ground the
    recorded view shows (see :func:`ptztrack.builders.world.visible_ground_m`).
    map_grid_px : the virtual camera computes where each pixel reads the recording exactly every
    ``map_grid_px`` pixels and interpolates in between (1: every pixel; see
    :class:`ptztrack.camera.virtual.VirtualPTZ`).
    """

    ground_truth: str
    calibration: str
    view: str = "View_001"
    video: str | None = None
    recorded_size_px: tuple[Pixels, Pixels] = (768, 576)
    frame_step: Annotated[int, Field(ge=1), at_most(_MAX_FRAMES, "video frames")] = 2
    occluded_above: float = Field(0.25, ge=0, le=1)
    frame_range: tuple[_VideoFrame, _VideoFrame] | None = None
    area_m: (
        Annotated[tuple[tuple[_Coordinate, _Coordinate], ...], at_most_items(1000, "corners of a polygon")] | None
    ) = None
    map_grid_px: Annotated[int, Field(ge=1), at_most(64, "pixels between the sampling map's grid points")] = 1

    @model_validator(mode="after")
    def _range_and_area(self):
        if self.frame_range is not None and self.frame_range[1] <= self.frame_range[0]:
            raise ValueError(f"frame_range must be [first, stop) with first < stop (got {list(self.frame_range)})")
        if self.area_m is not None and len(self.area_m) < 3:
            raise ValueError(f"area_m must be a polygon of at least 3 [x, y] points (got {len(self.area_m)})")
        return self


_FollowPixels = Annotated[NonNegativeFloat, at_most(8192, "pixels")]
_PARTICLE_TIME = "time: every particle is scored on every patch each step"
Fraction = Annotated[float, Field(gt=0, lt=1)]
Patch = tuple[
    Annotated[float, Field(ge=0, le=1)],
    Annotated[float, Field(ge=0, le=1)],
    Annotated[float, Field(gt=0, le=1)],
    Annotated[float, Field(gt=0, le=1)],
]


class Follow(_Strict):
    """The follow camera (the robot-cameraman paper, seed 003): one person kept at an image point and size.

    The ``tracker.kind`` 'particle' (the paper's particle filter), 'csrt' or 'mil' (OpenCV's) follows
    the person and the policy 'follow' moves the camera. Each default's source is in the README
    ("Follow camera: parameters"); none was tuned on PETS.

    target_id : the annotated person followed; the tracker starts from their first annotated box.
    target_point_px : (x*, y*) where the middle of the person should be; null: the image centre.
    target_height_px : the person's height wanted in the image.
    max_speed_deg_s, max_acceleration_deg_s2 : of pan and of tilt; max_zoom_speed (per s),
    max_zoom_acceleration (per s^2) : of the natural logarithm of the zoom; zoom_range : [lowest, highest].
    smoothing_cutoff_hz : the tracker's output low-pass filter.
    particles, search_particles : tracking, and searching after a loss.
    patches : [left, top, width, height] in units of the person's box (default: the head, and the torso
    and the legs each split into a left and a right half).
    histogram_bins : N of the N x N hue-saturation histograms; samples_per_patch : grid points per axis.
    achromatic_bins : N more bins by value for pixels too grey or dark to have a hue (Perez et al.);
    false: the paper's hue-saturation histograms alone.
    background_area_ratio : weigh the histograms' bins down by how common they are in the ring around
    the first box, out to a box of this many times its area (Comaniciu et al.'s background-weighted
    histogram, their 3); null: the paper's unweighted histograms.
    lambda_colour, lambda_motion : equations 3 and 4 (lambda_colour: K / 20 for K patches, Perez et al.'s
    exp(-20 D^2) on the patches' mean).
    lambda_loss : the colour likelihood's lambda in the loss test, exp(-sum_p B_p^2 / lambda_loss): the
    weights stay sharp (``lambda_colour``) while the loss test tolerates the appearance changes of a
    walking person (K / 3: 1.0 chosen for three patches on the even-numbered PETS people; see the README).
    walk_heights_per_s : random-walk spread of the box position, box heights per second;
    scale_change_per_s : relative random-walk spread of its height per second.
    prediction : 'particle_velocity' (every particle carries its own image velocity, changed each step
    by a white acceleration: the nearly-constant-velocity model), 'constant_velocity' (the random walk
    about the estimate's image velocity, averaged with the output filter's cut-off
    ``smoothing_cutoff_hz``) or 'random_walk' (the paper's, no drift).
    acceleration_heights_per_s2 : the particles' white acceleration (with 'particle_velocity'), box
    heights per second squared; initial_speed_heights_per_s : the spread of their velocities per axis
    when the person's velocity is not known (the first step, the diffuse prior after a loss).
    loss_fraction, adapt_fraction : the loss test (P < loss_fraction P_ref) and when P_ref adapts.
    reference_time_constant_s : how slowly P_ref adapts.
    search_heights : spread of the diffuse prior after a loss, in box heights; search_scale : of its height.
    motion_threshold : grey levels; motion_memory_s : how long the motion history lasts;
    motion_scale : the motion image's resolution relative to the view's.
    """

    target_id: int | None = None
    target_point_px: tuple[_FollowPixels, _FollowPixels] | None = None
    target_height_px: Annotated[PositiveFloat, at_most(8192, "pixels")] = 160.0
    max_speed_deg_s: Annotated[PositiveFloat, at_most(1000, "degrees per second")] = 30.0
    max_acceleration_deg_s2: Annotated[PositiveFloat, at_most(10_000, "degrees per second squared")] = 30.0
    max_zoom_speed: Annotated[PositiveFloat, at_most(100, "per second")] = 0.7
    max_zoom_acceleration: Annotated[PositiveFloat, at_most(1000, "per second squared")] = 0.7
    zoom_range: tuple[_Zoom, _Zoom] = (1.0, 4.0)
    smoothing_cutoff_hz: Annotated[PositiveFloat, at_most(1000, "hertz")] = 1.0
    particles: Annotated[int, Field(ge=1), at_most(100_000, _PARTICLE_TIME)] = 100
    search_particles: Annotated[int, Field(ge=2), at_most(100_000, _PARTICLE_TIME)] = 400
    patches: Annotated[tuple[Patch, ...], at_most_items(100, _PARTICLE_TIME)] = (
        (0.3, 0.0, 0.4, 0.15),
        (0.15, 0.15, 0.35, 0.35),
        (0.5, 0.15, 0.35, 0.35),
        (0.2, 0.5, 0.3, 0.5),
        (0.5, 0.5, 0.3, 0.5),
    )
    histogram_bins: int = Field(10, ge=1, le=64)
    achromatic_bins: bool = False
    background_area_ratio: Annotated[float, Field(gt=1), at_most(10_000, "box areas")] | None = 3.0
    height_log_sigma: PositiveFloat | None = 0.1
    samples_per_patch: Annotated[int, Field(ge=1), at_most(1000, _PARTICLE_TIME)] = 20
    lambda_colour: Annotated[PositiveFloat, at_most(1e6, "a likelihood scale")] = 5 / 20
    lambda_loss: Annotated[PositiveFloat, at_most(1e6, "a likelihood scale")] = 5 / 3
    lambda_motion: Annotated[PositiveFloat, at_most(1e6, "a likelihood scale")] = 0.434
    walk_heights_per_s: Annotated[PositiveFloat, at_most(1000, "box heights per second")] = 1.0
    scale_change_per_s: Annotated[PositiveFloat, at_most(100, "per second")] = 0.2
    prediction: Literal["constant_velocity", "particle_velocity", "random_walk"] = "particle_velocity"
    acceleration_heights_per_s2: Annotated[PositiveFloat, at_most(1000, "box heights per second squared")] = 1.0
    initial_speed_heights_per_s: Annotated[PositiveFloat, at_most(1000, "box heights per second")] = 0.75
    loss_fraction: Fraction = 0.1
    adapt_fraction: Fraction = 0.6
    reference_time_constant_s: Annotated[PositiveFloat, at_most(86_400, "seconds")] = 2.0
    search_heights: Annotated[PositiveFloat, at_most(1000, "box heights")] = 1.0
    search_scale: Annotated[PositiveFloat, at_most(100, "a relative spread")] = 0.2
    motion_threshold: Annotated[NonNegativeFloat, at_most(255, "grey levels")] = 15.0
    motion_memory_s: Annotated[PositiveFloat, at_most(86_400, "seconds")] = 0.3
    motion_scale: Annotated[float, Field(gt=0, le=1)] = 0.5

    @model_validator(mode="after")
    def _consistent(self):
        if self.zoom_range[1] < self.zoom_range[0]:
            raise ValueError(f"zoom_range must be [lowest, highest] (got {list(self.zoom_range)})")
        if self.adapt_fraction <= self.loss_fraction:
            raise ValueError(
                f"adapt_fraction ({self.adapt_fraction}) must be above loss_fraction ({self.loss_fraction})"
            )
        if not self.patches:
            raise ValueError("patches must hold at least one [left, top, width, height]")
        for number, (left, top, width, height) in enumerate(self.patches):
            if left + width > 1 or top + height > 1:
                raise ValueError(f"patch {number} {[left, top, width, height]} reaches outside the box")
        return self


_Side = Annotated[PositiveFloat, at_most(1000, "metres: the ground a PTZ camera can cover")]


class Scenario(_Strict):
    """Everything a run needs besides the policy and the seed."""

    area_m: tuple[_Side, _Side] = (15.0, 15.0)
    frames: Annotated[
        int, Field(ge=1), at_most(_MAX_FRAMES, "memory: a run keeps every step's history, a few kB a step")
    ] = 50
    frame_rate_hz: Annotated[PositiveFloat, at_most(1000, "steps per second")] = 5.0
    people: People = People()
    camera: Camera = Camera()
    actions: Actions = Actions()
    detector: Detector = Detector()
    tracker: Tracker = Tracker()
    control: Control = Control()
    pose_feedback: PoseFeedback = PoseFeedback()
    follow: Follow = Follow()
    recording: Recording | None = None

    @model_validator(mode="after")
    def _images_need_a_video(self):
        has_video = self.recording is not None and self.recording.video is not None
        if self.detector.kind == "hog" and not has_video:
            raise ValueError("detector.kind 'hog' needs a recording with a video (recording.video)")
        if self.pose_feedback.source == "registered" and not has_video:
            raise ValueError("pose_feedback.source 'registered' needs a recording with a video (recording.video)")
        if self.tracker.measurement_source == "spatiogram" and not has_video:
            raise ValueError("tracker.measurement_source 'spatiogram' needs a recording with a video (recording.video)")
        return self

    def required_recording(self, purpose: str) -> Recording:
        """The scenario's recording; a :class:`ScenarioError` saying that ``purpose`` needs one if it has none."""
        if self.recording is None:
            raise ScenarioError(f"{purpose} needs a recording (recording)")
        return self.recording

    def required_video(self, purpose: str) -> str:
        """The recording's video; a :class:`ScenarioError` saying that ``purpose`` needs one if it has none."""
        video = self.required_recording(purpose).video
        if video is None:
            raise ScenarioError(f"{purpose} needs a recording with a video (recording.video)")
        return video


def _first_error_line(error: pydantic.ValidationError, source: str) -> str:
    first = error.errors()[0]
    field = ".".join(str(part) for part in first["loc"])[:SHOWN_CHARACTERS] or "(top level)"
    message = first["msg"]
    if first["type"] == "extra_forbidden":
        message = "unknown key"
    elif first["type"] == "value_error":
        message = str(first["ctx"]["error"])
    if isinstance(first["input"], dict):  # a section's own check, whose message names its fields
        return f"{source}: {field}: {message}"
    return f"{source}: {field}: {message} (got {shown(first['input'])})"


def scenario_from_dict(data: dict, source: str = "scenario", **overrides) -> Scenario:
    """Validate a scenario mapping, with top-level ``overrides`` applied on top.

    Raises :class:`ScenarioError` with one line naming the source, the field and the value.
    """
    if not isinstance(data, dict):
        raise ScenarioError(f"{source}: expected a mapping of scenario fields (got {type(data).__name__})")
    merged = dict(data)
    for key, value in overrides.items():
        section, _, field = key.partition(".")
        if field:
            merged[section] = {**merged.get(section, {}), field: value}
        else:
            merged[key] = value
    try:
        return Scenario.model_validate(merged)
    except pydantic.ValidationError as error:
        raise ScenarioError(_first_error_line(error, source)) from None


def _pets_recording() -> dict:
    """The files of the PETS 2009 S2.L1 recording that ship with the package."""
    data_dir = resources.files("ptztrack.data") / "pets2009_s2l1"
    return {
        "ground_truth": str(data_dir / "gt_mot15.txt"),
        "calibration": str(data_dir / "pinhole.json"),
        "video": str(data_dir / "View_001.avi"),
    }


def pets_scenario(detector: str = "ideal", **overrides) -> Scenario:
    """The built-in PETS 2009 S2.L1 scenario: the paper's realistic experiment (section 5.2), with every
    parameter fixed a priori (the defaults; :mod:`ptztrack.builders.pets` fits the detector's model on
    frames a table does not score).

    detector : 'ideal' (annotated boxes) or 'hog' (OpenCV's people detector on the view).
    """
    if detector not in ("ideal", "hog"):
        raise ScenarioError(f"pets: detector {detector!r} is not available; expected ideal or hog")
    recording = _pets_recording()
    data = {
        "frames": 398,
        "frame_rate_hz": 5.0,
        "camera": {"image_size_px": (160, 120)},
        "actions": {
            "pan_deg": {"start": -14.0, "stop": 14.0, "count": 7},
            "tilt_deg": {"start": -10.0, "stop": 10.0, "count": 5},
            "zoom": (1.0, 2.0, 3.0, 4.0),
        },
        "detector": {"kind": detector},
        # A person's box as the policies see it: the Caltech benchmark's standardised pedestrian aspect
        # ratio, width = 0.41 x height (Dollar et al., "Pedestrian detection: an evaluation of the state
        # of the art", 2012), at the policies' 1.75 m.
        "people": {"width_m": 0.41 * 1.75},
        # People come and go here (section 5.2): the patrolling term looks for them.
        "control": {"beta": 1.0},
        "recording": recording,
    }
    return scenario_from_dict(data, "pets", **overrides)


def pets_follow_scenario(tracker: str = "particle", **overrides) -> Scenario:
    """The follow camera on PETS 2009 S2.L1: every recorded frame (10 Hz), seen by a 640 x 480 virtual view.

    640 x 480 is the paper's camera (section IV). The camera starts at the view of the whole recorded
    frame (the action grid's only pose). tracker : 'particle', 'csrt' or 'mil'. The person
    is ``follow.target_id``; :func:`ptztrack.builders.follow.target_scenario` narrows the steps to
    their annotated frames. The virtual camera interpolates its sampling map over 8 px, which keeps a
    view's rendering at a few milliseconds (see ``recording.map_grid_px``).
    """
    data = {
        "frames": 795,
        "frame_rate_hz": 10.0,
        "camera": {"image_size_px": (640, 480)},
        # One action: the view of the whole recorded frame, where the camera starts; the policy
        # commands every other pose itself.
        "actions": {
            "pan_deg": {"start": 0.0, "stop": 0.0, "count": 1},
            "tilt_deg": {"start": 0.0, "stop": 0.0, "count": 1},
            "zoom": (1.0,),
        },
        # The annotations lie about 2 px from the calibrated feet in the 768 px frame (0.5 px at 160 px).
        "detector": {"kind": "ideal", "pixel_noise_px": 0.5},
        "tracker": {"kind": tracker},
        "recording": {**_pets_recording(), "frame_step": 1, "map_grid_px": 8},
    }
    return scenario_from_dict(data, "pets follow", **overrides)


def load_scenario(path: str | Path, **overrides) -> Scenario:
    """Read and validate a YAML scenario file (see the README for the format)."""
    path = Path(path)
    data = read_yaml(path, "scenario", ScenarioError)
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise ScenarioError(f"{path}: expected a mapping of scenario fields (got {type(data).__name__})")
    recording = data.get("recording")
    if isinstance(recording, dict):
        data = {**data, "recording": {**recording, **_resolved_paths(recording, path.parent)}}
    return scenario_from_dict(data, str(path), **overrides)


class _LimitedLoader(yaml.SafeLoader):
    """YAML's safe loader, refusing duplicate keys (YAML forbids them; PyYAML keeps the last)."""

    def construct_mapping(self, node, deep=False):
        seen = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            if isinstance(key, Hashable) and key in seen:
                raise _DuplicateKey(key, key_node.start_mark.line + 1)
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


class _DuplicateKey(Exception):
    def __init__(self, key, line: int):
        super().__init__(key, line)
        self.key, self.line = key, line


def _expanded_values(node: yaml.Node, limit: int) -> int:
    """How many values ``node`` holds with every alias expanded, counting no further than past ``limit``.

    An alias is the node it names, so a shared node is counted once per reference; the sizes are
    memoised per node, which takes time linear in the document even when the expansion is exponential.
    """
    sizes: dict[int, int] = {}

    def size(current: yaml.Node) -> int:
        if id(current) in sizes:
            return sizes[id(current)]
        sizes[id(current)] = limit + 1  # a node reached again while being sized is a cycle
        if isinstance(current, yaml.SequenceNode):
            total = 1 + sum(size(child) for child in current.value)
        elif isinstance(current, yaml.MappingNode):
            total = 1 + sum(size(key) + size(value) for key, value in current.value)
        else:
            total = 1
        sizes[id(current)] = min(total, limit + 1)
        return sizes[id(current)]

    return size(node)


def read_yaml(path: str | Path, what: str, error_type: type[InputError]) -> object:
    """A user's YAML file, read safely: at most 1 MB of UTF-8 and 100 000 values once aliases are
    expanded, no duplicate keys; any problem is ``error_type`` naming the file and the line."""
    path = Path(path)
    text = read_text(path, what, SCENARIO_MAX_BYTES, error_type)
    try:
        loader = _LimitedLoader(text)
    except yaml.YAMLError as error:  # characters YAML does not allow, found as the reader starts
        raise error_type(f"{path}: not valid YAML ({shown(str(error).splitlines()[0])})") from None
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        if _expanded_values(node, YAML_MAX_VALUES) > YAML_MAX_VALUES:
            raise error_type(
                f"{path}: more than {YAML_MAX_VALUES} values once its aliases are expanded; expected a {what} file"
            )
        return loader.construct_document(node)
    except _DuplicateKey as duplicate:
        raise error_type(f"{path}: line {duplicate.line}: key {shown(duplicate.key)} appears twice") from None
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark else ""
        raise error_type(f"{path}: not valid YAML{where}") from None
    except RecursionError:
        raise error_type(f"{path}: YAML nested too deeply for a {what} file") from None
    finally:
        loader.dispose()


def _resolved_paths(recording: dict, base: Path) -> dict:
    return {
        key: str(base / value)
        for key, value in recording.items()
        if key in ("ground_truth", "calibration", "video") and isinstance(value, str)
    }


# ---------------------------------------------------------------------------
# Multi-view datasets and the occupancy-map detector (the LPOM paper).
# ---------------------------------------------------------------------------


class DatasetView(_Strict):
    """One fixed camera of a multi-view dataset.

    calibration : a Tsai XML (PETS 2009) or a pinhole JSON (``{view: {K, dist, R, t}}``, world in mm);
    calibration_view : the view's key in a pinhole JSON (default: ``name``).
    image_size_px : (width, height); read from a Tsai XML, checked against it when given; needed with
    a pinhole JSON. video (a file) or images (a folder, frames in sorted name order) : the frames,
    for motion edges; detections : a MOTChallenge detection file (``frame,-1,left,top,width,height,score,...``,
    frames from 1), for views without frames and for the clustering baseline. weight : ``w_c``.
    """

    name: str
    calibration: str
    calibration_view: str | None = None
    image_size_px: tuple[Pixels, Pixels] | None = None
    video: str | None = None
    images: str | None = None
    detections: str | None = None
    weight: Annotated[PositiveFloat, at_most(1e6, "a relative weight")] = 1.0

    @model_validator(mode="after")
    def _has_evidence(self):
        if self.video is not None and self.images is not None:
            raise ValueError("give video or images, not both")
        if self.video is None and self.images is None and self.detections is None:
            raise ValueError("a view needs video, images or detections")
        return self


_PersonHeight = Annotated[PositiveFloat, at_most(10, "metres: a person")]
_GroundDistance = Annotated[PositiveFloat, at_most(1000, "metres")]
_LOCUS_MEMORY = "memory: the locus tables hold every block's points for every height"
MAX_PERSON_HEIGHTS = 100
MAX_GROUND_CELLS = 10_000_000
MAX_DATASET_FRAMES = _MAX_FRAMES
"""Cells of an occupancy map: 80 MB a map in float64, several kept per frame."""


class Occupancy(_Strict):
    """The occupancy-map detector, its baseline and where their parameters come from (README).

    Person model (equation 4, Algorithm 1): heights from min_height_m up to max_height_m in steps of
    height_step_m (at the steps' midpoints), width_m, samples_per_height tangent points per height.
    Map: cell_m, kernel_sigma_m (the Gaussian kernel), block_px (locus tables per block of pixels).
    Modes: separation_m (closest two people), window_m (their mean and covariance), min_strength
    (fraction of the frame's strongest mode; None: fitted on the other half of the frames).
    Motion edges: canny_low, canny_high, difference_threshold (grey levels), dilation_px.
    Boxes: outline_points_per_box, min_box_score. Baseline: linkage_m (complete-linkage cut),
    min_views (None: fitted like min_strength), blob_min_area_px (blob boxes of views without detections).
    """

    min_height_m: _PersonHeight = 1.6
    max_height_m: _PersonHeight = 1.9
    height_step_m: _PersonHeight = 0.1
    width_m: Annotated[PositiveFloat, at_most(10, "metres: a person")] = 0.5
    samples_per_height: Annotated[int, Field(ge=1), at_most(1000, _LOCUS_MEMORY)] = 32
    cell_m: PositiveFloat = 0.05
    kernel_sigma_m: _GroundDistance = 0.1
    block_px: Annotated[int, Field(ge=1), at_most(256, "pixels")] = 4
    separation_m: _GroundDistance = 0.5
    window_m: _GroundDistance = 0.25
    canny_low: Annotated[NonNegativeFloat, at_most(10_000, "a gradient magnitude")] = 50.0
    canny_high: Annotated[NonNegativeFloat, at_most(10_000, "a gradient magnitude")] = 150.0
    difference_threshold: Annotated[NonNegativeFloat, at_most(255, "grey levels")] = 15.0
    dilation_px: Annotated[int, Field(ge=0), at_most(256, "pixels")] = 2
    outline_points_per_box: Annotated[int, Field(ge=4), at_most(10_000, _LOCUS_MEMORY)] = 64
    min_box_score: float = Field(0.5, ge=0, le=1)
    linkage_m: _GroundDistance = 1.0
    blob_min_area_px: Annotated[int, Field(ge=1), at_most(8192 * 8192, "an image's pixels")] = 400

    @model_validator(mode="after")
    def _heights_ordered(self):
        if self.max_height_m < self.min_height_m:
            raise ValueError(f"max_height_m must be at least min_height_m ({self.min_height_m})")
        heights = (self.max_height_m - self.min_height_m) / self.height_step_m
        if heights > MAX_PERSON_HEIGHTS:
            raise ValueError(
                f"height_step_m {self.height_step_m:g} gives {heights:.3g} heights; at most "
                f"{MAX_PERSON_HEIGHTS} ({_LOCUS_MEMORY})"
            )
        return self


class OccupancyTracker(Tracker):
    """The ground tracker fed by the occupancy map: the scenario's tracker section, but a track is
    reported from its second detection on (the map's one-off ghosts, loci of two views crossing by
    chance, rarely repeat at the same place, as HOG's false positives: ``PETS_HOG_TRACKER``)."""

    confirmation_hits: int = Field(2, ge=1)


class MultiViewDataset(_Strict):
    """A calibrated multi-view recording (README, "The occupancy-map detector"). Relative paths in a
    dataset file are relative to it.

    area_m : [[x0, y0], [x1, y1]] the ground the map covers, metres (people outside it are not scored);
    frames : how many frames to use (default: all that every view and the ground truth have);
    ground_truth : MOTChallenge rows with world x, y in metres in columns 8-9 (frames from 1).
    """

    name: str = "dataset"
    frame_rate_hz: Annotated[PositiveFloat, at_most(1000, "frames per second")]
    frames: (
        Annotated[int, Field(ge=1), at_most(MAX_DATASET_FRAMES, "memory: every frame's map and modes are kept")] | None
    ) = None
    area_m: tuple[tuple[float, float], tuple[float, float]]
    ground_truth: str | None = None
    views: Annotated[list[DatasetView], Field(min_length=1), at_most_items(64, "time: every view's loci, every frame")]
    occupancy: Occupancy = Occupancy()
    tracker: OccupancyTracker = OccupancyTracker()

    @model_validator(mode="after")
    def _area_and_names(self):
        (x0, y0), (x1, y1) = self.area_m
        if not (x1 > x0 and y1 > y0):
            raise ValueError("area_m must be [[x0, y0], [x1, y1]] with x1 > x0 and y1 > y0")
        cells = (x1 - x0) * (y1 - y0) / self.occupancy.cell_m**2
        if cells > MAX_GROUND_CELLS:
            raise ValueError(
                f"area_m at occupancy.cell_m {self.occupancy.cell_m:g} m makes {cells:.3g} cells; at most "
                f"{MAX_GROUND_CELLS:g} (memory: a map of float64 cells per frame): make the cells larger"
            )
        names = [view.name for view in self.views]
        if len(set(names)) != len(names):
            raise ValueError(f"view names must differ (got {names})")
        if self.tracker.association != "hungarian":
            raise ValueError("the occupancy map's modes are associated by the Hungarian assignment only")
        return self


DATASET_PATH_FIELDS = ("calibration", "video", "images", "detections")


def dataset_from_dict(data: Any, source: str = "dataset") -> MultiViewDataset:
    """Validate a multi-view dataset mapping; a :class:`ScenarioError` of one line naming the field."""
    if not isinstance(data, dict):
        raise ScenarioError(f"{source}: expected a mapping of dataset fields (got {type(data).__name__})")
    try:
        return MultiViewDataset.model_validate(data)
    except pydantic.ValidationError as error:
        raise ScenarioError(_first_error_line(error, source)) from None


def load_dataset(path: str | Path) -> MultiViewDataset:
    """Read and validate a multi-view dataset YAML file, its relative paths made relative to it."""
    path = Path(path)
    data = read_yaml(path, "dataset", ScenarioError)
    if isinstance(data, dict):
        base = path.parent
        if isinstance(data.get("ground_truth"), str):
            data = {**data, "ground_truth": str(base / data["ground_truth"])}
        if isinstance(data.get("views"), list):
            views = [
                {
                    **view,
                    **{key: str(base / view[key]) for key in DATASET_PATH_FIELDS if isinstance(view.get(key), str)},
                }
                if isinstance(view, dict)
                else view
                for view in data["views"]
            ]
            data = {**data, "views": views}
    return dataset_from_dict(data, str(path))


# PETS 2009 S2.L1 as a multi-view dataset: the seven views with published detections (View_002 has
# none), their official Tsai calibrations, View_001's video. The area holds every annotated
# position with a margin of about a metre. A person in these views is 0.1-0.4 m on the ground per
# 4-15 px of feet error (the detections' median, README of the data), hence the wider kernel and
# cells than in the room; 10 fps as in the PETS scenario.
PETS_VIEWS = ("View_001", "View_003", "View_004", "View_005", "View_006", "View_007", "View_008")
PETS_OCCUPANCY = {"cell_m": 0.1, "kernel_sigma_m": 0.25}


def pets_dataset(**overrides) -> MultiViewDataset:
    """The built-in PETS 2009 S2.L1 dataset (seven views), from the files shipped with ptztrack."""
    data_dir = resources.files("ptztrack.data") / "pets2009_s2l1"
    views = [
        {
            "name": view,
            "calibration": str(data_dir / f"{view}.xml"),
            "detections": str(data_dir / f"{view}_det.txt.gz"),
            **({"video": str(data_dir / "View_001.avi")} if view == "View_001" else {}),
        }
        for view in PETS_VIEWS
    ]
    data = {
        "name": "pets",
        "frame_rate_hz": 10.0,
        "area_m": ((-21.0, -17.5), (8.5, 9.0)),
        "ground_truth": str(data_dir / "gt_mot15.txt"),
        "views": views,
        "occupancy": PETS_OCCUPANCY,
        **overrides,
    }
    return dataset_from_dict(data, "pets")


# ---------------------------------------------------------------------------
# A real (or virtual) ONVIF PTZ camera: its calibration file (README, "Real cameras").
# ---------------------------------------------------------------------------

_MoveTime = tuple[
    Annotated[NonNegativeFloat, at_most(60, "seconds")], Annotated[NonNegativeFloat, at_most(60, "seconds per unit")]
]


class MoveTimesSection(_Strict):
    """``intercept_s + slope x distance`` per axis (Frigate's model), as [intercept_s, slope]: pan and tilt
    per degree, zoom per unit of zoom factor; ``ptztrack camera calibrate`` measures them."""

    pan: _MoveTime = (0.0, 0.0)
    tilt: _MoveTime = (0.0, 0.0)
    zoom: _MoveTime = (0.0, 0.0)


class CameraCalibrationFile(_Strict):
    """How a camera's normalised ONVIF spaces map to the camera model, and how long its moves take.

    pan_deg, tilt_deg : the degrees at normalised -1 and +1; zoom_curve : [[normalised, zoom factor], ...]
    both increasing, from the widest view (zoom factor 1); position_m : the optical centre (x, y, z) on the
    ground plane's axes, metres, and f_min_px : the focal length at zoom 1 (null: the scenario's camera);
    move_times : see :class:`MoveTimesSection`; image_delay_s : how long after the camera stands still
    its images show where it stands (a frame interval and the stream's latency; 0.1 s: a 10 fps stream).
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

    @model_validator(mode="after")
    def _monotonic(self):
        if self.pan_deg[0] == self.pan_deg[1] or self.tilt_deg[0] == self.tilt_deg[1]:
            raise ValueError("pan_deg and tilt_deg must each span a range (two different ends)")
        curve = np.asarray(self.zoom_curve, dtype=float)
        if np.any(np.diff(curve, axis=0) <= 0):
            raise ValueError("zoom_curve must increase in both columns, point after point")
        return self


def load_camera_calibration(path: str | Path) -> CameraCalibrationFile:
    """Read and validate a camera calibration YAML file; a :class:`ScenarioError` of one line if it is not one."""
    data = read_yaml(path, "camera calibration", ScenarioError)
    if not isinstance(data, dict):
        raise ScenarioError(f"{path}: expected a mapping of camera calibration fields (got {type(data).__name__})")
    try:
        return CameraCalibrationFile.model_validate(data)
    except pydantic.ValidationError as error:
        raise ScenarioError(_first_error_line(error, str(path))) from None


# The virtual ONVIF camera of `ptztrack serve-camera` over PETS: spaces wider than the PETS grid, as a
# real camera's are, and the zoom range of the virtual camera.
VIRTUAL_CAMERA_CALIBRATION = {
    "pan_deg": (-90.0, 90.0),
    "tilt_deg": (-45.0, 45.0),
    "zoom_curve": [(0.0, 1.0), (1.0, 8.0)],
}


def write_camera_calibration(path: str | Path, calibration: CameraCalibrationFile) -> None:
    """Write a camera calibration as YAML, atomically (comments of an earlier file are not kept)."""
    text = yaml.safe_dump(calibration.model_dump(mode="json"), sort_keys=False)
    write_atomically(Path(path), text.encode())
