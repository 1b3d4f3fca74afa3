"""One validated configuration object per run, loadable from YAML.

The defaults are the synthetic scene of the paper's section 5.1 with the
camera mounting chosen in :mod:`ptztrack.scene.synthetic`.
"""

from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import pydantic
import yaml
from pydantic import AfterValidator, BaseModel, ConfigDict, Field, model_validator

from ptztrack import registry

PositiveFloat = Annotated[float, Field(gt=0)]
NonNegativeFloat = Annotated[float, Field(ge=0)]


class ScenarioError(ValueError):
    """A scenario that cannot be run; the message is one line naming the field and value."""


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
    model_config = ConfigDict(extra="forbid", frozen=True)


class People(_Strict):
    count: int = Field(7, ge=0)
    speed_m_s: tuple[PositiveFloat, PositiveFloat] = (1.0, 1.5)
    height_m: tuple[PositiveFloat, PositiveFloat] = (1.6, 1.9)
    width_m: PositiveFloat = 0.5
    turn_rate_sigma_deg_s: NonNegativeFloat = 40.0
    enter_leave: bool = False
    stay_s: tuple[PositiveFloat, PositiveFloat] = (8.0, 20.0)

    @model_validator(mode="after")
    def _intervals_ordered(self):
        for name in ("speed_m_s", "height_m", "stay_s"):
            low, high = getattr(self, name)
            if high < low:
                raise ValueError(f"{name} must be [low, high] with low <= high (got {[low, high]})")
        return self


class PoseError(_Strict):
    """How far a real PTZ camera lands from the pose it was sent to (backlash, zoom curves).

    Each time the command changes, the camera lands at the commanded pan and tilt plus
    ``pan_tilt_bias_deg`` plus independent Gaussian errors of ``pan_tilt_sigma_deg``, and at the
    commanded zoom times ``zoom_bias`` times (1 + a Gaussian error of ``zoom_sigma``); it stays there
    while the command does not change. The defaults are a perfect camera.
    """

    pan_tilt_sigma_deg: NonNegativeFloat = 0.0
    pan_tilt_bias_deg: tuple[float, float] = (0.0, 0.0)
    zoom_sigma: Annotated[float, Field(ge=0, lt=0.5)] = 0.0
    zoom_bias: PositiveFloat = 1.0


class Camera(_Strict):
    """The PTZ camera. backend : a registered camera backend; by default 'simulated' for the
    synthetic scene and 'virtual' (the virtual PTZ camera) for a recording."""

    position_m: tuple[float, float, PositiveFloat] = (7.5, -4.0, 7.0)
    image_size_px: tuple[Annotated[int, Field(gt=0)], Annotated[int, Field(gt=0)]] = (640, 480)
    f_min_px: PositiveFloat = 400.0
    pose_error: PoseError = PoseError()
    backend: Annotated[str | None, _registered("cameras")] = None
    options: Options = Field(default_factory=dict)


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
    image_size_px: tuple[Annotated[int, Field(gt=0)], Annotated[int, Field(gt=0)]] = (640, 480)
    reference_zooms: tuple[Annotated[float, Field(ge=1)], ...] = (1.0, 2.0, 3.2)
    reference_pan_steps: int = Field(5, ge=1)
    reference_tilt_steps: int = Field(3, ge=1)
    reference_pose_sigma_deg: NonNegativeFloat = 0.5
    reference_zoom_spread: Annotated[float, Field(ge=0, lt=0.5)] = 0.03
    index: str | None = None


class AxisRange(_Strict):
    start: float
    stop: float
    count: int = Field(ge=1)

    def values(self) -> np.ndarray:
        return np.linspace(self.start, self.stop, self.count)


class Actions(_Strict):
    pan_deg: AxisRange = AxisRange(start=-45.0, stop=45.0, count=7)
    tilt_deg: AxisRange = AxisRange(start=15.0, stop=60.0, count=10)
    zoom: tuple[Annotated[float, Field(ge=1)], ...] = (1.0, 2.0, 3.0, 4.0)
    max_steps: tuple[Annotated[int, Field(ge=0)], Annotated[int, Field(ge=0)], Annotated[int, Field(ge=0)]] = (
        2,
        2,
        1,
    )

    @model_validator(mode="after")
    def _zoom_increasing(self):
        if len(self.zoom) == 0 or np.any(np.diff(self.zoom) <= 0):
            raise ValueError(f"zoom must be a non-empty increasing list (got {list(self.zoom)})")
        if not -90 < self.tilt_deg.start <= self.tilt_deg.stop < 90:
            raise ValueError("tilt_deg must run upwards within (-90, 90)")
        return self


