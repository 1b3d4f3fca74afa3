"""People walking among fixed calibrated cameras, rendered: the one renderer of the synthetic room, the
plaza and ``ptztrack render``.

The *stage* is the static surroundings (:class:`Stage`): an axis-aligned box standing on the ground
plane z = 0, whose floor is laid with square tiles of random shade under a texture, whose four walls
carry another texture and a dark skirting band at their foot, and whose lid is plain (a ceiling, or
the sky). Every pixel's ray is cast to the nearest of the box's six planes, so any calibrated camera
inside the box gets its background (:func:`stage_background`); :func:`stage_around` builds one
around an area and its cameras. The people walk as in :mod:`ptztrack.scene.synthetic` and are drawn
as textured cone models (legs swinging with the gait, torso, shoulders, neck and head: a more
detailed body than the detector's model) by the painter's algorithm with OpenCV, lit from above
(:func:`draw_people`). Each frame gets sensor noise (:class:`SceneRenderer`).
"""

from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from ptztrack.geometry.calibration import (
    PinholeCalibration,
    camera_centre_m,
    imaged_radius,
    in_image,
    pixel_rays,
    project_pinhole,
)
from ptztrack.scene.cutouts import CutoutTrack, paste_people
from ptztrack.types import GroundTruth

FACETS = 16  # facets around each cone
STRIPES = 3  # rings along each cone, alternately shaded: the clothes' texture
STRIDE_M = 1.4  # walking distance of one gait cycle
NOISE_FRAMES = 16  # sensor noise images per camera, drawn from per frame
NOISE_SIGMA = 2.0  # grey levels
LIGHT = np.array([0.3, 0.2, 0.93])  # towards the light: from above
TEXTURE_PX, TEXTURE_GRAINS = 512, 24  # the texture image's side and its coarse noise cells
TILE_SHADES = 64  # tiles of distinct shade per side; the pattern repeats beyond
SKIRTING_M = 0.12
FLOOR_TINT, WALL_TINT = np.array([0.95, 1.0, 1.05]), np.array([1.05, 1.0, 0.9])  # BGR
NEAREST_FACET_M = 0.05  # facets nearer the camera's image plane than this are not drawn
MAX_PIXEL = 1e5  # facet corners are clamped to +- this many pixels: cv2's fixed-point int32 stays in range
WALK_PROBE_M = 0.1  # which way a person walks across an image: their feet and this far ahead, projected


@dataclass(frozen=True)
class Stage:
    """The static surroundings the people walk in: a box on the ground plane, every camera inside it.

    bounds_m : ((x0, y0), (x1, y1)) the walls' footprint, m; height_m : the lid's height, m;
    tile_m : the floor tiles' side, m; texture_m : the period of the floor's and walls' texture, m;
    lid_bgr : the lid's plain colour (a ceiling's grey, the sky's blue).
    """

    bounds_m: tuple[tuple[float, float], tuple[float, float]]
    height_m: float
    tile_m: float = 0.5
    texture_m: float = 4.0
    lid_bgr: tuple[float, float, float] = (200.0, 200.0, 200.0)


SKY_BGR = (235.0, 215.0, 195.0)


def stage_around(
    area_m,
    cameras: Sequence[PinholeCalibration],
    margin_m: float = 5.0,
    height_m: float = 15.0,
    tile_m: float = 1.0,
    lid_bgr: tuple[float, float, float] = SKY_BGR,
) -> Stage:
    """An open place around an area and its cameras: the box is their bounding box on the ground
    (area_m ((x0, y0), (x1, y1)) m and every camera's centre), widened by ``margin_m`` on every side, and
    ``height_m`` high but at least ``margin_m`` above the highest camera (the renderer needs every
    camera inside the box); the floor is paved in ``tile_m`` slabs and the lid is the sky."""
    centres_m = np.array([camera_centre_m(camera) for camera in cameras]).reshape(-1, 3)
    footprint_m = np.concatenate([np.asarray(area_m, dtype=float), centres_m[:, :2]])
    low, high = footprint_m.min(axis=0) - margin_m, footprint_m.max(axis=0) + margin_m
    height_m = max(height_m, float(centres_m[:, 2].max(initial=0.0)) + margin_m)
    bounds_m = ((float(low[0]), float(low[1])), (float(high[0]), float(high[1])))
    return Stage(bounds_m=bounds_m, height_m=height_m, tile_m=tile_m, lid_bgr=lid_bgr)


