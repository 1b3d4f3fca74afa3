"""One person followed in the image, reported as one ground-plane track: the follow camera's tracker.

A *target source* follows the person's box from view to view: the
robot-cameraman paper's particle filter (:mod:`ptztrack.follow.particle_filter`)
or an OpenCV tracker (CSRT, MIL) as the comparator. :class:`TargetTracker`
wraps either into a :class:`ptztrack.roles.Tracker`: it asks for no
detections, reads the view, gives the source the homography from the
previous pose to the current one, and reports the box as one track on the
ground, so that the project's metrics and pictures apply unchanged.

Ground position. The box's centre is better found than its bottom edge:
colour and motion pin down where a person is sooner than how tall the box
around them is, and a box whose height is 20 % off moves its feet by 10 %
of the person's height. So the track's position is where the ray through
the box centre meets the plane ``person_height_m / 2`` above the ground (the
middle of a standing person), which is the point under the person's middle
on the ground; a controller that projects that middle back into the view
finds the box centre again. Its covariance is the source's pixel covariance
of the centre carried through that mapping's Jacobian.

Output filter (section III-C6): "filtering the tracking output by a further
temporal low-pass filter". A critically damped alpha-beta filter on the
ground position (both poles at ``smoothing``; alpha = 1 - smoothing^2, beta
= (1 - smoothing)^2): a second-order low-pass that follows a walker's
constant velocity without lag, and whose velocity the controller uses to
lead the person. While the source is lost the track holds its last position
with no velocity (the paper's robot "does not drift but simply keeps the
last estimated position"), with existence 0 (the tracker does not see the
person) and the steps counted in the tracker's ``missed_steps``; when the
source finds the person again the filter starts afresh from the new
position.
"""

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Protocol

import cv2
import numpy as np

from ptztrack.follow.particle_filter import (
    ParticleFilter,
    ParticleFilterParameters,
    StandingHeight,
    start_filter,
    step_filter,
)
from ptztrack.geometry.ptz import (
    PTZCamera,
    apply_homography,
    homography_jacobian,
    plane_homography,
    pose_noise_px2,
    rotation_homography,
    standing_height_px,
)
from ptztrack.roles import ImageSource
from ptztrack.types import Detections, Tracks, TrackUpdate

TRACK_ID = 0
# The uncertainty of a box centre given without one (the initial box, an OpenCV tracker's box), as a
# fraction of the box height per axis; set a priori, it only sizes the reported covariance (nothing
# that steers the camera or scores a run reads it).
BOX_CENTRE_SPREAD = 0.1


@dataclass(frozen=True)
class TargetEstimate:
    """Where a source puts the person in the current view.

    box_px : (4,) (left, top, width, height); lost : the source has lost the person (the box is
    then its last one); centre_covariance_px2 : (2, 2), the uncertainty of the box centre.
    """

    box_px: np.ndarray
    lost: bool
    centre_covariance_px2: np.ndarray


class TargetSource(Protocol):
    """Follows one person's box from view to view."""

    def start(self, image_bgr: np.ndarray, box_px: np.ndarray) -> TargetEstimate:
        """Begin on the person in ``box_px`` (left, top, width, height) of the first view (h, w, 3) uint8 BGR."""
        ...

    def step(self, image_bgr: np.ndarray, homography: np.ndarray, standing_height_px: StandingHeight) -> TargetEstimate:
        """The person in the next view, into which the previous view maps by ``homography`` (3, 3);
        ``standing_height_px`` is the view's calibration (the height of a person standing on given feet
        pixels), for a source that uses it."""
        ...


def box_corners_carried(box_px, homography) -> np.ndarray:
    """The bounding box (4,) of a box (left, top, width, height) whose corners are carried by ``homography``."""
    left, top, width, height = np.asarray(box_px, dtype=float)
    corners = np.array([[left, top], [left + width, top], [left, top + height], [left + width, top + height]])
    carried = apply_homography(homography, corners)
    low, high = carried.min(axis=0), carried.max(axis=0)
    return np.r_[low, high - low]


