"""The episode video: per step, what the camera saw beside a map of the ground plane.

As in the paper's Figures 1b and 4. Left, the camera's view at the step's
pose, upscaled, with the step's detections (white: feet point, and a box
where the detector gave a height) and each track's id and 2-sigma position
ellipse carried into the image through the pose's ground-to-image Jacobian.
Right, the ground plane seen from above (x to the right, y up, a 5 m grid):
the true positions (grey), the tracks (coloured by id, 2-sigma ellipses),
the camera's field of view on the ground (blue) and the area where people
can be (black frame). Below, a caption: step, pose, label, legend.

The view comes from a caller's ``render_view(step, pose)``;
:func:`view_renderer` builds it for a :class:`~ptztrack.loop.steps.World`: the
camera backend's image (the recorded frame seen by the virtual camera, say),
or where the backend renders none, the camera model's picture of the true
people. A run longer than ``VIDEO_MAX_STEPS`` steps has a video of its last ``VIDEO_MAX_STEPS`` (each
caption gives its step): its whole run is in the folder's tables, and drawing every step of an hour's
run would take longer than the run's last minutes are worth. Everything is drawn with OpenCV
and encoded by OpenCV's MPEG-4 Part 2 writer ('mp4v'; its H.264 encoder is
not in the pip wheels).
"""

import functools
import os
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from ptztrack.files import open_temporary_beside
from ptztrack.geometry.ptz import PTZCamera, feet_jacobian, ground_footprint, project_people
from ptztrack.loop.steps import Episode, World
from ptztrack.track.observation import predicted_feet_px
from ptztrack.types import Detections, GroundTruth, Tracks

RenderView = Callable[[int, np.ndarray], np.ndarray]
"""``render_view(step, pose) -> (h, w, 3) uint8 BGR``: the camera's image at a step and a (pan_deg, tilt_deg, zoom)."""

PANEL_SIZE_PX = (640, 480)  # (width, height) of the view and of the map
CAPTION_HEIGHT_PX = 48  # two lines of text
VIDEO_MAX_STEPS = 3000
FRAME_SIZE_PX = (2 * PANEL_SIZE_PX[0], PANEL_SIZE_PX[1] + CAPTION_HEIGHT_PX)
SIGMAS = 2.0  # ellipses at 2 standard deviations hold 86 % of a 2-D Gaussian
GRID_STEP_M = 5.0
GRID_BGR, GRID_LABEL_BGR = (225, 225, 225), (130, 130, 130)
GRID_LABEL_ROOM_PX = 25  # a grid label needs this far from the panel's edges
MAP_MARGIN_M = 2.0

# Track colours by id: matplotlib's tab10 in BGR without its grey, which is the truth's colour.
TRACK_COLOURS_BGR = (
    (180, 119, 31), (14, 127, 255), (44, 160, 44), (40, 39, 214), (189, 103, 148),
    (75, 86, 140), (194, 119, 227), (34, 189, 188), (207, 190, 23),
)  # fmt: skip
WHITE, BLACK = (255, 255, 255), (0, 0, 0)
TRUTH_BGR = (150, 150, 150)
FOOTPRINT_BGR = (200, 120, 40)
FOOTPRINT_OPACITY = 0.2
# The synthetic view: people as boxes on a plain background (also the view of a recording without video).
MODEL_BACKGROUND_BGR, MODEL_PERSON_BGR, MODEL_EDGE_BGR = (170, 170, 170), (105, 105, 105), (60, 60, 60)
# Detections carry feet and height only; boxes are drawn as wide as a PETS
# annotation box is for its height (median width / height 0.355).
DETECTION_WIDTH_PER_HEIGHT = 0.35
# cv2 draws with int32 coordinates; a point near the horizon maps arbitrarily far.
MAX_DRAWN_PX = 100_000