def _texture(rng: np.random.Generator, size: int, grains: int) -> np.ndarray:
    """A smooth random grey texture (size, size) float32 in about [-1, 1]: noise of ``grains`` x ``grains``
    cells, upsampled bicubically, plus fine grain."""
    coarse = rng.uniform(-1, 1, (grains, grains)).astype(np.float32)
    smooth = cv2.resize(coarse, (size, size), interpolation=cv2.INTER_CUBIC)
    return 0.7 * smooth + 0.3 * rng.uniform(-1, 1, (size, size)).astype(np.float32)


def stage_background(
    stage: Stage, calibration: PinholeCalibration, image_size_px: tuple[int, int], rng: np.random.Generator
) -> np.ndarray:
    """The empty stage as the camera sees it: (height, width, 3) uint8 BGR, image_size_px (width, height).

    Each pixel's ray c + t d (:func:`~ptztrack.geometry.calibration.pixel_rays`, metres) meets the
    planes z = 0, z = height_m, x = x0, x = x1, y = y0 and y = y1 at t = (value - c_axis) / d_axis; the
    nearest positive t is the surface seen. The floor is tile_m tiles (shade 0.75-1 drawn per tile)
    times 150 + 35 g, the walls 170 + 30 g (70 + 10 g below SKIRTING_M), g the texture (about
    [-1, 1], period texture_m) at the point, coordinates from the box's corner (x0, y0). ``rng``
    draws the texture and the tiles' shades.
    """
    width_px, height_px = image_size_px
    u, v = np.meshgrid(np.arange(width_px) + 0.5, np.arange(height_px) + 0.5)
    centre_m, direction = pixel_rays(calibration, np.stack([u.ravel(), v.ravel()], axis=-1))
    (x0, y0), (x1, y1) = stage.bounds_m
    planes = [(2, 0.0), (2, stage.height_m), (0, x0), (0, x1), (1, y0), (1, y1)]
    with np.errstate(divide="ignore", invalid="ignore"):
        t_m = np.stack([(value - centre_m[axis]) / direction[:, axis] for axis, value in planes], axis=-1)
    t_m = np.where(t_m > 1e-6, t_m, np.inf)
    surface = np.argmin(t_m, axis=-1)  # the index into planes: 0 floor, 1 lid, 2-5 walls
    point_m = centre_m + np.min(t_m, axis=-1)[:, None] * direction
    texture = _texture(rng, TEXTURE_PX, TEXTURE_GRAINS)
    tiles = rng.uniform(0.75, 1.0, (TILE_SHADES, TILE_SHADES))
    x_m, y_m = point_m[:, 0] - x0, point_m[:, 1] - y0
    # Floor: texture over x and y; walls: along the wall and up.
    on_floor = surface == 0
    along = np.where(surface >= 4, x_m, y_m)
    texture_u = np.where(on_floor, x_m, along) / stage.texture_m * TEXTURE_PX
    texture_v = np.where(on_floor, y_m, point_m[:, 2]) / stage.texture_m * TEXTURE_PX
    grain = cv2.remap(
        texture,
        np.mod(texture_u, TEXTURE_PX).astype(np.float32).reshape(height_px, width_px),
        np.mod(texture_v, TEXTURE_PX).astype(np.float32).reshape(height_px, width_px),
        cv2.INTER_LINEAR,
    ).ravel()
    tile = tiles[
        np.clip(np.floor(x_m / stage.tile_m).astype(int), 0, None) % TILE_SHADES,
        np.clip(np.floor(y_m / stage.tile_m).astype(int), 0, None) % TILE_SHADES,
    ]
    skirting = (surface >= 2) & (point_m[:, 2] < SKIRTING_M)
    wall_grey = np.where(skirting, 70 + 10 * grain, 170 + 30 * grain)
    colour = np.where(
        on_floor[:, None],
        (tile * (150 + 35 * grain))[:, None] * FLOOR_TINT,
        np.where((surface == 1)[:, None], np.asarray(stage.lid_bgr, dtype=float), wall_grey[:, None] * WALL_TINT),
    )
    return np.clip(colour, 0, 255).reshape(height_px, width_px, 3).astype(np.uint8)


