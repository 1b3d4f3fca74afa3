"""A live camera that reports no positions, placed by its own pictures: the sweep that builds its
reference index at the start, the registration of its pictures against it, and the moves that take it
from a registered pose to a target without AbsoluteMove.

The sweep starts from a view whose world pose is known (:class:`KnownView`: the calibration's ground
view, a preset at the widest zoom, or an AbsoluteMove where the camera has positions), then turns the
camera by RelativeMoves over a grid of poses covering the action grid (:func:`sweep_poses`) and takes a
picture where it stands still at each, its rough pose the planned one. The views are bundle-adjusted
with the known one first and exact (:func:`ptztrack.geometry.registration.build_index`).

A move from ``current`` to ``target`` (3,) poses is a RelativeMove by
``spaces.normalised(target) - spaces.normalised(current)`` (the generic translation spaces: pan and
tilt linear in the calibration's degrees, zoom through its zoom curve); a node without RelativeMove gets
a ContinuousMove of every axis for the time the move-time model gives at full speed for the slowest one,
``T = max_a slope_a |target_a - current_a|``, each axis at velocity
``sign(n_a) slope_a |target_a - current_a| / T`` (``n`` the normalised translation), so that all end
together, its Timeout ``T``; and a Stop just after the model lands it (``max_a intercept_a + T``).
"""

import logging
import time
from dataclasses import dataclass, replace

import cv2
import numpy as np

from ptztrack.camera.onvif_client import CameraError, ONVIFClient
from ptztrack.camera.onvif_spaces import CameraSpaces, MoveTimes
from ptztrack.camera.stream import Frame, LatestFrame, thumbnail
from ptztrack.geometry.ptz import PTZCamera
from ptztrack.geometry.registration import ReferenceIndex, build_index, register

log = logging.getLogger("ptztrack.loop.live")

# The sweep's zooms from the action grid's widest to its longest, each at most this factor from the one
# before: at a 160 x 120 stream a view 2x as zoomed shares too few features with the one before it to be
# tied to it, one sqrt(2)x as zoomed does (docs/decisions/0067-reference-sweep-grid.md).
SWEEP_ZOOM_RATIO = 2.0**0.5
# Neighbouring views of the sweep at most this fraction of their field of view apart, in pan and in tilt:
# a pair of views is tied in the index by 30 RANSAC inliers, which a 160 x 120 stream's views share only
# when they overlap by half (docs/decisions/0067-reference-sweep-grid.md).
SWEEP_STEP_FRACTION = 0.5
# A picture shows the camera still once the thumbnails (:func:`ptztrack.camera.stream.thumbnail`) of it
# and the picture before differ by at most this many grey levels on average: a priori, between a still
# stream's compression noise and a turn of a frame's time at a dome's speed.
STILL_GREY = 1.0
# The pictures have changed with a move once their thumbnails differ from the view it left by more than
# this many grey levels on average: a priori, beyond what people walking in a still view change and
# within what a turn by a third of the view or a zoom by sqrt(2) changes.
MOVED_GREY = 10.0
# How long past its landing a picture of the sweep waits for the camera to stand still.
SETTLE_TIMEOUT_S = 3.0
# A ContinuousMove's Stop goes this long after the move-time model lands it: past the end of its
# Timeout, by which a camera that honours it has stopped (a priori: a frame interval at 20 fps).
STOP_MARGIN_S = 0.05
# Pictures are smoothed by a Gaussian of this standard deviation (px, a 3 x 3 kernel) before SIFT, the
# reference views and the live pictures alike: a video stream's compression leaves blocks and ringing at
# the finest scale, where SIFT's keypoints then differ from picture to picture of one view
# (docs/decisions/0067-reference-sweep-grid.md).
SMOOTHING_SIGMA_PX = 0.8
# An index of fewer views than this does not cover the action grid.
MIN_REFERENCE_VIEWS = 4
# A registered pose's standard deviation: pan and tilt in degrees, zoom as a fraction of the zoom; chosen
# from the errors of the PETS views registered at 160 x 120 (docs/decisions/0067-reference-sweep-grid.md).
REGISTERED_SD_DEG = 0.1
REGISTERED_SD_ZOOM_FRACTION = 0.01


