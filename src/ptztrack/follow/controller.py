"""The follow controller (Nair et al., IROS 2008, section III-D): keep one person at a chosen image point and size.

The robot cameraman keeps "the error vector as small as possible while, at
the same time, avoiding jittering and abrupt accelerations": the image error
``e_f = [x - x*, y - y*]`` (equation 7) drives the camera, the depth error
(equation 8) the zoom, and ``(x*, y*)`` need not be the image centre. Here
the camera turns instead of translating, so the controller works in pose
space, which makes both errors one: each step it computes the *framing
pose*, the pan and tilt that show the person's middle at ``(x*, y*)``
(:func:`ptztrack.geometry.ptz.aim_at`) at the zoom that makes them
``target_height_px`` tall, and moves the commanded pose towards it.

Distance. The paper measured the moderator's distance with a second,
overhead camera; PETS has one video, so the distance comes from the
ground-plane calibration: the track is a point on the ground (the person's
feet on the ground plane), and the zoom is the one at which a person
``person_height_m`` tall standing there is ``target_height_px`` tall in the
framing view. The zoom is also capped, at the current pan and tilt, so
that the person's whole box stays in the image: zooming in on a person who
is not yet at ``(x*, y*)`` would push them out of view.

Motion. Pan, tilt and the logarithm of the zoom each follow their framing
value by a pursuit law with a feed-forward of the framing pose's own rate
(from the track's velocity):

    v_wanted = rate + error / time_constant,   |v_wanted| <= max_speed,
    v = v_previous + clip(v_wanted - v_previous, +-max_acceleration * step),
    pose = previous pose + v * step,

where ``error = framing - previous pose - rate * step``: a camera that was
at the previous step's framing is on the person with ``v = rate``, so a
walker is followed without lag.

so the commanded velocity changes by at most ``max_acceleration`` per
second: the second difference of the commanded angles (the jitter) is at
most ``max_acceleration * step^2``. With ``time_constant = max_speed / (2
max_acceleration)`` a camera at full speed starts braking early enough not
to overshoot. While the track is lost (existence 0) the tracker
holds its last position with no velocity, so the camera settles on it and
waits.
"""

from dataclasses import dataclass, field

import numpy as np

from ptztrack.follow.parameters import FollowParameters
from ptztrack.geometry.ptz import PAN, TILT, ZOOM, PTZCamera, aim_at, project_people
from ptztrack.types import DecisionContext

# Fixed-point iterations between the framing pose's pan and tilt and its zoom (they depend on each
# other unless (x*, y*) is the image centre): for (x*, y*) = (100, 400) px in 640 x 480 and a person
# 20 m away, three leave 0.0015 deg and 0.03 px of height to go.
FRAMING_ITERATIONS = 3


@dataclass(frozen=True)
class FramingParameters:
    """The controller's parameters: the follow camera's (its target height, motion limits and zoom range)
    and what the camera and the run fix.

    follow : the follow camera's parameters (:class:`~ptztrack.follow.parameters.FollowParameters`).
    target_point_px : (2,) (x*, y*) where the person's middle should be (``follow.target_point_px``, or
    the image centre where that is None).
    person_height_m, person_width_m : the person assumed (their middle is at half the height).
    step_s : seconds per step.
    """

    follow: FollowParameters
    target_point_px: np.ndarray
    person_height_m: float
    person_width_m: float
    step_s: float

    @property
    def max_speed(self) -> np.ndarray:
        """(3,) pan deg/s, tilt deg/s, log zoom per s."""
        follow = self.follow
        return np.array([follow.max_speed_deg_s, follow.max_speed_deg_s, follow.max_zoom_speed])

    @property
    def max_acceleration(self) -> np.ndarray:
        """(3,) pan deg/s^2, tilt deg/s^2, log zoom per s^2."""
        follow = self.follow
        return np.array([follow.max_acceleration_deg_s2, follow.max_acceleration_deg_s2, follow.max_zoom_acceleration])