@dataclass
class ParticleSource:
    """The robot-cameraman paper's particle filter as a target source; ``rng`` draws every particle."""

    parameters: ParticleFilterParameters
    rng: np.random.Generator
    filter: ParticleFilter | None = None

    def start(self, image_bgr, box_px) -> TargetEstimate:
        self.filter = start_filter(image_bgr, box_px, self.parameters)
        return self._estimate()

    def step(self, image_bgr, homography, standing_height_px: StandingHeight) -> TargetEstimate:
        if self.filter is None:
            raise RuntimeError("the particle filter steps before it started")
        self.filter = step_filter(self.filter, image_bgr, homography, self.parameters, self.rng, standing_height_px)
        return self._estimate()

    def _estimate(self) -> TargetEstimate:
        assert self.filter is not None
        return TargetEstimate(self.filter.box_px(), self.filter.lost, self.filter.centre_covariance_px2())


@dataclass
class OpenCVSource:
    """An OpenCV tracker (``create``: ``cv2.TrackerCSRT.create``, say) as a target source.

    It sees every view as it comes: OpenCV's trackers cannot be told that the camera moved, except by
    starting them again, which the one-pass protocol forbids. While it reports failure the box is its
    last good one. The box centre's uncertainty is ``spread`` of the box height per axis (a tracker
    gives none of its own). CSRT gives the same boxes on the same frames every time; MIL does not,
    even after ``cv2.setRNGSeed`` and on one thread.
    """

    create: Callable[[], cv2.Tracker]
    spread: float = BOX_CENTRE_SPREAD
    tracker: cv2.Tracker | None = None
    box_px: np.ndarray = field(default_factory=lambda: np.zeros(4))

    def start(self, image_bgr, box_px) -> TargetEstimate:
        self.tracker = self.create()
        self.box_px = np.asarray(box_px, dtype=float)
        left, top, width, height = (int(round(value)) for value in self.box_px)
        self.tracker.init(image_bgr, (left, top, width, height))
        return self._estimate(lost=False)

    def step(self, image_bgr, homography, standing_height_px: StandingHeight) -> TargetEstimate:
        """The tracker's box in the next view; OpenCV's trackers take neither the homography nor the
        calibration."""
        if self.tracker is None:
            raise RuntimeError("the OpenCV tracker steps before it started")
        found, box = self.tracker.update(image_bgr)
        if found:
            self.box_px = np.asarray(box, dtype=float)
        return self._estimate(lost=not found)

    def _estimate(self, lost: bool) -> TargetEstimate:
        return TargetEstimate(self.box_px, lost, (self.spread * self.box_px[3]) ** 2 * np.eye(2))


def opencv_tracker_factory(name: str) -> Callable[[], cv2.Tracker]:
    """The OpenCV tracker constructor of a name: 'csrt' or 'mil' (CSRT needs opencv-contrib)."""
    creators: dict[str, Callable[[], cv2.Tracker]] = {"csrt": cv2.TrackerCSRT.create, "mil": cv2.TrackerMIL.create}
    return creators[name]