@dataclass(frozen=True)
class KnownView:
    """The view a sweep starts from, at world pose ``pose`` (3,): reached by GotoPreset ``preset`` and a
    move to the widest zoom, or (no preset) by AbsoluteMove to ``position`` (3,) in the normalised spaces."""

    pose: np.ndarray
    preset: str | None = None
    position: np.ndarray | None = None


def smoothed(image: np.ndarray) -> np.ndarray:
    """A picture (h, w, 3) smoothed for SIFT (SMOOTHING_SIGMA_PX)."""
    return cv2.GaussianBlur(image, (3, 3), SMOOTHING_SIGMA_PX)


def registered_sd(pose) -> np.ndarray:
    """The standard deviation (3,) of a registered pose (3,): pan, tilt (deg) and zoom factor."""
    return np.array([REGISTERED_SD_DEG, REGISTERED_SD_DEG, REGISTERED_SD_ZOOM_FRACTION * float(pose[2])])


@dataclass(frozen=True)
class PictureRegistration:
    """Pictures registered against a camera's reference ``index`` through ``model`` (at the index's size).

    A registered pose is kept only within the reference views' reach: pan and tilt within their range
    widened by the widest view's field of view, zoom within SWEEP_ZOOM_RATIO of their zooms (a homography
    of a few chance matches can give a rotation half a turn away).
    """

    model: PTZCamera
    index: ReferenceIndex

    def pose(self, image: np.ndarray) -> np.ndarray | None:
        """The pose (3,) of the picture ``image`` (h, w, 3); None where it does not register, or registers
        beyond the reference views' reach, or is not of the index's size."""
        if (image.shape[1], image.shape[0]) != tuple(self.index.image_size_px):
            return None
        try:
            registration = register(self.model, self.index, smoothed(image))
        except ValueError:  # a refinement that starts from a degenerate homography's pose
            return None
        if registration is None:
            return None
        poses, pose = self.index.poses, registration.pose
        low, high = poses.min(axis=0), poses.max(axis=0)
        size_px = np.array([self.model.image_width_px, self.model.image_height_px])
        view_deg = 2.0 * np.rad2deg(np.arctan(size_px / 2.0 / (low[2] * self.model.f_min_px)))
        within = np.all(np.abs(pose[:2] - (low[:2] + high[:2]) / 2) <= (high[:2] - low[:2]) / 2 + view_deg)
        return pose if within and low[2] / SWEEP_ZOOM_RATIO <= pose[2] <= high[2] * SWEEP_ZOOM_RATIO else None


def relative_translation(spaces: CameraSpaces, current, target) -> np.ndarray:
    """The generic translation (3,) from pose ``current`` (3,) to ``target`` (3,), each axis within [-1, 1]."""
    return np.clip(spaces.normalised(target) - spaces.normalised(current), -1.0, 1.0)


def continuous_move(spaces: CameraSpaces, move_times: MoveTimes, current, target) -> tuple[np.ndarray, float]:
    """The velocity (3,) (fractions of full speed) and duration (s) of a ContinuousMove from ``current`` to
    ``target`` (module docstring); a zero velocity and duration where they are the same pose."""
    distance = np.abs(np.asarray(target, dtype=float) - np.asarray(current, dtype=float))
    slopes = np.array([move_times.pan[1], move_times.tilt[1], move_times.zoom[1]])
    if np.any((distance > 0) & ~(slopes > 0)):
        raise CameraError("a ContinuousMove is timed by the calibration's move_times: measure them first")
    at_speed_s = slopes * distance
    duration_s = float(at_speed_s.max())
    if duration_s <= 0:
        return np.zeros(3), 0.0
    direction = np.sign(spaces.normalised(target) - spaces.normalised(current))
    return direction * at_speed_s / duration_s, duration_s