def framing_pose(camera: PTZCamera, position_m, current_pose, parameters: FramingParameters) -> np.ndarray:
    """The pose (3,) that shows a person standing at ``position_m`` (2,) at (x*, y*), target_height_px tall.

    The zoom is within ``zoom_range`` and no more than keeps the person's whole box in the image at
    the current pan and tilt (``current_pose`` (3,)).
    """
    middle_m = np.r_[position_m, parameters.person_height_m / 2]
    in_view_zoom = _zoom_keeping_in_view(camera, current_pose, position_m, parameters)
    zoom = float(current_pose[ZOOM])
    for _ in range(FRAMING_ITERATIONS):
        pose = aim_at(camera, middle_m, parameters.target_point_px, zoom)
        wanted = parameters.follow.target_height_px / _height_at_zoom_1(camera, pose, position_m, parameters)
        zoom = float(np.clip(min(wanted, in_view_zoom), *parameters.follow.zoom_range))
    return aim_at(camera, middle_m, parameters.target_point_px, zoom)


def _height_at_zoom_1(camera: PTZCamera, pose, position_m, parameters: FramingParameters) -> float:
    """The person's height in pixels at ``pose``'s pan and tilt and zoom 1 (pixel sizes scale with the zoom)."""
    people = project_people(
        camera,
        np.r_[pose[:ZOOM], 1.0],
        np.asarray(position_m)[None],
        parameters.person_height_m,
        parameters.person_width_m,
    )
    return float(people.height_px[0])


def _zoom_keeping_in_view(camera: PTZCamera, pose, position_m, parameters: FramingParameters) -> float:
    """The highest zoom at ``pose``'s pan and tilt at which the person's box lies inside the image."""
    people = project_people(
        camera, pose, np.asarray(position_m)[None], parameters.person_height_m, parameters.person_width_m
    )
    if not people.in_front[0]:
        return parameters.follow.zoom_range[0]
    corners = people.box_px[0].reshape(2, 2)  # (left, top), (right, bottom)
    # Zooming about the principal point scales every offset from it by the zoom ratio.
    offset = np.abs(corners - camera.principal_point_px).max(axis=0)
    half_size = camera.principal_point_px
    return float(pose[ZOOM] * np.min(half_size / np.maximum(offset, 1e-9)))


@dataclass
class FollowPolicy:
    """Follows the first track of ``context.tracks`` with a continuously commanded pose (a
    :class:`ptztrack.roles.Policy`); holds still while there is none."""

    camera: PTZCamera
    parameters: FramingParameters
    velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def choose(self, context: DecisionContext) -> np.ndarray:
        current = np.asarray(context.current_pose, dtype=float)
        p = self.parameters
        if len(context.tracks) == 0:
            wanted_speed = np.zeros(3)
        else:
            mean = context.tracks.mean[0]
            here = framing_pose(self.camera, mean[:2], current, p)
            ahead = framing_pose(self.camera, mean[:2] + p.step_s * mean[2:], current, p)
            rate = _pose_difference(ahead, here) / p.step_s
            # The camera should now be where the framing was a step ago: this step's move is the rate.
            error = _pose_difference(here, current) - rate * p.step_s
            wanted_speed = rate + error / (p.max_speed / (2 * p.max_acceleration))
        wanted_speed = np.clip(wanted_speed, -p.max_speed, p.max_speed)
        change = np.clip(wanted_speed - self.velocity, -p.max_acceleration * p.step_s, p.max_acceleration * p.step_s)
        self.velocity = self.velocity + change
        pan_deg, tilt_deg = current[:ZOOM] + self.velocity[:ZOOM] * p.step_s
        log_zoom = np.log(current[ZOOM]) + self.velocity[ZOOM] * p.step_s
        held = float(np.clip(log_zoom, *np.log(p.follow.zoom_range)))
        if held != log_zoom:  # at a zoom limit the zoom stops
            self.velocity[ZOOM] = (held - np.log(current[ZOOM])) / p.step_s
        return np.array([(pan_deg + 180.0) % 360.0 - 180.0, tilt_deg, np.exp(held)])


def _pose_difference(a, b) -> np.ndarray:
    """``a - b`` (3,) for poses: pan wrapped to [-180, 180) deg, tilt in deg, zoom as a log ratio."""
    pan = (a[PAN] - b[PAN] + 180.0) % 360.0 - 180.0
    return np.array([pan, a[TILT] - b[TILT], np.log(a[ZOOM] / b[ZOOM])])