class Detector(_Strict):
    """The detector: simulated (ideal, realistic), OpenCV's HOG on a recording's virtual view, or any
    detector registered by another package (``options`` are its parameters).

    The policies plan with recall 1 for 'ideal' and with the recall curve ``recall_kd``,
    ``recall_r0_px`` (the paper's equation 13) for every other kind.
    """

    kind: Annotated[str, _registered("detectors")] = "realistic"
    options: Options = Field(default_factory=dict)
    recall_kd: PositiveFloat = 0.0098
    recall_r0_px: NonNegativeFloat = 21.29
    pixel_noise_px: NonNegativeFloat = 2.0
    false_positives_per_frame: NonNegativeFloat = 0.0
    hog_upsample: PositiveFloat = 6.0
    hog_hit_threshold: float = 0.0
    hog_nms_iou: float = Field(0.4, gt=0, le=1)


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
    """

    kind: Annotated[str, _registered("trackers")] = "ekf"
    options: Options = Field(default_factory=dict)
    acceleration_sigma_m_s2: PositiveFloat = 1.5
    initial_speed_sigma_m_s: PositiveFloat = 0.9
    gate_probability: float = Field(0.99, gt=0, lt=1)
    max_missed_steps: int = Field(5, ge=0)
    max_position_sigma_m: PositiveFloat = 2.0
    confirmation_hits: int = Field(1, ge=1)
    association: Literal["hungarian", "cjpdaf"] = "hungarian"
    clutter_density_per_px2: NonNegativeFloat = 0.0
    measurement_source: Literal["detector", "spatiogram"] = "detector"
    detector_every_steps: int = Field(5, ge=1)


class Control(_Strict):
    """Parameters of the information-gain policies (paper sections 4 and 4.4)."""

    samples: int = Field(100, ge=1)
    beta: NonNegativeFloat = 1.0
    person_height_m: PositiveFloat = 1.75
    exploration_cell_m: PositiveFloat = 1.0
    prior_occupancy: float = Field(0.05, ge=0, lt=1)
    arrival_rate_per_m2_s: NonNegativeFloat = 0.002


class Recording(_Strict):
    """A calibrated recording with ground truth, seen through a virtual PTZ camera (paper section 5.2).

    With a recording, the camera's position and focal length come from the
    calibration (``camera.image_size_px`` sets the virtual view), and the
    action grid's pan and tilt are offsets from the pose that shows the whole
    recorded frame. Relative paths in a scenario file are relative to it.
    """

    ground_truth: str
    calibration: str
    view: str = "View_001"
    video: str | None = None
    recorded_size_px: tuple[Annotated[int, Field(gt=0)], Annotated[int, Field(gt=0)]] = (768, 576)
    frame_step: int = Field(2, ge=1)
    occluded_above: float = Field(0.25, ge=0, le=1)


class Scenario(_Strict):
    """Everything a run needs besides the policy and the seed."""

    area_m: tuple[PositiveFloat, PositiveFloat] = (15.0, 15.0)
    frames: int = Field(50, ge=1)
    frame_rate_hz: PositiveFloat = 5.0
    people: People = People()
    camera: Camera = Camera()
    actions: Actions = Actions()
    detector: Detector = Detector()
    tracker: Tracker = Tracker()
    control: Control = Control()
    pose_feedback: PoseFeedback = PoseFeedback()
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

    @property
    def area_bounds_m(self) -> np.ndarray:
        """[[x0, y0], [x1, y1]] of the synthetic area, whose corner is the origin."""
        return np.array([[0.0, 0.0], list(self.area_m)])

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
    field = ".".join(str(part) for part in first["loc"]) or "(top level)"
    message = first["msg"]
    if first["type"] == "extra_forbidden":
        message = "unknown key"
    elif first["type"] == "value_error":
        message = str(first["ctx"]["error"])
    return f"{source}: {field}: {message} (got {first['input']!r})"


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


# Pixel noise of the feet in the 160 x 120 virtual view: the annotations lie
# about 2 px from the calibrated feet in the 768 px frame (0.5 px here); HOG's
# feet lie a median 1.6 px from them, which a 2-D Gaussian of 1.4 px gives.
PETS_PIXEL_NOISE_PX = {"ideal": 0.5, "hog": 1.5}
# The recall curve the policies plan with for HOG on these views, fitted by
# benchmarks/fit_hog_recall.py (maximum likelihood over 2210 annotated people
# in views of every 20th step at zoom 1-4): HOG on a 6x upsampled view finds
# 84 % of the people 15-21 px tall, where the paper's Caltech curve
# (Kd 0.0098, r0 21.29) predicts none.
PETS_HOG_RECALL = {"recall_kd": 0.0795, "recall_r0_px": 1.83}
# HOG reports false positives (fix: 599 against 1809 matches), which rarely
# repeat at the same ground point: with HOG a track is reported from its
# second detection on, and dies at its first miss until then. The simulated
# detectors report none, and there confirmation only loses tracks of people
# seen rarely (synthetic realistic table, fix: 63.2 % -> 32.3 % MOTA).
# The CJPDAF's clutter density: HOG's boxes whose feet lie more than 5 px x
# zoom from every annotated person's are 0.04 per view at zoom 1 and 0.2 at
# zoom 2, at a recall of 0.69 and 0.91 (benchmarks/hog_clutter.py), which
# makes lambda (1 - P_D P_G) / P_D 0.9e-6 and 1.2e-6 per px^2.
PETS_HOG_TRACKER = {"confirmation_hits": 2, "clutter_density_per_px2": 1e-6}


def pets_scenario(detector: str = "ideal", **overrides) -> Scenario:
    """The built-in PETS 2009 S2.L1 scenario: the paper's realistic experiment (section 5.2).

    detector : 'ideal' (annotated boxes) or 'hog' (OpenCV's people detector on the view).
    """
    if detector not in PETS_PIXEL_NOISE_PX:
        raise ScenarioError(f"pets: detector {detector!r} is not available; expected ideal or hog")
    data_dir = resources.files("ptztrack.data") / "pets2009_s2l1"
    recording = {
        "ground_truth": str(data_dir / "gt_mot15.txt"),
        "calibration": str(data_dir / "pinhole.json"),
        "video": str(data_dir / "View_001.avi"),
    }
    data = {
        "frames": 398,
        "frame_rate_hz": 5.0,
        "camera": {"image_size_px": (160, 120)},
        "actions": {
            "pan_deg": {"start": -14.0, "stop": 14.0, "count": 7},
            "tilt_deg": {"start": -10.0, "stop": 10.0, "count": 5},
            "zoom": (1.0, 2.0, 3.0, 4.0),
        },
        "detector": {
            "kind": detector,
            "pixel_noise_px": PETS_PIXEL_NOISE_PX[detector],
            **(PETS_HOG_RECALL if detector == "hog" else {}),
        },
        "tracker": PETS_HOG_TRACKER if detector == "hog" else {},
        "recording": recording,
    }
    return scenario_from_dict(data, "pets", **overrides)


def load_scenario(path: str | Path, **overrides) -> Scenario:
    """Read and validate a YAML scenario file (see the README for the format)."""
    path = Path(path)
    data = _read_yaml(path, "scenario")
    data = {} if data is None else data
    recording = data.get("recording") if isinstance(data, dict) else None
    if isinstance(recording, dict):
        data = {**data, "recording": {**recording, **_resolved_paths(recording, path.parent)}}
    return scenario_from_dict(data, str(path), **overrides)


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
    image_size_px: tuple[Annotated[int, Field(gt=0)], Annotated[int, Field(gt=0)]] | None = None
    video: str | None = None
    images: str | None = None
    detections: str | None = None
    weight: PositiveFloat = 1.0

    @model_validator(mode="after")
    def _has_evidence(self):
        if self.video is not None and self.images is not None:
            raise ValueError("give video or images, not both")
        if self.video is None and self.images is None and self.detections is None:
            raise ValueError("a view needs video, images or detections")
        return self


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

    min_height_m: PositiveFloat = 1.6
    max_height_m: PositiveFloat = 1.9
    height_step_m: PositiveFloat = 0.1
    width_m: PositiveFloat = 0.5
    samples_per_height: int = Field(32, ge=1)
    cell_m: PositiveFloat = 0.05
    kernel_sigma_m: PositiveFloat = 0.1
    block_px: int = Field(4, ge=1)
    separation_m: PositiveFloat = 0.5
    window_m: PositiveFloat = 0.25
    canny_low: NonNegativeFloat = 50.0
    canny_high: NonNegativeFloat = 150.0
    difference_threshold: NonNegativeFloat = 15.0
    dilation_px: int = Field(2, ge=0)
    outline_points_per_box: int = Field(64, ge=4)
    min_box_score: float = Field(0.5, ge=0, le=1)
    linkage_m: PositiveFloat = 1.0
    blob_min_area_px: int = Field(400, ge=1)

    @model_validator(mode="after")
    def _heights_ordered(self):
        if self.max_height_m < self.min_height_m:
            raise ValueError(f"max_height_m must be at least min_height_m ({self.min_height_m})")
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
    frame_rate_hz: PositiveFloat
    frames: int | None = Field(None, ge=1)
    area_m: tuple[tuple[float, float], tuple[float, float]]
    ground_truth: str | None = None
    views: list[DatasetView] = Field(min_length=1)
    occupancy: Occupancy = Occupancy()
    tracker: OccupancyTracker = OccupancyTracker()

    @model_validator(mode="after")
    def _area_and_names(self):
        (x0, y0), (x1, y1) = self.area_m
        if not (x1 > x0 and y1 > y0):
            raise ValueError("area_m must be [[x0, y0], [x1, y1]] with x1 > x0 and y1 > y0")
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
    data = _read_yaml(path, "dataset")
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


def _read_yaml(path: Path, what: str) -> Any:
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        raise ScenarioError(f"{path}: cannot read {what} file ({error.strerror})") from None
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark else ""
        raise ScenarioError(f"{path}: not valid YAML{where}") from None


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