class Mover:
    """Takes a camera from one pose to another (module docstring): by RelativeMove if ``relative``, else
    by ContinuousMove timed by ``move_times``, then Stop."""

    def __init__(self, spaces: CameraSpaces, move_times: MoveTimes, relative: bool):
        self.spaces, self.move_times, self.relative = spaces, move_times, relative

    def move(self, client: ONVIFClient, current, target) -> float | None:
        """Send the move from ``current`` (3,) to ``target`` (3,); the epoch second to send Stop at (a
        ContinuousMove's), None for none."""
        if self.relative:
            client.relative_move(relative_translation(self.spaces, current, target))
            return None
        velocity, duration_s = continuous_move(self.spaces, self.move_times, current, target)
        if duration_s <= 0:
            return None
        sent_s = time.time()
        client.continuous_move(velocity, duration_s)
        intercepts = [self.move_times.pan[0], self.move_times.tilt[0], self.move_times.zoom[0]]
        return sent_s + max(intercepts) + duration_s + STOP_MARGIN_S

    def widest(self, client: ONVIFClient) -> float | None:
        """Zoom out to the widest zoom where the camera looks; the epoch second to send Stop at, or None."""
        if self.relative:
            client.relative_move([0.0, 0.0, -1.0])
            return None
        zooms = [factor for _, factor in self.spaces.zoom_curve]
        duration_s = self.move_times.zoom[1] * (zooms[-1] - zooms[0])
        if not duration_s > 0:
            raise CameraError("a ContinuousMove is timed by the calibration's move_times: measure them first")
        sent_s = time.time()
        client.continuous_move([0.0, 0.0, -1.0], duration_s)
        return sent_s + self.move_times.zoom[0] + duration_s + STOP_MARGIN_S


def stop_at(client: ONVIFClient, stop_s: float | None) -> None:
    """Send Stop at epoch second ``stop_s`` (at once if past), nothing for None."""
    if stop_s is not None:
        time.sleep(max(0.0, stop_s - time.time()))
        client.stop()


def settled_picture(
    latest: LatestFrame, earliest_s: float, unchanged_s: float, moved_from: np.ndarray | None = None
) -> Frame:
    """The first picture that shows the camera still after a move: it and the picture before differ by at
    most STILL_GREY, it was captured at or after epoch ``earliest_s`` (the move-time model's landing), and
    the pictures have changed from ``moved_from`` (the thumbnail of the view the move left) by more than
    MOVED_GREY since, or it was captured at or after ``unchanged_s`` (for a move that may change nothing:
    once any move could have landed). The newest picture SETTLE_TIMEOUT_S past that; a CameraError if the
    stream gives none."""
    number, before, newest = 0, None, None
    changed = moved_from is None
    deadline_s = max(earliest_s, unchanged_s) + SETTLE_TIMEOUT_S
    while True:
        frame = latest.newer(number, max(0.5, deadline_s - time.time()))
        if frame is None:
            if newest is not None:
                return newest
            raise CameraError(f"no picture from the camera's stream for {SETTLE_TIMEOUT_S:g} s")
        number, small = frame.number, thumbnail(frame.image)
        changed = changed or bool(np.mean(np.abs(small - moved_from)) > MOVED_GREY)
        still = before is not None and np.mean(np.abs(small - before)) <= STILL_GREY
        if frame.time_s > deadline_s or (
            still and frame.time_s >= earliest_s and (changed or frame.time_s >= unchanged_s)
        ):
            return frame
        before, newest = small, frame


def sweep_poses(model: PTZCamera, grid_poses, known_pose, ratio: float = SWEEP_ZOOM_RATIO) -> np.ndarray:
    """(L, 3) the sweep's poses after the known view ``known_pose`` (3,): at zooms from the least to the most
    of ``grid_poses`` (G, 3) and the known pose, geometrically spaced at most ``ratio`` apart, a grid over
    their pan and tilt range whose neighbours are at most SWEEP_STEP_FRACTION of that zoom's field of view
    apart, row after row in alternating directions; the known pose left out."""
    grid_poses, known_pose = np.asarray(grid_poses, dtype=float), np.asarray(known_pose, dtype=float)
    low, high = np.minimum(grid_poses.min(axis=0), known_pose), np.maximum(grid_poses.max(axis=0), known_pose)
    count = int(np.ceil(np.log(high[2] / low[2]) / np.log(ratio) - 1e-9)) + 1 if high[2] > low[2] else 1
    poses = []
    for zoom in np.geomspace(low[2], high[2], count):
        focal_px = zoom * model.f_min_px
        view_deg = 2.0 * np.rad2deg(np.arctan(np.array([model.image_width_px, model.image_height_px]) / 2 / focal_px))
        steps = np.ceil((high[:2] - low[:2]) / (SWEEP_STEP_FRACTION * view_deg) - 1e-9).astype(int) + 1
        pans, tilts = np.linspace(low[0], high[0], steps[0]), np.linspace(low[1], high[1], steps[1])
        for row, tilt in enumerate(tilts):
            poses += [[pan, tilt, zoom] for pan in (pans if row % 2 == 0 else pans[::-1])]
    poses_array = np.array(poses)
    return poses_array[np.any(np.abs(poses_array - known_pose) > 1e-9, axis=1)]