@dataclass(frozen=True)
class Outfit:
    """Colours (BGR) of a person's parts: legs, torso, skin, hair."""

    legs: tuple[int, int, int]
    torso: tuple[int, int, int]
    skin: tuple[int, int, int]
    hair: tuple[int, int, int]


def random_outfit(rng: np.random.Generator) -> Outfit:
    """Clothes of random colours (legs darker, torso any) and a skin tone of 0.6-1 times a light one."""

    def colour(low: int, high: int) -> tuple[int, int, int]:
        return tuple(int(value) for value in rng.integers(low, high, 3))  # type: ignore[return-value]

    skin = tuple(int(value) for value in np.array([120, 150, 200]) * rng.uniform(0.6, 1.0))
    return Outfit(legs=colour(20, 140), torso=colour(30, 230), skin=skin, hair=colour(10, 70))  # type: ignore[arg-type]


def body_cones(position_m, heading_rad: float, phase_rad: float, height_m: float, width_m: float):
    """A walking person as truncated cones: (C, 2, 3) axis end points m, (C, 2) radii m, (C,) part
    (0 legs, 1 torso, 2 skin, 3 hair). The legs swing along the heading with the gait phase."""
    x, y = position_m
    ahead = np.array([np.cos(heading_rad), np.sin(heading_rad), 0.0])
    side = np.array([-ahead[1], ahead[0], 0.0])
    ground = np.array([x, y, 0.0])
    hip_z, shoulder_z, neck_z, chin_z = 0.48 * height_m, 0.8 * height_m, 0.84 * height_m, 0.87 * height_m
    half = width_m / 2
    cones, radii, parts = [], [], []
    for sign in (1.0, -1.0):
        foot = ground + sign * 0.2 * half * side + sign * 0.22 * np.sin(phase_rad) * ahead
        hip = ground + sign * 0.3 * half * side + np.array([0.0, 0.0, hip_z])
        cones.append([foot, hip])
        radii.append([0.05, 0.085])
        parts.append(0)
    axis = ground + np.array([0.0, 0.0, 1.0])[None, :] * np.array([[hip_z], [shoulder_z], [neck_z], [chin_z]])
    head_mid, top = ground + [0, 0, 0.93 * height_m], ground + [0, 0, height_m]
    for (bottom, upper), (r0, r1), part in (
        ((axis[0] - [0, 0, 0.05], axis[1]), (0.62 * half, 0.82 * half), 1),
        ((axis[1], axis[2]), (0.82 * half, 0.25 * half), 1),
        ((axis[2], axis[3]), (0.22 * half, 0.22 * half), 2),
        ((axis[3], head_mid), (0.3 * half, 0.4 * half), 2),
        ((head_mid, top), (0.4 * half, 0.12 * half), 3),
    ):
        cones.append([bottom, upper])
        radii.append([r0 * 0.85, r1 * 0.85] if part == 1 else [r0, r1])
        parts.append(part)
    return np.asarray(cones, dtype=float), np.asarray(radii, dtype=float), np.asarray(parts)


