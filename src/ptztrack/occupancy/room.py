"""A synthetic room seen by fixed calibrated cameras: the LPOM paper's lab, rendered.

The paper's experiments (section 5) ran in "a lab of about 5 x 6 metres with
four cameras mounted in the four corners", 1024 x 768 px at 15 Hz, with one
and with three people. Here the people walk as in :mod:`ptztrack.scene.synthetic`
and are drawn as textured cone models (legs swinging with the gait, torso,
shoulders, neck and head: a more detailed body than the detector's model)
over a textured floor and textured walls, by the painter's algorithm with
OpenCV. The cameras (mounting not given by the paper) hang 2.8 m high,
0.1 m inside each corner, aimed at the room's centre 0.9 m above the floor,
with a 1024 x 768 image and a 500 px focal length (91 deg horizontal field
of view) and no lens distortion. Each frame gets sensor noise.
"""

from dataclasses import dataclass

import cv2
import numpy as np

from ptztrack.geometry.calibration import PinholeCalibration, pixel_rays, project_pinhole
from ptztrack.scene.parameters import Crowd
from ptztrack.scene.synthetic import walk_people
from ptztrack.types import GroundTruth

FACETS = 16  # facets around each cone
STRIPES = 3  # rings along each cone, alternately shaded: the clothes' texture
STRIDE_M = 1.4  # walking distance of one gait cycle
NOISE_FRAMES = 16  # sensor noise images per camera, drawn from per frame
NOISE_SIGMA = 2.0  # grey levels
LIGHT = np.array([0.3, 0.2, 0.93])  # towards the light: from above


@dataclass(frozen=True)
class RoomLayout:
    """The room and its cameras.

    size_m : (x, y) extent of the floor, the origin at one corner; wall_height_m : up to the ceiling.
    camera_height_m, camera_inset_m : where the cameras hang in the corners; aim_height_m : they look
    at the room's centre at this height. image_size_px : (width, height); focal_px : in pixels.
    """

    size_m: tuple[float, float] = (5.0, 6.0)
    wall_height_m: float = 3.0
    camera_height_m: float = 2.8
    camera_inset_m: float = 0.1
    aim_height_m: float = 0.9
    image_size_px: tuple[int, int] = (1024, 768)
    focal_px: float = 500.0
    frame_rate_hz: float = 15.0


def look_at(centre_m, target_m, focal_px: float, image_size_px) -> PinholeCalibration:
    """A distortion-free pinhole camera at ``centre_m`` looking at ``target_m``, image x level with the floor."""
    forward = np.asarray(target_m, dtype=float) - np.asarray(centre_m, dtype=float)
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    R = np.stack([right, np.cross(forward, right), forward])
    width_px, height_px = image_size_px
    K = np.array([[focal_px, 0.0, width_px / 2], [0.0, focal_px, height_px / 2], [0.0, 0.0, 1.0]])
    return PinholeCalibration(K=K, dist=np.zeros(5), R=R, t=-R @ np.asarray(centre_m, dtype=float) * 1000.0)


def room_cameras(layout: RoomLayout) -> list[PinholeCalibration]:
    """The four corner cameras, counter-clockwise from the origin's corner."""
    (width_m, depth_m), inset = layout.size_m, layout.camera_inset_m
    corners = [(inset, inset), (width_m - inset, inset), (width_m - inset, depth_m - inset), (inset, depth_m - inset)]
    target = (width_m / 2, depth_m / 2, layout.aim_height_m)
    return [look_at((x, y, layout.camera_height_m), target, layout.focal_px, layout.image_size_px) for x, y in corners]


def _texture(rng: np.random.Generator, size: int, grains: int) -> np.ndarray:
    """A smooth random grey texture (size, size) float32 in about [-1, 1]: noise of ``grains`` x ``grains``
    cells, upsampled bicubically, plus fine grain."""
    coarse = rng.uniform(-1, 1, (grains, grains)).astype(np.float32)
    smooth = cv2.resize(coarse, (size, size), interpolation=cv2.INTER_CUBIC)
    return 0.7 * smooth + 0.3 * rng.uniform(-1, 1, (size, size)).astype(np.float32)


def room_background(layout: RoomLayout, calibration: PinholeCalibration, rng: np.random.Generator) -> np.ndarray:
    """The empty room as the camera sees it: (height, width, 3) uint8 BGR.

    Every pixel's ray is cast to the nearest of the floor (0.5 m tiles of random shade with a
    texture), the walls (another texture, a skirting band) and the ceiling (plain).
    """
    width_px, height_px = layout.image_size_px
    u, v = np.meshgrid(np.arange(width_px) + 0.5, np.arange(height_px) + 0.5)
    centre_m, direction = pixel_rays(calibration, np.stack([u.ravel(), v.ravel()], axis=-1))
    size_x, size_y = layout.size_m
    planes = [(2, 0.0), (2, layout.wall_height_m), (0, 0.0), (0, size_x), (1, 0.0), (1, size_y)]
    with np.errstate(divide="ignore", invalid="ignore"):
        t_m = np.stack([(value - centre_m[axis]) / direction[:, axis] for axis, value in planes], axis=-1)
    t_m = np.where(t_m > 1e-6, t_m, np.inf)
    surface = np.argmin(t_m, axis=-1)
    point_m = centre_m + np.min(t_m, axis=-1)[:, None] * direction
    texture_px, texture = 512, _texture(rng, 512, 24)
    tiles = rng.uniform(0.75, 1.0, (64, 64))
    # Floor: tiles with a texture; walls: texture along the wall and up; ceiling: plain.
    along = np.where(surface >= 4, point_m[:, 0], point_m[:, 1])
    on_floor = surface == 0
    texture_u = np.where(on_floor, point_m[:, 0], along) / 4.0 * texture_px
    texture_v = np.where(on_floor, point_m[:, 1], point_m[:, 2]) / 4.0 * texture_px
    grain = cv2.remap(
        texture,
        np.mod(texture_u, texture_px).astype(np.float32).reshape(height_px, width_px),
        np.mod(texture_v, texture_px).astype(np.float32).reshape(height_px, width_px),
        cv2.INTER_LINEAR,
    ).ravel()
    tile = tiles[
        np.clip(np.floor(point_m[:, 0] / 0.5).astype(int), 0, 63),
        np.clip(np.floor(point_m[:, 1] / 0.5).astype(int), 0, 63),
    ]
    skirting = (surface >= 2) & (point_m[:, 2] < 0.12)
    grey = np.select(
        [on_floor, surface == 1, skirting],
        [tile * (150 + 35 * grain), np.full_like(grain, 200.0), 70 + 10 * grain],
        170 + 30 * grain,
    )
    tint = np.select([on_floor[:, None], (surface >= 2)[:, None]], [[0.95, 1.0, 1.05], [1.05, 1.0, 0.9]], 1.0)
    colour = np.clip(grey[:, None] * tint, 0, 255)
    return colour.reshape(height_px, width_px, 3).astype(np.uint8)