def ellipse_axes(covariance, sigmas: float = SIGMAS) -> tuple[np.ndarray, np.ndarray]:
    """Half-axes and direction of the ``sigmas`` ellipses of 2-D covariances.

    covariance : (..., 2, 2) in some unit squared. Returns half_axes (..., 2),
    major then minor, in that unit, and angle_deg (...), the major axis's
    direction from the first coordinate axis towards the second (in an
    image, clockwise from +u, as cv2.ellipse takes it).
    """
    eigenvalues, eigenvectors = np.linalg.eigh(covariance)  # ascending
    half_axes = sigmas * np.sqrt(np.clip(eigenvalues[..., ::-1], 0.0, None))
    major = eigenvectors[..., :, 1]
    return half_axes, np.rad2deg(np.arctan2(major[..., 1], major[..., 0]))


def image_ellipses(camera: PTZCamera, pose, position_m, covariance_m2, sigmas: float = SIGMAS):
    """Ground position ellipses carried into the image at ``pose`` (linearised: J Sigma J^T).

    position_m : (n, 2) ground points; covariance_m2 : (n, 2, 2) their covariances.
    Returns centre_px (n, 2), in_front (n,) bool, half_axes_px (n, 2) major
    then minor, angle_deg (n,) clockwise from +u.
    """
    position_m = np.asarray(position_m, dtype=float)
    centre_px, in_front = predicted_feet_px(camera, pose, position_m)  # it reads a state's position only
    J = feet_jacobian(camera, pose, position_m)
    half_axes_px, angle_deg = ellipse_axes(J @ covariance_m2 @ np.swapaxes(J, -1, -2), sigmas)
    return centre_px, in_front, half_axes_px, angle_deg


@dataclass(frozen=True)
class MapTransform:
    """Ground metres to map pixels, y up: (u, v) = J ((x, y) - centre_m) + centre_px with J = diag(s, -s)."""

    scale_px_per_m: float
    centre_m: np.ndarray
    centre_px: np.ndarray

    @property
    def jacobian(self) -> np.ndarray:
        """(2, 2) map pixels per metre."""
        return np.diag([self.scale_px_per_m, -self.scale_px_per_m])

    def to_px(self, points_m) -> np.ndarray:
        """Map pixels (..., 2) of ground points (..., 2) in metres."""
        return (np.asarray(points_m, dtype=float) - self.centre_m) @ self.jacobian.T + self.centre_px

    def to_m(self, points_px) -> np.ndarray:
        """Ground points (..., 2) in metres of map pixels (..., 2)."""
        return (np.asarray(points_px, dtype=float) - self.centre_px) @ np.linalg.inv(self.jacobian).T + self.centre_m


def map_transform(episode: Episode) -> MapTransform:
    """The largest scale that shows the area and the camera with a margin, centred in the map panel."""
    corners_m = np.vstack([episode.area_polygon_m, episode.camera.centre_m[:2]])
    low_m, high_m = corners_m.min(axis=0) - MAP_MARGIN_M, corners_m.max(axis=0) + MAP_MARGIN_M
    scale = float(np.min(np.asarray(PANEL_SIZE_PX) / (high_m - low_m)))
    return MapTransform(scale, (low_m + high_m) / 2, np.asarray(PANEL_SIZE_PX) / 2)


def model_view(camera: PTZCamera, truth: GroundTruth, step: int, pose) -> np.ndarray:
    """The camera model's picture (h, w, 3) uint8 BGR: the present people's boxes, nearer ones on top
    (people of unknown height are not drawn)."""
    image = _model_background(camera.image_height_px, camera.image_width_px).copy()
    present = truth.present[step] & np.isfinite(truth.heights_m)
    people = project_people(
        camera, pose, truth.positions_m[step, present], truth.heights_m[present], truth.widths_m[present]
    )
    for index in np.argsort(-people.range_m):
        if people.in_front[index]:
            corners = _int_px(people.box_px[index].reshape(2, 2))
            cv2.rectangle(image, corners[0], corners[1], MODEL_PERSON_BGR, cv2.FILLED)
            cv2.rectangle(image, corners[0], corners[1], MODEL_EDGE_BGR, 1)
    return image