def cone_facets(cones, radii) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Quadrilateral facets of truncated cones: corners (C, STRIPES, FACETS, 4, 3) m, outward normals
    (C, STRIPES, FACETS, 3) and centres (C, STRIPES, FACETS, 3)."""
    bottom, top = cones[:, 0], cones[:, 1]
    axis = top - bottom
    length = np.linalg.norm(axis, axis=-1, keepdims=True)
    unit = axis / length
    reference = np.where(np.abs(unit[:, 2:3]) < 0.9, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0])
    e1 = np.cross(unit, reference)
    e1 /= np.linalg.norm(e1, axis=-1, keepdims=True)
    e2 = np.cross(unit, e1)
    angle = np.linspace(0, 2 * np.pi, FACETS + 1)
    level = np.linspace(0, 1, STRIPES + 1)
    ring_radius = radii[:, :1] + (radii[:, 1:] - radii[:, :1]) * level  # (C, STRIPES + 1)
    around = np.cos(angle)[None, :, None] * e1[:, None, :] + np.sin(angle)[None, :, None] * e2[:, None, :]
    ring_centre = bottom[:, None, :] + level[None, :, None] * axis[:, None, :]  # (C, STRIPES + 1, 3)
    rings = ring_centre[:, :, None, :] + ring_radius[:, :, None, None] * around[:, None, :, :]
    corners = np.stack([rings[:, :-1, :-1], rings[:, :-1, 1:], rings[:, 1:, 1:], rings[:, 1:, :-1]], axis=-2)
    middle = 0.5 * (angle[:-1] + angle[1:])
    outward = np.cos(middle)[None, :, None] * e1[:, None, :] + np.sin(middle)[None, :, None] * e2[:, None, :]
    slope = (radii[:, 0] - radii[:, 1]) / length[:, 0]
    normal = outward + slope[:, None, None] * unit[:, None, :]
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    normals = np.broadcast_to(normal[:, None], corners.shape[:3] + (3,))
    return corners, normals, corners.mean(axis=-2)


def draw_people(background, calibration: PinholeCalibration, people_cones: list, outfits: list[Outfit]) -> np.ndarray:
    """The background (height, width, 3) uint8 BGR with the people painted over it, far facets first
    (painter's algorithm).

    people_cones : per person, what :func:`body_cones` returns; outfits : per person. A facet is
    shaded by its part's colour, its stripe (1 or 0.8) and Lambert's law 0.55 + 0.45 max(0, n . l)
    towards LIGHT. Facets facing away from the camera, nearer its image plane than NEAREST_FACET_M,
    or beyond the radius its distortion maps outwards (where OpenCV's polynomial folds back into the
    image: :func:`~ptztrack.geometry.calibration.imaged_radius`) are not drawn.
    """
    image = background.copy()
    if not people_cones:
        return image
    centre_m = camera_centre_m(calibration)
    corner_list, shade_list, depth_list = [], [], []
    for (cones, radii, parts), outfit in zip(people_cones, outfits, strict=True):
        corners, normals, centres = cone_facets(cones, radii)
        palette = np.array([outfit.legs, outfit.torso, outfit.skin, outfit.hair], dtype=float)[parts]
        stripe = np.where(np.arange(STRIPES) % 2 == 0, 1.0, 0.8)
        lambert = 0.55 + 0.45 * np.clip(normals @ (LIGHT / np.linalg.norm(LIGHT)), 0, 1)
        colour = palette[:, None, None, :] * (stripe[None, :, None] * lambert)[..., None]
        towards_camera = centre_m - centres
        facing = np.einsum("...d,...d->...", normals, towards_camera) > 0
        corner_list.append(corners[facing])
        shade_list.append(colour[facing])
        depth_list.append(np.linalg.norm(towards_camera[facing], axis=-1))
    corners = np.concatenate(corner_list)
    shades = np.concatenate(shade_list)
    depth = np.concatenate(depth_list)
    camera_m = corners @ calibration.R.T + calibration.t / 1000.0
    in_front = camera_m[..., 2].min(axis=-1) > NEAREST_FACET_M
    with np.errstate(divide="ignore", invalid="ignore"):
        radius = np.hypot(camera_m[..., 0], camera_m[..., 1]) / camera_m[..., 2]
    drawn = in_front & (np.where(in_front[:, None], radius, 0.0).max(axis=-1) < imaged_radius(calibration))
    corners, shades, depth = corners[drawn], shades[drawn], depth[drawn]
    pixels = project_pinhole(calibration, corners.reshape(-1, 3) * 1000.0).reshape(-1, 4, 2)
    # cv2 puts pixel (i, j)'s centre at (i, j); ptztrack's pixel coordinates put it at (i + 0.5, j + 0.5).
    fixed = np.round((np.clip(pixels, -MAX_PIXEL, MAX_PIXEL) - 0.5) * 16).astype(np.int32)
    for index in np.argsort(-depth):
        cv2.fillConvexPoly(image, fixed[index], tuple(float(value) for value in shades[index]), cv2.LINE_AA, 4)
    return image


class SceneRenderer:
    """The frames of fixed calibrated cameras watching people on a stage: ``image(view, frame)``,
    (height, width, 3) uint8 BGR at the view's image size.

    cameras : the views' calibrations (world in mm); image_sizes_px : per view, (width, height);
    stage : the surroundings, every camera inside its box; truth : the people (positions (T, N, 2) m,
    heights and widths (N,) m); seed : fixes the textures, outfits and sensor noise (a frame's noise
    is the same however often it is rendered). people_cutouts : real pedestrians to draw the people as
    (:mod:`ptztrack.scene.cutouts`) instead of cone bodies: each person walks as one of them, drawn at
    random, from a random frame of its walk on, one frame of it per frame.
    """

    def __init__(
        self,
        cameras: Sequence[PinholeCalibration],
        image_sizes_px: Sequence[tuple[int, int]],
        stage: Stage,
        truth: GroundTruth,
        seed: int,
        people_cutouts: Sequence[CutoutTrack] | None = None,
    ):
        self.cameras = list(cameras)
        self.image_sizes_px = [(int(width), int(height)) for width, height in image_sizes_px]
        self.stage, self.truth, self.seed = stage, truth, seed
        texture_seed, outfit_seed, noise_seed = np.random.SeedSequence(seed).spawn(3)
        # Each view draws its own textures: the detectors read every view on its own, so the views'
        # surfaces need not agree.
        texture_rng = np.random.default_rng(texture_seed)
        self.backgrounds = [
            stage_background(stage, camera, size, texture_rng)
            for camera, size in zip(self.cameras, self.image_sizes_px, strict=True)
        ]
        outfit_rng = np.random.default_rng(outfit_seed)
        self.outfits = [random_outfit(outfit_rng) for _ in range(truth.positions_m.shape[1])]
        noise_rng = np.random.default_rng(noise_seed)
        # One noise stack of the largest size; each view takes its top-left corner.
        width_px = max(size[0] for size in self.image_sizes_px)
        height_px = max(size[1] for size in self.image_sizes_px)
        self.noise = noise_rng.normal(0, NOISE_SIGMA, (NOISE_FRAMES, height_px, width_px, 1)).astype(np.float32)
        self.heading_rad, self.phase_rad = _gait(truth)
        self.people_cutouts = list(people_cutouts) if people_cutouts is not None else None
        if self.people_cutouts is not None:
            if not self.people_cutouts:
                raise ValueError("people_cutouts: no pedestrian to draw the people as")
            # A fourth stream: the first three are those above, whatever follows.
            cutout_rng = np.random.default_rng(np.random.SeedSequence(seed).spawn(4)[3])
            people = truth.positions_m.shape[1]
            self.cutout_track = cutout_rng.integers(len(self.people_cutouts), size=(people,))
            self.cutout_offset = cutout_rng.integers(0, 2**31, size=(people,))

    def people_cones(self, frame: int) -> list:
        """The cones (:func:`body_cones`) of every person present at ``frame``."""
        truth = self.truth
        return [
            body_cones(
                truth.positions_m[frame, person],
                self.heading_rad[frame, person],
                self.phase_rad[frame, person],
                truth.heights_m[person],
                truth.widths_m[person],
            )
            for person in np.flatnonzero(truth.present[frame])
        ]

    def image(self, view: int, frame: int) -> np.ndarray:
        """View ``view``'s image at ``frame``: the people over its background, plus one of the noise images."""
        present = np.flatnonzero(self.truth.present[frame])
        if self.people_cutouts is not None:
            drawn = self._pasted(view, frame, present)
        else:
            drawn = draw_people(
                self.backgrounds[view],
                self.cameras[view],
                self.people_cones(frame),
                [self.outfits[person] for person in present],
            )
        rng = np.random.default_rng([self.seed, view, frame])
        width_px, height_px = self.image_sizes_px[view]
        noise = self.noise[rng.integers(NOISE_FRAMES), :height_px, :width_px]
        return np.clip(drawn + noise, 0, 255).astype(np.uint8)

    def _pasted(self, view: int, frame: int, present: np.ndarray) -> np.ndarray:
        """The view's background with the people ``present`` at ``frame`` pasted as their cutouts, each
        mirrored where it walked the other way across the image than the person walks across this one."""
        assert self.people_cutouts is not None
        truth, camera = self.truth, self.cameras[view]
        feet_m = truth.positions_m[frame, present]
        boxes, _ = person_boxes(
            camera, self.image_sizes_px[view], feet_m, truth.heights_m[present], truth.widths_m[present]
        )
        shown = np.isfinite(boxes[:, 0])
        heading = self.heading_rad[frame, present[shown]]
        ahead_m = feet_m[shown] + WALK_PROBE_M * np.stack([np.cos(heading), np.sin(heading)], axis=-1)
        ahead_px = project_pinhole(camera, 1000.0 * np.c_[ahead_m, np.zeros(len(ahead_m))])
        moving_right = ahead_px[:, 0] > boxes[shown, 0] + boxes[shown, 2] / 2
        tracks = [self.people_cutouts[index] for index in self.cutout_track[present[shown]]]
        cutouts = [
            track.cutouts[(offset + frame) % len(track.cutouts)]
            for track, offset in zip(tracks, self.cutout_offset[present[shown]], strict=True)
        ]
        mirrored = [track.moving_right != right for track, right in zip(tracks, moving_right, strict=True)]
        return paste_people(self.backgrounds[view], camera, boxes[shown], feet_m[shown], cutouts, mirrored)


def _gait(truth: GroundTruth) -> tuple[np.ndarray, np.ndarray]:
    """Heading (T, N) rad from each person's motion, and gait phase (T, N) rad from the distance walked."""
    step_m = np.diff(truth.positions_m, axis=0, prepend=truth.positions_m[:1])
    step_m[0] = step_m[1] if len(step_m) > 1 else 0.0
    heading = np.arctan2(step_m[..., 1], step_m[..., 0])
    walked_m = np.nancumsum(np.linalg.norm(np.nan_to_num(step_m), axis=-1), axis=0)
    return heading, 2 * np.pi * walked_m / STRIDE_M


def person_boxes(
    calibration: PinholeCalibration, image_size_px: tuple[int, int], positions_m, heights_m, widths_m
) -> tuple[np.ndarray, np.ndarray]:
    """People's boxes in a calibrated view, as an annotator would draw them: boxes (N, 4) (left, top,
    width, height) px and whether each person's feet are in the image (N,) bool (in front of the camera
    and inside (width, height) = ``image_size_px``; :func:`~ptztrack.geometry.calibration.in_image`).

    positions_m : (N, 2) feet on the ground; heights_m, widths_m : (N,). A box's bottom centre is the
    feet's projection and its top the head's (the point ``heights_m`` above the feet); its width is the
    distance between the projections of the two points ``widths_m`` / 2 either side of the feet along
    the camera's horizontal axis. The boxes of people whose feet or head are not ahead of the camera by
    NEAREST_FACET_M, or beyond the radius its distortion maps outwards, are NaN.
    """
    positions_m = np.asarray(positions_m, dtype=float).reshape(-1, 2)
    count = len(positions_m)
    feet_mm = 1000.0 * np.c_[positions_m, np.zeros(count)]
    head_mm = feet_mm + 1000.0 * np.c_[np.zeros((count, 2)), np.asarray(heights_m, dtype=float).reshape(-1)]
    across = np.array([*calibration.R[0, :2], 0.0])  # the image's x axis on the ground
    across /= np.linalg.norm(across)
    half_mm = 500.0 * np.asarray(widths_m, dtype=float).reshape(-1)[:, None] * across
    boxes = np.full((count, 4), np.nan)
    ends = np.stack([feet_mm, head_mm, feet_mm - half_mm, feet_mm + half_mm], axis=1)  # (N, 4, 3)
    camera_m = (ends @ calibration.R.T + calibration.t) / 1000.0
    with np.errstate(divide="ignore", invalid="ignore"):
        radius = np.hypot(camera_m[..., 0], camera_m[..., 1]) / camera_m[..., 2]
    drawn = np.all(camera_m[..., 2] > NEAREST_FACET_M, axis=1) & np.all(radius < imaged_radius(calibration), axis=1)
    if drawn.any():
        feet_px, head_px, left_px, right_px = (
            project_pinhole(calibration, ends[drawn].reshape(-1, 3)).reshape(-1, 4, 2).transpose(1, 0, 2)
        )
        width_px = np.linalg.norm(right_px - left_px, axis=-1)
        height_px = feet_px[:, 1] - head_px[:, 1]
        boxes[drawn] = np.c_[feet_px[:, 0] - width_px / 2, feet_px[:, 1] - height_px, width_px, height_px]
    return boxes, in_image(calibration, image_size_px, feet_mm) & drawn