@dataclass
class TargetTracker:
    """One person followed by a target source, reported as one ground track (a :class:`ptztrack.roles.Tracker`).

    camera : the PTZ camera model; source : the target source.
    initial_box_px : (4,) the person's box (left, top, width, height) in the view at ``initial_pose``
        (3,), the pose the camera was at before the first step.
    person_height_m : the height assumed for everybody (the track is under the person's middle).
    smoothing : the alpha-beta output filter's pole, in (0, 1) (0: no smoothing).
    step_s : seconds per step; dt_s : the time the last prediction stepped (``step_s`` unless it was given one).
    """

    camera: PTZCamera
    source: TargetSource
    initial_box_px: np.ndarray
    initial_pose: np.ndarray
    person_height_m: float
    smoothing: float
    step_s: float
    pose: np.ndarray | None = None
    track: Tracks | None = None
    missed_steps: int = 0
    dt_s: float = field(init=False)

    def __post_init__(self):
        self.dt_s = self.step_s

    def predict(self, dt_s: float | None = None) -> Tracks:
        """The track predicted to this step (``dt_s``, by default ``step_s``, of its velocity on), or the
        initial box's before the first; the next update's filter steps by the same time."""
        self.dt_s = self.step_s if dt_s is None else dt_s
        if self.track is None:
            box = np.asarray(self.initial_box_px, dtype=float)
            centre = box[:2] + box[2:] / 2
            spread_px2 = (BOX_CENTRE_SPREAD * box[3]) ** 2 * np.eye(2)
            position, covariance = self._ground(centre, spread_px2, self.initial_pose)
            return self._tracks(position, np.zeros(2), covariance, missed_steps=0, hits=0)
        mean = self.track.mean[0]
        return replace(self.track, mean=np.r_[mean[:2] + self.dt_s * mean[2:], mean[2:]][None])

    def wants_detections(self, step: int) -> bool:
        return False

    def update(self, detections: Detections | None, pose, view: ImageSource, pose_sd=None) -> TrackUpdate:
        """Step the target source on the view; pose_sd (3,) widens its box centre's noise by the pixel
        noise of a pose known only so well (:func:`~ptztrack.geometry.ptz.pose_noise_px2`)."""
        image = view()
        if image is None:
            raise RuntimeError("the follow camera's tracker needs a camera backend that renders images")
        pose = np.asarray(pose, dtype=float)
        if self.pose is None:
            carried = box_corners_carried(
                self.initial_box_px, rotation_homography(self.camera, self.initial_pose, pose)
            )
            estimate = self.source.start(image, carried)
        else:
            standing = partial(standing_height_px, self.camera, pose, self.person_height_m)
            estimate = self.source.step(image, rotation_homography(self.camera, self.pose, pose), standing)
        self.pose = pose
        box = np.asarray(estimate.box_px, dtype=float)
        centre_covariance_px2 = estimate.centre_covariance_px2
        if pose_sd is not None:
            centre_covariance_px2 = centre_covariance_px2 + pose_noise_px2(self.camera, pose, pose_sd)
        position, covariance = self._ground(box[:2] + box[2:] / 2, centre_covariance_px2, pose)
        self.track = self._filtered(position, covariance, estimate.lost)
        feet_px = np.array([[box[0] + box[2] / 2, box[1] + box[3]]])
        measured = Detections(feet_px, np.array([box[3]]), np.array([-1]))
        updated = np.array([], dtype=int) if estimate.lost else np.array([TRACK_ID])
        return TrackUpdate(self.track, updated, np.zeros(len(updated), dtype=int), measured)

    def reported(self) -> Tracks:
        return self.track if self.track is not None else Tracks.empty()

    def _ground(self, centre_px, covariance_px2, pose) -> tuple[np.ndarray, np.ndarray]:
        """The ground point (2,) under the person whose box centre is ``centre_px``, and its covariance (2, 2)."""
        to_ground = np.linalg.inv(plane_homography(self.camera, pose, self.person_height_m / 2))
        centre_px = np.asarray(centre_px, dtype=float)[None]
        J = homography_jacobian(to_ground, centre_px)[0]
        return apply_homography(to_ground, centre_px)[0], J @ covariance_px2 @ J.T

    def _filtered(self, position, covariance, lost: bool) -> Tracks:
        """The track after a step: the alpha-beta filter on ``position``, or held while ``lost``."""
        previous = self.track
        hits = 0 if previous is None else int(previous.hits[0])
        was_lost = self.missed_steps > 0
        self.missed_steps = self.missed_steps + 1 if lost and previous is not None else 0
        if previous is None or was_lost and not lost:
            return self._tracks(position, np.zeros(2), covariance, missed_steps=0, hits=hits + 1)
        mean = previous.mean[0]
        if lost:
            return self._tracks(mean[:2], np.zeros(2), previous.covariance[0, :2, :2], self.missed_steps, hits)
        predicted = mean[:2] + self.dt_s * mean[2:]
        residual = position - predicted
        alpha, beta = 1 - self.smoothing**2, (1 - self.smoothing) ** 2
        velocity = mean[2:] + beta / self.dt_s * residual
        return self._tracks(predicted + alpha * residual, velocity, covariance, missed_steps=0, hits=hits + 1)

    def _tracks(self, position, velocity, covariance, missed_steps: int, hits: int) -> Tracks:
        # The filter's velocity is a difference of positions over about its time constant.
        time_constant_s = self.step_s / max(1 - self.smoothing, 1e-9)
        full = np.zeros((4, 4))
        full[:2, :2] = covariance
        full[2:, 2:] = covariance / time_constant_s**2
        return Tracks(
            np.array([TRACK_ID]),
            np.r_[position, velocity][None],
            full[None],
            np.array([1.0 if missed_steps == 0 else 0.0]),
            np.array([hits]),
            next_id=TRACK_ID + 1,
        )