@functools.cache
def _model_background(height_px: int, width_px: int) -> np.ndarray:
    """The synthetic view's background, read-only: a copy of it is some fifty times faster than np.full
    with a colour (a strided fill), which took a live view's run a millisecond a picture."""
    background = np.full((height_px, width_px, 3), MODEL_BACKGROUND_BGR, np.uint8)
    background.flags.writeable = False
    return background


def view_renderer(world: World) -> RenderView:
    """``render_view`` for an episode in ``world``: the camera backend's image, or where it renders
    none, :func:`model_view`."""

    def render(step: int, pose) -> np.ndarray:
        image = world.backend.image(step, pose)
        return model_view(world.camera, world.truth, step, pose) if image is None else image

    return render


def write_episode_video(path: str | Path, episode: Episode, render_view: RenderView, label: str = "") -> None:
    """Write the episode video to ``path`` (.mp4, MPEG-4 Part 2) at the scene's frame rate.

    One frame (FRAME_SIZE_PX) per step, of the last ``VIDEO_MAX_STEPS`` steps. Written to a temporary file beside
    ``path`` and renamed, so a failure leaves no partial file and keeps an old one.
    """
    write_video(path, episode_frames(episode, render_view, label), episode.truth.frame_rate_hz, FRAME_SIZE_PX)


def write_video(
    path: str | Path, frames: Iterable[np.ndarray], frame_rate_hz: float, size_px, fourcc: str = "mp4v"
) -> None:
    """Write ``frames`` ((height, width, 3) uint8 BGR of ``size_px`` (width, height)) to ``path`` through a
    temporary file beside it and a rename. fourcc : the codec ('mp4v': MPEG-4 Part 2, for .mp4; 'MJPG':
    Motion JPEG, for .avi), which OpenCV's FFmpeg encodes; the container is the path's suffix's."""
    path = Path(path)
    handle, temporary = open_temporary_beside(path, path.suffix or ".mp4")  # OpenCV picks the container by it
    os.close(handle)
    try:
        writer = cv2.VideoWriter(str(temporary), cv2.VideoWriter.fourcc(*fourcc), frame_rate_hz, tuple(size_px))
        try:
            if not writer.isOpened():
                raise RuntimeError(f"{path}: OpenCV cannot write {fourcc} video here")
            for frame in frames:
                writer.write(frame)
        finally:
            writer.release()
        os.replace(temporary, path)
    except BaseException:
        os.unlink(temporary)
        raise


def episode_frames(
    episode: Episode, render_view: RenderView, label: str = "", max_steps: int = VIDEO_MAX_STEPS
) -> Iterator[np.ndarray]:
    """The video's frames, one per step of the last ``max_steps``: (FRAME_SIZE_PX[1], FRAME_SIZE_PX[0], 3)
    uint8 BGR."""
    transform = map_transform(episode)
    background = map_background(episode, transform)
    first = max(len(episode.poses) - max_steps, 0)
    for step, pose in enumerate(episode.poses[first:], start=first):
        view = render_view(step, pose)
        view = view_panel(episode.camera, view, pose, episode.detections[step], episode.tracks[step])
        ground = map_panel(episode, step, background, transform)
        yield np.vstack([np.hstack([view, ground]), caption(episode, step, label)])