@dataclass(frozen=True)
class Outfit:
    """Colours (BGR) of a person's parts: legs, torso, skin, hair."""

    legs: tuple[int, int, int]
    torso: tuple[int, int, int]
    skin: tuple[int, int, int]
    hair: tuple[int, int, int]


def random_outfit(rng: np.random.Generator) -> Outfit:
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
    """The background with the people painted over it, far facets first (painter's algorithm).

    people_cones : per person, what :func:`body_cones` returns; outfits : per person.
    """
    image = background.copy()
    if not people_cones:
        return image
    centre_m = -calibration.R.T @ calibration.t / 1000.0
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
    in_front = (corners @ calibration.R.T + calibration.t / 1000.0)[..., 2].min(axis=-1) > 0.05
    corners, shades, depth = corners[in_front], shades[in_front], depth[in_front]
    pixels = project_pinhole(calibration, corners.reshape(-1, 3) * 1000.0).reshape(-1, 4, 2)
    # cv2 puts pixel (i, j)'s centre at (i, j); ptztrack's pixel coordinates put it at (i + 0.5, j + 0.5).
    fixed = np.round((pixels - 0.5) * 16).astype(np.int32)
    for index in np.argsort(-depth):
        cv2.fillConvexPoly(image, fixed[index], tuple(float(value) for value in shades[index]), cv2.LINE_AA, 4)
    return image


class RoomRenderer:
    """The frames of the room's cameras: ``image(view, frame)`` (height, width, 3) uint8 BGR.

    layout : the room; truth : the people (positions, heights, widths); seed : fixes the textures,
    outfits and sensor noise (a frame's noise is the same however often it is rendered).
    """

    def __init__(self, layout: RoomLayout, truth: GroundTruth, seed: int):
        self.layout, self.truth = layout, truth
        self.cameras = room_cameras(layout)
        self.seed = seed
        texture_seed, outfit_seed, noise_seed = np.random.SeedSequence(seed).spawn(3)
        texture_rng = np.random.default_rng(texture_seed)
        self.backgrounds = [room_background(layout, camera, texture_rng) for camera in self.cameras]
        outfit_rng = np.random.default_rng(outfit_seed)
        self.outfits = [random_outfit(outfit_rng) for _ in range(truth.positions_m.shape[1])]
        noise_rng = np.random.default_rng(noise_seed)
        width_px, height_px = layout.image_size_px
        self.noise = noise_rng.normal(0, NOISE_SIGMA, (NOISE_FRAMES, height_px, width_px, 1)).astype(np.float32)
        self.heading_rad, self.phase_rad = _gait(truth)

    def people_cones(self, frame: int) -> list:
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
        present = np.flatnonzero(self.truth.present[frame])
        drawn = draw_people(
            self.backgrounds[view],
            self.cameras[view],
            self.people_cones(frame),
            [self.outfits[person] for person in present],
        )
        rng = np.random.default_rng([self.seed, view, frame])
        noise = self.noise[rng.integers(NOISE_FRAMES)]
        return np.clip(drawn + noise, 0, 255).astype(np.uint8)


def _gait(truth: GroundTruth) -> tuple[np.ndarray, np.ndarray]:
    """Heading (T, N) rad from each person's motion, and gait phase (T, N) rad from the distance walked."""
    step_m = np.diff(truth.positions_m, axis=0, prepend=truth.positions_m[:1])
    step_m[0] = step_m[1] if len(step_m) > 1 else 0.0
    heading = np.arctan2(step_m[..., 1], step_m[..., 0])
    walked_m = np.nancumsum(np.linalg.norm(np.nan_to_num(step_m), axis=-1), axis=0)
    return heading, 2 * np.pi * walked_m / STRIDE_M


def room_truth(layout: RoomLayout, people: int, frames: int, seed: int) -> GroundTruth:
    """People walking in the room for ``frames`` frames: 0.5-1.2 m/s (indoor walking), 1.6-1.9 m tall,
    0.5 m wide, present throughout."""
    crowd = Crowd(
        count=people,
        paired_fraction=0.0,
        pair_spacing_m=0.0,
        speed_m_s=(0.5, 1.2),
        height_m=(1.6, 1.9),
        width_m=0.5,
        turn_rate_sigma_deg_s=40.0,
        enter_leave=False,
        stay_s=(1.0, 1.0),
    )
    return walk_people(crowd, layout.size_m, frames, layout.frame_rate_hz, np.random.default_rng(seed))