def sweep_index(
    client: ONVIFClient,
    latest: LatestFrame,
    model: PTZCamera,
    mover: Mover,
    known: KnownView,
    grid_poses,
) -> PictureRegistration:
    """Build the camera's reference index (module docstring): to the ``known`` view, then over
    :func:`sweep_poses` of ``grid_poses`` (G, 3) with ``mover``, a picture where the camera stands still at
    each (``latest``: its stream's newest picture), bundle-adjusted through ``model`` brought to the
    stream's picture size. One log line per phase with its time; a CameraError of one line if fewer
    than MIN_REFERENCE_VIEWS views are tied to the known one."""
    started_s = time.time()
    move_times, spaces = mover.move_times, mover.spaces
    intercept_s = max(move_times.pan[0], move_times.tilt[0], move_times.zoom[0])
    # The camera may be anywhere: a move to the known view lands at the latest in the model's time across
    # the spaces, a zoom to the widest in its time across the zoom curve.
    ends = spaces.pose(np.array([[-1.0, -1.0, 0.0], [1.0, 1.0, 1.0]]))
    anywhere_s = float(move_times.seconds(ends[0], ends[1]))
    widest_s = float(move_times.seconds(ends[1], [ends[1][0], ends[1][1], ends[0][2]]))

    def arrived(move_s: float) -> Frame:
        """The settled picture of a move just sent that lands within ``move_s``."""
        sent_s, left = time.time(), latest.newer(0, SETTLE_TIMEOUT_S)
        if left is None:
            raise CameraError(f"no picture from the camera's stream for {SETTLE_TIMEOUT_S:g} s")
        return settled_picture(latest, sent_s + intercept_s, sent_s + move_s, thumbnail(left.image))

    if known.preset is not None:
        client.goto_preset(known.preset)
        arrived(anywhere_s)
        stop_at(client, mover.widest(client))
        first = arrived(widest_s)
    elif known.position is not None:
        client.move_to(known.position)
        first = arrived(anywhere_s)
    else:
        raise CameraError("the sweep needs a known view: a ground_view preset, or AbsoluteMove")
    height_px, width_px = first.image.shape[:2]
    model = replace(model, image_width_px=width_px, image_height_px=height_px,
                    f_min_px=model.f_min_px * width_px / model.image_width_px)  # fmt: skip
    log.warning("registered pose: at the known view %s in %.1f s", np.round(known.pose, 2), time.time() - started_s)
    phase_s = time.time()
    planned = sweep_poses(model, grid_poses, known.pose)
    images, here = [first.image], np.asarray(known.pose, dtype=float)
    for pose in planned:
        sent_s = time.time()
        stop_at(client, mover.move(client, here, pose))
        landed_s = sent_s + float(move_times.seconds(here, pose))
        images.append(settled_picture(latest, landed_s, landed_s + SETTLE_TIMEOUT_S, thumbnail(images[-1])).image)
        here = pose
    # Back to the known view: the loop starts where the ground is seen, not at the sweep's last corner,
    # which may look beyond anything that registers. By its preset or position, not by a relative move: a
    # relative move sent before the last one ended counts from where the head was, and the sweep's slips
    # add up.
    if known.preset is not None:
        client.goto_preset(known.preset)
    else:
        client.move_to(known.position)
    arrived(anywhere_s)
    log.warning("registered pose: %d views swept in %.1f s", len(images), time.time() - phase_s)
    phase_s = time.time()
    poses = np.vstack([known.pose, planned])
    try:
        index = build_index(model, [smoothed(image) for image in images], poses)
    except ValueError:  # no pair of views matched: bundle adjustment has nothing to adjust
        index = None
    kept = 0 if index is None else len(index.poses)
    if index is None or kept < MIN_REFERENCE_VIEWS:
        raise CameraError(
            f"only {kept} of the sweep's {len(images)} views register to the known view (at least "
            f"{MIN_REFERENCE_VIEWS} needed): the camera's pictures cannot place it"
        )
    log.warning(
        "registered pose: reference index of %d of %d views in %.1f s", kept, len(images), time.time() - phase_s
    )
    return PictureRegistration(model, index)