def view_panel(camera: PTZCamera, view_bgr, pose, detections: Detections, tracks: Tracks) -> np.ndarray:
    """The view upscaled into the panel (top left), with the detections and the tracks' ellipses and ids."""
    scale = min(PANEL_SIZE_PX[0] / camera.image_width_px, PANEL_SIZE_PX[1] / camera.image_height_px)
    panel = np.zeros((PANEL_SIZE_PX[1], PANEL_SIZE_PX[0], 3), np.uint8)
    width, height = round(scale * camera.image_width_px), round(scale * camera.image_height_px)
    # Nearest neighbour keeps the view's pixels visible: that is all the detector had.
    panel[:height, :width] = cv2.resize(view_bgr, (width, height), interpolation=cv2.INTER_NEAREST)
    _draw_detections(panel, detections, scale)
    centre_px, in_front, half_axes_px, angle_deg = image_ellipses(
        camera, pose, tracks.mean[:, :2], tracks.covariance[:, :2, :2]
    )
    # A pixel's centre is at (i + 0.5) in camera coordinates and at i in cv2's.
    centre_px = scale * centre_px - 0.5
    # Only tracks predicted near the view: towards the horizon the Jacobian,
    # and with it the linearised ellipse, grows without bound.
    panel_size_px = np.asarray(PANEL_SIZE_PX)
    near = in_front & np.all(np.abs(centre_px - panel_size_px / 2) <= panel_size_px, axis=1)
    _draw_tracks(panel, tracks.ids[near], centre_px[near], scale * half_axes_px[near], angle_deg[near])
    return panel


def map_background(episode: Episode, transform: MapTransform) -> np.ndarray:
    """What the map shows at every step: the 5 m grid with its labels, the area, the camera."""
    panel = np.full((PANEL_SIZE_PX[1], PANEL_SIZE_PX[0], 3), 255, np.uint8)
    low_m, high_m = np.sort(transform.to_m([[0, 0], PANEL_SIZE_PX]), axis=0)
    for axis in (0, 1):
        for value_m in np.arange(np.ceil(low_m[axis] / GRID_STEP_M), high_m[axis] / GRID_STEP_M) * GRID_STEP_M:
            ends_m = np.array([low_m, high_m])
            ends_m[:, axis] = value_m
            ends = _int_px(transform.to_px(ends_m))
            cv2.line(panel, ends[0], ends[1], GRID_BGR, 1)
            # x labels along the bottom edge, y labels along the left one, where they fit
            position_px = ends[0][axis]
            if GRID_LABEL_ROOM_PX <= position_px <= PANEL_SIZE_PX[axis] - GRID_LABEL_ROOM_PX:
                where = (position_px + 3, PANEL_SIZE_PX[1] - 5) if axis == 0 else (3, position_px - 3)
                font = cv2.FONT_HERSHEY_SIMPLEX
                cv2.putText(panel, f"{value_m:g}", where, font, 0.35, GRID_LABEL_BGR, 1, cv2.LINE_AA)
    cv2.polylines(panel, [_int_px(transform.to_px(episode.area_polygon_m))], True, BLACK, 1)
    camera = _int_px(transform.to_px(episode.camera.centre_m[:2]))
    triangle = np.array([camera + [0, -8], camera + [-7, 5], camera + [7, 5]], np.int32)
    cv2.fillPoly(panel, [triangle], BLACK, cv2.LINE_AA)
    _text(panel, "camera", camera + [10, 4], BLACK, outline=WHITE)
    return panel


def map_panel(episode: Episode, step: int, background, transform: MapTransform) -> np.ndarray:
    """The map at ``step``: field of view, true positions and tracks over the background."""
    panel = background.copy()
    reach_m = float(np.hypot(*PANEL_SIZE_PX)) / transform.scale_px_per_m
    footprint = _int_px(transform.to_px(ground_footprint(episode.camera, episode.poses[step], max_range_m=reach_m)))
    shaded = panel.copy()
    cv2.fillPoly(shaded, [footprint], FOOTPRINT_BGR, cv2.LINE_AA)
    cv2.addWeighted(shaded, FOOTPRINT_OPACITY, panel, 1 - FOOTPRINT_OPACITY, 0, dst=panel)
    cv2.polylines(panel, [footprint], True, FOOTPRINT_BGR, 1, cv2.LINE_AA)
    truth_m = episode.truth.positions_m[step]
    radius_px = max(2, round(0.2 * transform.scale_px_per_m))  # about a person's half-width
    for point in _int_px(transform.to_px(truth_m[episode.truth.present[step]])):
        cv2.circle(panel, point, radius_px, TRUTH_BGR, cv2.FILLED, cv2.LINE_AA)
    tracks = episode.tracks[step]
    J = transform.jacobian
    half_axes_px, angle_deg = ellipse_axes(J @ tracks.covariance[:, :2, :2] @ J.T)
    _draw_tracks(panel, tracks.ids, transform.to_px(tracks.mean[:, :2]), half_axes_px, angle_deg, outline=WHITE)
    return panel


