"""One validated configuration object per run, loadable from YAML: the scenario, its people, detector,
tracker, control and recording sections.

The defaults are the synthetic scene of the paper's section 5.1 with the
camera mounting chosen in :mod:`ptztrack.scene.synthetic`.
"""

from pathlib import Path
from typing import Annotated, Literal

import pydantic
from pydantic import Field, model_validator

from ptztrack.config.camera import Actions, Camera, PoseFeedback
from ptztrack.config.fields import (
    _MAX_FRAMES,
    NonNegativeFloat,
    Options,
    Pixels,
    PositiveFloat,
    _Coordinate,
    _registered,
    _Strict,
    at_most,
    at_most_items,
)
from ptztrack.config.follow import Follow
from ptztrack.config.reading import FILE_KINDS, ScenarioError, _first_error_line, read_yaml, refuse_another_kind
from ptztrack.control.parameters import ControlParameters
from ptztrack.detect.parameters import BoxDetectorParameters, DetectorPriorParameters, HogParameters
from ptztrack.names import DETECTOR_MODELS
from ptztrack.scene.parameters import CrowdParameters
from ptztrack.track.parameters import TrackerParameters

_Speed = Annotated[PositiveFloat, at_most(15, "metres per second: faster than anyone runs")]
_Height = Annotated[PositiveFloat, at_most(3, "metres: taller than anyone")]
_Stay = Annotated[PositiveFloat, at_most(86_400, "seconds: a day")]


class People(_Strict):
    """The synthetic crowd (:class:`~ptztrack.scene.parameters.CrowdParameters`, whose defaults it takes).
    paired_fraction : the share of the ``count`` people who walk in pairs, side by side
    ``pair_spacing_m`` apart (pairs: the fraction of count / 2, rounded).

    trajectories : a file of recorded people's positions in metres to replay instead of the walkers
    (:mod:`ptztrack.scene.trajectories`: MOTChallenge rows with metres in columns 8-9, or ``frame id x
    y`` lines), relative to the scenario file; its people are the crowd, so ``count``, ``speed_m_s``,
    the turning, ``enter_leave``, ``stay_s`` and the pairs do not apply: each person gets a height drawn
    from ``height_m`` and the width ``width_m``. Not with a ``recording``, whose people are its own.
    trajectories_frame_rate_hz : frames per second of the file's frame numbers (neither format says it;
    a sample of frame f is at (f - the file's first frame) / this rate seconds, the run's step 0 at
    its first frame). Required with ``trajectories``.
    trajectories_offset_m : (dx, dy) metres added to the file's positions; None: the translation that
    puts the centre of the bounding box of all its positions at the centre of ``area_m``.
    """

    count: Annotated[int, Field(ge=0), at_most(1000, "time: the policies score every person under every action")] = (
        CrowdParameters.count
    )
    speed_m_s: tuple[_Speed, _Speed] = CrowdParameters.speed_m_s
    height_m: tuple[_Height, _Height] = CrowdParameters.height_m
    width_m: Annotated[PositiveFloat, at_most(3, "metres: a person's width")] = CrowdParameters.width_m
    turn_rate_sigma_deg_s: Annotated[NonNegativeFloat, at_most(3600, "degrees per second")] = (
        CrowdParameters.turn_rate_sigma_deg_s
    )
    enter_leave: bool = CrowdParameters.enter_leave
    stay_s: tuple[_Stay, _Stay] = CrowdParameters.stay_s
    paired_fraction: float = Field(CrowdParameters.paired_fraction, ge=0, le=1)
    pair_spacing_m: Annotated[PositiveFloat, at_most(10, "metres between two people walking together")] = (
        CrowdParameters.pair_spacing_m
    )
    trajectories: str | None = None
    trajectories_frame_rate_hz: Annotated[PositiveFloat, at_most(1000, "frames per second")] | None = None
    trajectories_offset_m: tuple[_Coordinate, _Coordinate] | None = None

    @model_validator(mode="after")
    def _intervals_ordered(self):
        for name in ("speed_m_s", "height_m", "stay_s"):
            low, high = getattr(self, name)
            if high < low:
                raise ValueError(f"{name} must be [low, high] with low <= high (got {[low, high]})")
        return self

    @model_validator(mode="after")
    def _trajectories_with_their_rate(self):
        if self.trajectories is not None and self.trajectories_frame_rate_hz is None:
            raise ValueError(
                "trajectories_frame_rate_hz is required with trajectories: the frames per second of the "
                f"file's frame numbers, which it does not say (trajectories {self.trajectories!r})"
            )
        if self.trajectories is None:
            for name in ("trajectories_frame_rate_hz", "trajectories_offset_m"):
                if getattr(self, name) is not None:
                    raise ValueError(f"{name} is set but trajectories, the file it is for, is not")
        return self