def caption(episode: Episode, step: int, label: str) -> np.ndarray:
    """Two lines under the panels: step, pose, counts and label; then the legend."""
    strip = np.full((CAPTION_HEIGHT_PX, FRAME_SIZE_PX[0], 3), 40, np.uint8)
    pan_deg, tilt_deg, zoom = episode.poses[step]
    first = (
        f"step {step}/{len(episode.poses) - 1}   pan {pan_deg:.1f} deg  tilt {tilt_deg:.1f} deg  zoom {zoom:.1f}x   "
        f"{len(episode.detections[step])} detections, {len(episode.tracks[step])} tracks   {label}"
    )
    legend = (
        "left: camera view, detections white, tracks by id with 2-sigma ellipses   "
        "right: ground plane [m], truth grey, tracks, field of view blue, area black"
    )
    _text(strip, first, (8, 19), WHITE, 0.5)
    _text(strip, legend, (8, 40), (200, 200, 200), 0.42)
    return strip


def _draw_detections(panel, detections: Detections, scale: float) -> None:
    """Feet points, and boxes from the feet up where the height is known (false positives have none)."""
    feet_px = scale * detections.feet_px
    height_px = scale * detections.height_px
    for feet, height in zip(feet_px, height_px, strict=True):
        if np.isfinite(height):
            half_width = 0.5 * DETECTION_WIDTH_PER_HEIGHT * height
            corners = _int_px(np.array([feet + [-half_width, -height], feet + [half_width, 0.0]]) - 0.5)
            cv2.rectangle(panel, corners[0], corners[1], WHITE, 1, cv2.LINE_AA)
        # A cross whose arms stay visible around the dot of a track drawn over it
        point = _int_px(feet - 0.5)
        cv2.drawMarker(panel, point, BLACK, cv2.MARKER_CROSS, 13, 3, cv2.LINE_AA)
        cv2.drawMarker(panel, point, WHITE, cv2.MARKER_CROSS, 11, 1, cv2.LINE_AA)


def _draw_tracks(panel, ids, centre_px, half_axes_px, angle_deg, outline=BLACK) -> None:
    """Each track's ellipse, centre and id in its colour; ``half_axes_px`` major then minor."""
    for track_id, centre, axes, angle in zip(ids, centre_px, half_axes_px, angle_deg, strict=True):
        colour = TRACK_COLOURS_BGR[int(track_id) % len(TRACK_COLOURS_BGR)]
        point = _int_px(centre)
        size = tuple(int(a) for a in np.clip(np.round(axes), 1, MAX_DRAWN_PX))
        cv2.ellipse(panel, point, size, float(angle), 0, 360, colour, 2, cv2.LINE_AA)
        cv2.circle(panel, point, 2, colour, cv2.FILLED, cv2.LINE_AA)
        _text(panel, str(int(track_id)), point + [6, -6], colour, outline=outline)


def _text(image, text: str, origin_px, colour, scale: float = 0.45, outline=BLACK) -> None:
    """Text with an outline, legible on a busy background."""
    origin = tuple(int(v) for v in origin_px)
    cv2.putText(image, text, origin, cv2.FONT_HERSHEY_SIMPLEX, scale, outline, 3, cv2.LINE_AA)
    cv2.putText(image, text, origin, cv2.FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv2.LINE_AA)


def _int_px(points_px) -> np.ndarray:
    """Points rounded to int32 for cv2, clipped to +-MAX_DRAWN_PX."""
    return np.clip(np.round(np.asarray(points_px, dtype=float)), -MAX_DRAWN_PX, MAX_DRAWN_PX).astype(np.int32)