class Detector(_Strict):
    """The detector: simulated (ideal, realistic), OpenCV's HOG on a recording's virtual view, a recording's
    precomputed boxes, or any detector registered by another package.

    kind : a registered detector: 'ideal' (simulated, recall 1; on a recording, every annotated person
    wholly in view and hidden at most ``recording.occluded_above``), 'realistic' (simulated, the recall
    curve ``recall_kd``, ``recall_r0_px``, with ``pixel_noise_px`` and ``false_positives_per_frame``), 'hog'
    (OpenCV's HOG on the recording's views), 'detections' (the recording's precomputed boxes) or another
    package's. options : the parameters of another package's detector, passed to its factory unread
    (ptztrack's own detectors take none).
    model : what the policies and the tracker know of the detector (:mod:`ptztrack.detect.detector_model`):
    'online' (the default) starts from the recall curve ``recall_kd``, ``recall_r0_px`` (the paper's
    equation 13), its r0 shifted by ``prior_shift_px``, and learns the curve as the camera runs; 'a-priori'
    keeps that prior, 'true' plans with the simulation's own curve (a simulated detector only), and a file
    path (an earlier run's ``detector_model.json``) starts from what that run learned. For 'ideal' the
    model is recall 1, kept. prior_shift_px : pixels added to the prior curve's r0 (the person height in
    pixels below which the recall is 0) with 'online' and 'a-priori'; positive: a more pessimistic prior.

    The recall curve's, the noise's and the HOG fields' defaults are those of
    :class:`~ptztrack.detect.parameters.DetectorPriorParameters` and :class:`~ptztrack.detect.parameters.HogParameters`.

    hog_search : 'ground' scans only the windows where a standing person ``hog_person_height_m``
    (shortest, tallest) tall could be seen on the walkable area, at their sizes; 'image' scans every
    window of the pyramid, as OpenCV's ``detectMultiScale`` (:mod:`ptztrack.detect.hog`).
    hog_person_height_m : (shortest, tallest) metres, the standing people the 'ground' search looks for.
    box_min_score : 'detections' (the recording's precomputed boxes, ``recording.detections``) reports the
    boxes scored at least this.
    hog_luma : HOG reads only the pictures' luma (true) or the strongest gradient of their three colours
    (false); unset, luma for a live camera's pictures (decoded from its video stream, whose colour has
    half the resolution each way and its losses) and colour for a recording's views.
    """

    kind: Annotated[str, _registered("detectors")] = "realistic"
    options: Options = Field(default_factory=dict)
    recall_kd: Annotated[PositiveFloat, at_most(100, "per pixel")] = DetectorPriorParameters.recall_kd
    recall_r0_px: Annotated[NonNegativeFloat, at_most(10_000, "pixels")] = DetectorPriorParameters.recall_r0_px
    pixel_noise_px: Annotated[NonNegativeFloat, at_most(10_000, "pixels")] = DetectorPriorParameters.pixel_noise_px
    false_positives_per_frame: Annotated[
        NonNegativeFloat, at_most(1000, "time and memory: every detection is kept and associated")
    ] = DetectorPriorParameters.false_positives_per_frame
    hog_upsample: Annotated[PositiveFloat, at_most(16, "memory: the view is upsampled this much each way")] = (
        HogParameters.upsample
    )
    hog_hit_threshold: float = HogParameters.hit_threshold
    hog_nms_iou: float = Field(HogParameters.nms_iou, gt=0, le=1)
    hog_search: Literal["ground", "image"] = "ground"
    hog_person_height_m: tuple[_Height, _Height] = HogParameters.person_heights_m
    hog_luma: bool | None = None
    box_min_score: float = Field(BoxDetectorParameters.min_score, ge=0, le=1)
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

    The fields shared with :class:`~ptztrack.track.parameters.TrackerParameters` take its defaults.

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
    (a positive C there only discounts true detections of uncertain tracks);
    a detector model learned online replaces it by its own estimate every step.
    The Hungarian association ignores it.
    measurement_source : 'detector' (every step) or 'spatiogram' (the scale-invariant paper's
    section 5: the detector runs every ``detector_every_steps`` steps, to start tracks and retake
    each detected track's colour spatiogram; in between, each track is measured by searching for
    its spatiogram around its prediction, at the scale the head/feet homology gives;
    :mod:`ptztrack.track.templates`). Needs a recording with a video.
    kind : a registered tracker: 'ekf', or the follow camera's 'particle', 'csrt' and 'mil' (:class:`Follow`),
    or another package's. options : the parameters of another package's tracker, passed to its factory
    unread (ptztrack's own trackers take none).
    detector_every_steps : with ``measurement_source`` 'spatiogram', the detector runs at the steps that are
    multiples of this (0, n, 2n, ...) and the spatiograms measure the tracks in between; unused with 'detector'.
    existence_at_birth, existence_when_detected, existence_to_delete : the track lifecycle, by the
    probability that a track's person exists (:mod:`ptztrack.track.tracker`); existence_update 'bayes'
    weighs each detection against the clutter (the learned rate where the detector model learns,
    else ``clutter_density_per_px2``) and reports tracks of existence ``existence_to_report`` or more;
    'fixed' sets it to ``existence_when_detected`` at every detection and reports every track.
    max_position_sigma_m : where people can leave the scene (a recording, or ``people.enter_leave``),
    a track this uncertain is deleted; where they never leave, uncertainty deletes nobody.
    report_position_sigma_m : a track more uncertain than this is kept but not reported.
    velocity_time_constant_s : how fast a track's velocity is predicted to decay (s); .inf: constant velocity.
    noise_dof : the feet pixels' noise's degrees of freedom: .inf for Gaussian noise, a few for Student-t noise,
    whose far detections update less (the Hungarian association only).
    negative_information, keep_within_area, association_cost, lost_tracks_kept : what a miss and the
    walkable area say of a track's position, the association's cost, and the deleted tracks kept to be
    taken back (:class:`~ptztrack.track.parameters.TrackerParameters`).
    """

    kind: Annotated[str, _registered("trackers")] = "ekf"
    options: Options = Field(default_factory=dict)
    acceleration_sigma_m_s2: Annotated[PositiveFloat, at_most(100, "metres per second squared")] = (
        TrackerParameters.acceleration_sigma_m_s2
    )
    velocity_time_constant_s: float = Field(TrackerParameters.velocity_time_constant_s, gt=0, allow_inf_nan=True)
    initial_speed_sigma_m_s: Annotated[PositiveFloat, at_most(100, "metres per second")] = (
        TrackerParameters.initial_speed_sigma_m_s
    )
    gate_probability: float = Field(TrackerParameters.gate_probability, gt=0, lt=1)
    existence_at_birth: float = Field(TrackerParameters.existence_at_birth, gt=0, lt=1)
    existence_when_detected: float = Field(TrackerParameters.existence_when_detected, gt=0, lt=1)
    existence_to_delete: float = Field(TrackerParameters.existence_to_delete, gt=0, lt=1)
    max_position_sigma_m: Annotated[PositiveFloat, at_most(10_000, "metres")] = TrackerParameters.max_position_sigma_m
    confirmation_hits: Annotated[int, Field(ge=1), at_most(_MAX_FRAMES, "steps")] = TrackerParameters.confirmation_hits
    report_position_sigma_m: Annotated[PositiveFloat, at_most(10_000, "metres")] = (
        TrackerParameters.report_position_sigma_m
    )
    existence_update: Literal["bayes", "fixed"] = TrackerParameters.existence_update
    existence_to_report: float = Field(TrackerParameters.existence_to_report, gt=0, lt=1)
    association: Literal["hungarian", "cjpdaf"] = TrackerParameters.association
    clutter_density_per_px2: Annotated[NonNegativeFloat, at_most(1, "detections per pixel")] = (
        TrackerParameters.clutter_density_per_px2
    )
    noise_dof: float = Field(TrackerParameters.noise_dof, gt=2, allow_inf_nan=True)
    negative_information: bool = TrackerParameters.negative_information
    keep_within_area: bool = TrackerParameters.keep_within_area
    association_cost: Literal["mahalanobis", "likelihood"] = TrackerParameters.association_cost
    lost_tracks_kept: Annotated[int, Field(ge=0), at_most(10_000, "tracks")] = TrackerParameters.lost_tracks_kept
    measurement_source: Literal["detector", "spatiogram"] = "detector"
    detector_every_steps: Annotated[int, Field(ge=1), at_most(_MAX_FRAMES, "steps")] = 5

    @model_validator(mode="after")
    def _gaussian_noise_for_cjpdaf(self):
        if self.association == "cjpdaf" and self.noise_dof != float("inf"):
            raise ValueError(f"association cjpdaf assumes Gaussian pixel noise: noise_dof .inf (got {self.noise_dof})")
        return self


class Control(_Strict):
    """Parameters of the information-gain policies (paper sections 4 and 4.4); the defaults are those of
    :class:`~ptztrack.control.parameters.ControlParameters`."""

    samples: Annotated[int, Field(ge=1), at_most(10_000, "time: smpl scores every sample under every action")] = (
        ControlParameters.samples
    )
    beta: Annotated[NonNegativeFloat, at_most(1e6, "a weight")] = ControlParameters.beta
    person_height_m: _Height = ControlParameters.person_height_m
    exploration_cell_m: Annotated[float, Field(ge=0.05), at_most(1000, "metres")] = ControlParameters.exploration_cell_m
    prior_untracked_people: Annotated[NonNegativeFloat, at_most(10_000, "people")] = (
        ControlParameters.prior_untracked_people
    )
    arrival_rate_per_s: Annotated[NonNegativeFloat, at_most(1000, "people per second")] = (
        ControlParameters.arrival_rate_per_s
    )


_VideoFrame = Annotated[int, Field(ge=0), at_most(10_000_000, "video frames: 4 days at 30 Hz")]


class Recording(_Strict):
    """A calibrated recording with ground truth, seen through a virtual PTZ camera (paper section 5.2):
    usually one view of a dataset file (:func:`ptztrack.builders.recording.dataset_scenario` fills this
    section from it).

    With a recording, the camera's position and focal length come from the calibration
    (``camera.image_size_px`` sets the virtual view), and the action grid's pan and tilt are offsets from
    the pose that shows the whole recorded frame. Relative paths in a scenario file are relative to it.
    ground_truth : the recorded view's annotations, a MOTChallenge file with world x, y in metres in columns
    8-9 (frames from 1): the people of the run, whom it is scored against. calibration : the recorded
    view's calibration, a Tsai XML (PETS 2009) or a pinhole JSON (``view`` picks its view).
    video : the recorded video, which the virtual camera's pictures are cut from (None: no pictures; the
    'hog' detector, 'registered' pose feedback and 'spatiogram' measurements need it).
    occluded_above : the fraction of a person's box (0 to 1) hidden by nearer people above which a person
    is occluded: a recording's 'ideal' detector does not report them and the recall fit leaves them out.
    view : the view's key in a pinhole JSON calibration (None: its only view).
    recorded_size_px : the recorded frames' (width, height) (None: read from a Tsai calibration or the video).
    frame_step : the recorded frames between two steps (the scenario's ``frame_rate_hz`` is the step rate).
    frame_range : [first, stop) video frames (0-based) to run on; default all.
    area_m : the walkable area, a polygon of [x, y] points in metres; default the ground the
    recorded view shows (see :func:`ptztrack.builders.world.visible_ground_m`).
    map_grid_px : the virtual camera computes where each pixel reads the recording exactly every
    ``map_grid_px`` pixels and interpolates in between (1: every pixel; see
    :class:`ptztrack.camera.virtual.VirtualPTZ`).
    detections : the view's precomputed boxes (MOTChallenge detections), for ``detector.kind`` 'detections'.
    dataset, dataset_view : the dataset file and its view the recording is (the other views are a camera
    network's fixed cameras); name : the recording in titles (the dataset's name and the view);
    tracking_area_m : the dataset's rectangle [[x0, y0], [x1, y1]] m where its annotations are complete.
    """

    ground_truth: str
    calibration: str
    view: str | None = None
    video: str | None = None
    recorded_size_px: tuple[Pixels, Pixels] | None = None
    frame_step: Annotated[int, Field(ge=1), at_most(_MAX_FRAMES, "video frames")] = 1
    occluded_above: float = Field(0.25, ge=0, le=1)
    frame_range: tuple[_VideoFrame, _VideoFrame] | None = None
    area_m: (
        Annotated[tuple[tuple[_Coordinate, _Coordinate], ...], at_most_items(1000, "corners of a polygon")] | None
    ) = None
    map_grid_px: Annotated[int, Field(ge=1), at_most(64, "pixels between the sampling map's grid points")] = 1
    detections: str | None = None
    dataset: str | None = None
    dataset_view: str | None = None
    tracking_area_m: tuple[tuple[float, float], tuple[float, float]] | None = None
    name: str = "recording"

    @model_validator(mode="after")
    def _range_and_area(self):
        if self.frame_range is not None and self.frame_range[1] <= self.frame_range[0]:
            raise ValueError(f"frame_range must be [first, stop) with first < stop (got {list(self.frame_range)})")
        if self.area_m is not None and len(self.area_m) < 3:
            raise ValueError(f"area_m must be a polygon of at least 3 [x, y] points (got {len(self.area_m)})")
        return self


class MountedCamera(_Strict):
    """One camera of a network (the scenario's ``cameras``): where it is mounted, whether it turns, its
    lens and its detector; every camera of a network is simulated, over the synthetic scene.

    kind : 'ptz' (it chooses its pose on the action grid every step) or 'fixed' (it stays at its widest
    view of the area, as the 'fix' policy does). position_m : its optical centre (x, y, z) in metres.
    The action grid's pan values are offsets from the bearing of the area's centre seen from the camera
    (the default camera, south of the area, faces it at pan 0), its tilts and zooms the scenario's.
    image_size_px, f_min_px : its image and widest focal length (None: the ``camera`` section's).
    detector : its detector (None: the scenario's ``detector``). The ``camera`` section's pose error
    applies to every camera.
    """

    kind: Literal["ptz", "fixed"] = "ptz"
    position_m: tuple[_Coordinate, _Coordinate, Annotated[PositiveFloat, at_most(10_000, "metres")]]
    image_size_px: tuple[Pixels, Pixels] | None = None
    f_min_px: Annotated[PositiveFloat, at_most(1e6, "pixels")] | None = None
    detector: Detector | None = None


_MAX_CAMERAS = 64


_Side = Annotated[PositiveFloat, at_most(1000, "metres: the ground a PTZ camera can cover")]


class Scenario(_Strict):
    """Everything a run needs besides the policy and the seed.

    area_m : (width, depth) metres of the synthetic scene's walkable rectangle [0, width] x [0, depth]
    on the ground's x and y axes (a recording's area is its own, ``recording.area_m``).
    frames : how many steps the run takes (one picture per camera each).
    frame_rate_hz : steps per second of the scenario's clock: a step lasts 1 / frame_rate_hz seconds,
    the time the people's walk and the tracker's motion model advance by.
    people : the synthetic crowd (section ``people``); with a ``recording``, its ``width_m`` applies, and its
    ``height_m`` where a rendered recording leaves a person's height unknown.
    camera : the PTZ camera, its lens and its pose error (section ``camera``). actions : the grid of poses
    the policies choose from every step (section ``actions``). detector : the detector and what the
    policies know of it (section ``detector``). tracker : the tracker and its data association (section
    ``tracker``). control : the information-gain policies' parameters (section ``control``).
    pose_feedback : which pose the tracker maps detections with (section ``pose_feedback``).
    follow : the follow camera's person, motion limits and particle filter (section ``follow``).
    recording : the recorded view the virtual PTZ camera looks at (section ``recording``; None: the
    synthetic scene).
    cameras : a network of cameras over the synthetic scene, each mounted, detecting and deciding every
    step, all updating one belief (section ``cameras``); empty: the one camera of ``camera``.
    """

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
    cameras: Annotated[
        tuple[MountedCamera, ...],
        at_most_items(_MAX_CAMERAS, "time: every camera detects, updates the belief and decides every step"),
    ] = ()

    @model_validator(mode="after")
    def _a_network_of_simulated_cameras(self):
        if not self.cameras:
            return self
        if self.recording is not None:
            raise ValueError("cameras: a network of cameras runs on the synthetic scene, not on a recording (yet)")
        if self.tracker.kind != "ekf" or self.tracker.measurement_source != "detector":
            raise ValueError(
                "cameras: a network's one belief is the 'ekf' tracker measured by the detector "
                f"(got tracker.kind {self.tracker.kind!r}, measurement_source {self.tracker.measurement_source!r})"
            )
        if self.camera.backend not in (None, "simulated"):
            raise ValueError(f"cameras: a network's cameras are simulated (got camera.backend {self.camera.backend!r})")
        return self

    @model_validator(mode="after")
    def _one_source_of_people(self):
        if self.recording is not None and self.people.trajectories is not None:
            raise ValueError(
                "people.trajectories replays a file as the synthetic scene's crowd; a recording's people are "
                f"its recording.ground_truth (got both, people.trajectories {self.people.trajectories!r})"
            )
        return self

    @model_validator(mode="after")
    def _images_need_a_video(self):
        has_video = self.recording is not None and self.recording.video is not None
        if self.detector.kind == "hog" and not has_video:
            raise ValueError("detector.kind 'hog' needs a recording with a video (recording.video)")
        if self.pose_feedback.source == "registered" and not has_video:
            raise ValueError("pose_feedback.source 'registered' needs a recording with a video (recording.video)")
        if self.detector.kind == "detections" and (self.recording is None or self.recording.detections is None):
            raise ValueError(
                "detector.kind 'detections' needs the recorded view's boxes (recording.detections; a dataset "
                "view's detections)"
            )
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


FILE_KINDS["scenario"] = Scenario


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


def load_scenario(path: str | Path, **overrides) -> Scenario:
    """Read and validate a YAML scenario file (docs: scenario files, for the format)."""
    path = Path(path)
    data = read_yaml(path, "scenario", ScenarioError)
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise ScenarioError(f"{path}: expected a mapping of scenario fields (got {type(data).__name__})")
    refuse_another_kind(path, data, "scenario")
    recording = data.get("recording")
    if isinstance(recording, dict):
        data = {**data, "recording": {**recording, **_resolved_paths(recording, path.parent)}}
    people = data.get("people")
    if isinstance(people, dict) and isinstance(people.get("trajectories"), str):
        data = {**data, "people": {**people, "trajectories": str(path.parent / people["trajectories"])}}
    return scenario_from_dict(data, str(path), **overrides)


def _resolved_paths(recording: dict, base: Path) -> dict:
    return {
        key: str(base / value)
        for key, value in recording.items()
        if key in ("ground_truth", "calibration", "video", "detections", "dataset") and isinstance(value, str)
    }
