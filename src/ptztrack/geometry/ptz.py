"""The one PTZ camera model: poses, homographies, the head/feet homology, Jacobians.

Conventions
-----------
World frame: metres, the ground is the plane z = 0, z points up.
Camera frame: OpenCV's (x right, y down, z along the optical axis).
A pose is an array ``(..., 3)`` holding ``(pan_deg, tilt_deg, zoom)``:

* ``pan_deg`` turns about the vertical axis; 0 looks along world +y and a
  positive pan turns towards +x (clockwise seen from above);
* ``tilt_deg`` is the depression of the optical axis below the horizon, so a
  positive tilt looks down;
* ``zoom = f / f_min``; the focal length in pixels is ``zoom * f_min_px``.

The camera turns about its own optical centre (no roll, no offset), which is
the model of both a real PTZ head and the paper's virtual camera. Every
function broadcasts over leading axes: ``poses`` of shape ``(*P, 3)`` go with
ground points of shape ``(*P, N, 2)`` (or anything that broadcasts to it).
"""

import functools
from dataclasses import dataclass

import numpy as np

PAN, TILT, ZOOM = 0, 1, 2


@dataclass(frozen=True)
class PTZCamera:
    """A PTZ camera mounted at a known position above the ground.

    Attributes
    ----------
    position_m : (3,) optical centre (x, y, z) in world metres, z > 0.
    image_width_px, image_height_px : image size; the principal point is its centre.
    f_min_px : focal length in pixels at zoom 1 (the widest view).
    """

    position_m: tuple[float, float, float]
    image_width_px: int
    image_height_px: int
    f_min_px: float

    @property
    def centre_m(self) -> np.ndarray:
        return np.asarray(self.position_m, dtype=float)

    @property
    def principal_point_px(self) -> np.ndarray:
        return np.array([self.image_width_px / 2.0, self.image_height_px / 2.0])


def pose_noise_px2(camera: PTZCamera, pose, pose_sd) -> np.ndarray:
    """The pixel noise (2, 2) px^2 that an error of standard deviation ``pose_sd`` (3,) (deg, deg, zoom
    factor) in the pose (3,) adds to a point of the image, the errors independent:

        V_pose = diag((f cos(tilt) s_pan)^2 + (w s_zoom / z)^2 / 12,  (f s_tilt)^2 + (h s_zoom / z)^2 / 12),

    with ``f`` the focal length (px) at zoom ``z`` and ``s_pan``, ``s_tilt`` in radians: a pan (about the
    vertical, at ``cos(tilt)`` to the image plane) and a tilt move the image centre by that many px, and a
    zoom scales the image about its centre, which moves a point spread evenly over a ``w`` x ``h`` image
    by ``w / sqrt(12)`` (``h / sqrt(12)``) px per unit of relative zoom, root mean square."""
    pan_sd, tilt_sd, zoom_sd = np.asarray(pose_sd, dtype=float)
    _, tilt_deg, zoom = np.asarray(pose, dtype=float)
    focal_px = zoom * camera.f_min_px
    relative_zoom_sd = zoom_sd / zoom
    return np.diag(
        [
            (focal_px * np.cos(np.deg2rad(tilt_deg)) * np.deg2rad(pan_sd)) ** 2
            + (camera.image_width_px * relative_zoom_sd) ** 2 / 12,
            (focal_px * np.deg2rad(tilt_sd)) ** 2 + (camera.image_height_px * relative_zoom_sd) ** 2 / 12,
        ]
    )


def rotation_world_to_camera(pan_deg, tilt_deg) -> np.ndarray:
    """Rotation ``R`` with ``X_cam = R (X_world - C)``; shape ``(*P, 3, 3)``.

    Its rows are the camera's right, down and forward axes in world coordinates.
    """
    pan = np.deg2rad(np.asarray(pan_deg, dtype=float))
    tilt = np.deg2rad(np.asarray(tilt_deg, dtype=float))
    cp, sp, ct, st = np.cos(pan), np.sin(pan), np.cos(tilt), np.sin(tilt)
    zero = np.zeros_like(pan)
    right = np.stack([cp, -sp, zero], axis=-1)
    forward = np.stack([ct * sp, ct * cp, -st * np.ones_like(pan)], axis=-1)
    down = np.cross(forward, right)
    return np.stack([right, down, forward], axis=-2)


def intrinsics(camera: PTZCamera, zoom) -> np.ndarray:
    """Intrinsic matrix ``K`` at the given zoom; shape ``(*P, 3, 3)``."""
    focal_px = np.asarray(zoom, dtype=float) * camera.f_min_px
    cx, cy = camera.principal_point_px
    K = np.zeros(focal_px.shape + (3, 3))
    K[..., 0, 0] = focal_px
    K[..., 1, 1] = focal_px
    K[..., 0, 2] = cx
    K[..., 1, 2] = cy
    K[..., 2, 2] = 1.0
    return K


def projection_matrix(camera: PTZCamera, poses) -> np.ndarray:
    """World-to-image projection ``P = K R [I | -C]``; shape ``(*P, 3, 4)``.

    One pose's matrix is remembered (:func:`_pose_projection`, read-only): a tracker's update and a
    simulated camera's look ask for the same pose's matrix a dozen times, and building it from the
    angles cost more than the update's own arithmetic with a network's 64 cameras.
    """
    poses = np.asarray(poses, dtype=float)
    if poses.shape == (3,):
        return _pose_projection(camera, float(poses[PAN]), float(poses[TILT]), float(poses[ZOOM]))
    return _projection_matrix(camera, poses)


def _projection_matrix(camera: PTZCamera, poses: np.ndarray) -> np.ndarray:
    R = rotation_world_to_camera(poses[..., PAN], poses[..., TILT])
    K = intrinsics(camera, poses[..., ZOOM])
    KR = K @ R
    translation = -KR @ camera.centre_m
    return np.concatenate([KR, translation[..., None]], axis=-1)


# Enough for every pose of a step of a 64-camera network, and each camera's next few.
@functools.lru_cache(maxsize=4096)
def _pose_projection(camera: PTZCamera, pan_deg: float, tilt_deg: float, zoom: float) -> np.ndarray:
    """:func:`_projection_matrix` of the one pose (3, 4), the same numbers, shared and so read-only."""
    P = _projection_matrix(camera, np.array([pan_deg, tilt_deg, zoom]))
    P.flags.writeable = False
    return P


def plane_homography(camera: PTZCamera, poses, height_m=0.0) -> np.ndarray:
    """Homography from the horizontal plane ``z = height_m`` to the image.

    Maps ``(x, y, 1)`` on that plane to homogeneous pixels; shape ``(*P, 3, 3)``.
    ``height_m`` broadcasts against the pose axes.
    """
    P = projection_matrix(camera, poses)
    height_m = np.asarray(height_m, dtype=float)[..., None]
    return np.stack([P[..., 0], P[..., 1], P[..., 3] + height_m * P[..., 2]], axis=-1)


def ground_to_image(camera: PTZCamera, poses) -> np.ndarray:
    """The ground-plane homography ``g`` of the paper; shape ``(*P, 3, 3)``."""
    return plane_homography(camera, poses, 0.0)


def image_to_ground(camera: PTZCamera, poses) -> np.ndarray:
    """Inverse of :func:`ground_to_image`; shape ``(*P, 3, 3)``."""
    return np.linalg.inv(ground_to_image(camera, poses))


def apply_homography(H, points) -> np.ndarray:
    """Map 2-D points through homographies.

    H : (*P, 3, 3); points : (*P, N, 2). Returns (*P, N, 2). Points that map
    to the line at infinity come out as inf or nan.
    """
    points = np.asarray(points, dtype=float)
    homogeneous = H[..., None, :, :2] @ points[..., :, None] + H[..., None, :, 2:]
    homogeneous = homogeneous[..., 0]
    return homogeneous[..., :2] / homogeneous[..., 2:]


def head_from_feet_homology(camera: PTZCamera, poses, height_m) -> np.ndarray:
    """The homology ``W`` mapping a feet pixel to the head pixel of a person
    ``height_m`` tall standing there: ``W = H_h H_0^-1``; shape ``(*P, 3, 3)``."""
    return plane_homography(camera, poses, height_m) @ image_to_ground(camera, poses)


def pixels_to_ground(camera: PTZCamera, pose, pixels) -> np.ndarray:
    """The ground points (N, 2) m that the pixels (N, 2) of the view at ``pose`` (3,) see; NaN where a
    pixel's ray does not come down to the ground (at or above the horizon).

    :func:`image_to_ground` maps a pixel above the horizon to the point behind the camera where its
    ray, extended backwards, meets the ground; here such pixels see no ground.
    """
    pixels = np.asarray(pixels, dtype=float).reshape(-1, 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        ground_m = apply_homography(image_to_ground(camera, pose), pixels)
        in_front = camera_depth_m(camera, pose, np.c_[ground_m, np.zeros(len(ground_m))]) > 0
    return np.where(in_front[:, None], ground_m, np.nan)


def standing_height_px(camera: PTZCamera, pose, height_m: float, feet_px) -> np.ndarray:
    """The image height (N,) px of a person ``height_m`` tall standing on feet pixels (N, 2) at ``pose``
    (3,): the distance from the feet to the projected head; NaN where the feet's ray meets the ground
    behind the camera (above the horizon) or the head is behind it."""
    feet_px = np.asarray(feet_px, dtype=float)
    ground_m = pixels_to_ground(camera, pose, feet_px)
    head_px = apply_homography(plane_homography(camera, pose, height_m), ground_m)
    head_in_front = camera_depth_m(camera, pose, np.c_[ground_m, np.full(len(ground_m), height_m)]) > 0
    return np.where(head_in_front, np.linalg.norm(head_px - feet_px, axis=-1), np.nan)


def homography_jacobian(H, points) -> np.ndarray:
    """Jacobian of ``p -> H p`` (inhomogeneous) at ``points``.

    H : (*P, 3, 3); points : (*P, N, 2). Returns (*P, N, 2, 2): rows are the
    output coordinates, columns the input ones.
    """
    H = np.asarray(H, dtype=float)[..., None, :, :]
    points = np.asarray(points, dtype=float)
    homogeneous = H[..., :, :2] @ points[..., :, None] + H[..., :, 2:]
    w = homogeneous[..., 2, :]
    mapped = homogeneous[..., :2, :] / w[..., None, :]
    return (H[..., :2, :2] - mapped * H[..., 2:, :2]) / w[..., None, :]


def feet_jacobian(camera: PTZCamera, poses, ground_xy) -> np.ndarray:
    """Jacobian of the feet pixel ``(u, v)`` with respect to the ground point ``(x, y)``.

    The position block of the EKF's observation matrix ``C_x(a)``.
    ground_xy : (*P, N, 2) metres. Returns (*P, N, 2, 2) in pixels per metre,
    rows (u, v), columns (x, y).
    """
    return homography_jacobian(ground_to_image(camera, poses), ground_xy)


def camera_depth_m(camera: PTZCamera, poses, points_m) -> np.ndarray:
    """Depth along the optical axis of world points (*P, N, 3); returns (*P, N)."""
    poses = np.asarray(poses, dtype=float)
    R = rotation_world_to_camera(poses[..., PAN], poses[..., TILT])
    forward = R[..., 2, :]
    return np.sum((np.asarray(points_m, dtype=float) - camera.centre_m) * forward[..., None, :], axis=-1)


@dataclass(frozen=True)
class ProjectedPeople:
    """Standing people seen at a pose; leading axes ``(*P, N)``.

    feet_px, head_px : (*P, N, 2) pixels.
    box_px : (*P, N, 4) as (left, top, right, bottom) pixels.
    depth_m, head_depth_m : (*P, N) depth of the feet and of the head along
        the optical axis (> 0 in front).
    range_m : (*P, N) distance from the optical centre to the middle of the
        body: who hides whom along a ray, whatever the pose.
    """

    feet_px: np.ndarray
    head_px: np.ndarray
    box_px: np.ndarray
    depth_m: np.ndarray
    head_depth_m: np.ndarray
    range_m: np.ndarray

    @property
    def in_front(self) -> np.ndarray:
        """Feet and head both in front of the camera: only then is the box meaningful."""
        return (self.depth_m > 0) & (self.head_depth_m > 0)

    @property
    def height_px(self) -> np.ndarray:
        return self.box_px[..., 3] - self.box_px[..., 1]


def project_people(camera: PTZCamera, poses, ground_xy, height_m, width_m) -> ProjectedPeople:
    """Project people (feet at ``ground_xy``, ``height_m`` tall, ``width_m`` wide) to boxes.

    ground_xy : (*P, N, 2); height_m, width_m : (*P, N) or broadcastable.
    The box spans the rows of the feet and the head and is as wide as the
    person seen at the mean depth of feet and head, centred between them. A
    person off the image centre leans in the image; the box then has the
    area of the leaning outline (a parallelogram), where a bounding box
    would be too wide by the lean, more so the farther from the centre.
    """
    poses = np.asarray(poses, dtype=float)
    ground_xy = np.asarray(ground_xy, dtype=float)
    height_m = np.broadcast_to(np.asarray(height_m, dtype=float), ground_xy.shape[:-1])
    feet_m = np.concatenate([ground_xy, np.zeros_like(ground_xy[..., :1])], axis=-1)
    head_m = feet_m + np.stack([np.zeros_like(height_m)] * 2 + [height_m], axis=-1)
    P = projection_matrix(camera, poses)[..., None, :, :]

    def project(points_m):
        homogeneous = (P[..., :3] @ points_m[..., None] + P[..., 3:])[..., 0]
        return homogeneous[..., :2] / homogeneous[..., 2:], homogeneous[..., 2]

    # A point in the camera's own plane (depth 0) projects to infinity; ``in_front`` flags it.
    with np.errstate(divide="ignore", invalid="ignore"):
        feet_px, feet_depth_m = project(feet_m)
        head_px, head_depth_m = project(head_m)
        focal_px = poses[..., ZOOM, None] * camera.f_min_px
        half_width_px = 0.5 * focal_px * np.asarray(width_m, dtype=float) / (0.5 * (feet_depth_m + head_depth_m))
    middle_u_px = 0.5 * (feet_px[..., 0] + head_px[..., 0])
    box_px = np.stack(
        [
            middle_u_px - half_width_px,
            np.minimum(feet_px[..., 1], head_px[..., 1]),
            middle_u_px + half_width_px,
            np.maximum(feet_px[..., 1], head_px[..., 1]),
        ],
        axis=-1,
    )
    range_m = np.linalg.norm(0.5 * (feet_m + head_m) - camera.centre_m, axis=-1)
    range_m = np.broadcast_to(range_m, feet_depth_m.shape)
    return ProjectedPeople(
        feet_px=feet_px,
        head_px=head_px,
        box_px=box_px,
        depth_m=feet_depth_m,
        head_depth_m=head_depth_m,
        range_m=range_m,
    )


def inside_image(camera: PTZCamera, pixels) -> np.ndarray:
    """Whether pixels (..., 2) fall inside the image; returns (...) bool."""
    pixels = np.asarray(pixels, dtype=float)
    return (
        (pixels[..., 0] >= 0)
        & (pixels[..., 0] <= camera.image_width_px)
        & (pixels[..., 1] >= 0)
        & (pixels[..., 1] <= camera.image_height_px)
    )


def person_in_view(camera: PTZCamera, people: ProjectedPeople) -> np.ndarray:
    """Whether each person stands in front of the camera with head and feet in the image; (*P, N)."""
    return people.in_front & inside_image(camera, people.feet_px) & inside_image(camera, people.head_px)


def look_at(camera: PTZCamera, target_xy, zoom=1.0) -> np.ndarray:
    """The pose whose optical axis passes through the ground point(s) ``target_xy`` (..., 2)."""
    target_xy = np.asarray(target_xy, dtype=float)
    offset = target_xy - camera.centre_m[:2]
    pan_deg = np.rad2deg(np.arctan2(offset[..., 0], offset[..., 1]))
    tilt_deg = np.rad2deg(np.arctan2(camera.centre_m[2], np.linalg.norm(offset, axis=-1)))
    return np.stack([pan_deg, tilt_deg, np.broadcast_to(zoom, pan_deg.shape)], axis=-1)


def rotation_homography(camera: PTZCamera, from_poses, to_poses) -> np.ndarray:
    """The homography ``K2 R2 R1^T K1^-1`` taking pixels of the view at ``from_poses`` to the view at ``to_poses``.

    The camera turns about its optical centre, so every point of the scene (near or far) maps
    through it. Poses broadcast; shape ``(*P, 3, 3)``.
    """
    from_poses, to_poses = np.asarray(from_poses, dtype=float), np.asarray(to_poses, dtype=float)
    R1 = rotation_world_to_camera(from_poses[..., PAN], from_poses[..., TILT])
    R2 = rotation_world_to_camera(to_poses[..., PAN], to_poses[..., TILT])
    K1_inv = np.linalg.inv(intrinsics(camera, from_poses[..., ZOOM]))
    return intrinsics(camera, to_poses[..., ZOOM]) @ R2 @ np.swapaxes(R1, -1, -2) @ K1_inv


def aim_at(camera: PTZCamera, points_m, pixels_px, zoom) -> np.ndarray:
    """The poses at ``zoom`` that show the world points ``points_m`` (..., 3) at the pixels ``pixels_px`` (..., 2).

    Returns (..., 3) (pan_deg, tilt_deg, zoom). In closed form: with the pixel's ray
    ``(a, b, 1)`` in the camera frame and the point seen at depression ``delta`` below the
    horizon, the ray's depression at tilt ``phi`` satisfies ``tan delta = (b cos phi + sin phi) /
    sqrt(a^2 + (cos phi - b sin phi)^2)``, whose solution is ``phi = psi - atan b`` with
    ``cos^2 psi = cos^2 delta - a^2 sin^2 delta / (1 + b^2)``; the pan then turns the ray's
    azimuth, ``atan2(a, cos phi - b sin phi)`` to the right of the optical axis, onto the
    point's. Where no tilt within +-90 deg brings the pixel's ray down (or up) to the point (a
    point nearly below the camera, a pixel far from the image's vertical centre line), there is
    no such pose, and the one returned turns the pixel's ray as steeply as it goes (psi = +-90 deg).
    """
    points_m, pixels_px = np.asarray(points_m, dtype=float), np.asarray(pixels_px, dtype=float)
    zoom = np.asarray(zoom, dtype=float)
    ray = (pixels_px - camera.principal_point_px) / (zoom * camera.f_min_px)[..., None]
    a, b = ray[..., 0], ray[..., 1]
    offset = points_m - camera.centre_m
    horizontal_m = np.hypot(offset[..., 0], offset[..., 1])
    depression = np.arctan2(-offset[..., 2], horizontal_m)
    cos_psi_squared = np.cos(depression) ** 2 - a**2 * np.sin(depression) ** 2 / (1 + b**2)
    psi = np.sign(depression) * np.arccos(np.sqrt(np.clip(cos_psi_squared, 0.0, 1.0)))
    tilt = psi - np.arctan(b)
    pan = np.arctan2(offset[..., 0], offset[..., 1]) - np.arctan2(a, np.cos(tilt) - b * np.sin(tilt))
    pan_deg = (np.rad2deg(pan) + 180.0) % 360.0 - 180.0
    return np.stack([pan_deg, np.rad2deg(tilt), np.broadcast_to(zoom, pan_deg.shape)], axis=-1)


def ground_footprint(camera: PTZCamera, poses, points_per_edge: int = 16, max_range_m: float = 60.0) -> np.ndarray:
    """The field of view on the ground: a polygon (*P, 4 * points_per_edge, 2) in metres.

    The image border is sampled and each pixel's ray is cut with the ground.
    Rays at or above the horizon, or meeting the ground beyond ``max_range_m``,
    stop at that horizontal range, so a view of the horizon gives a finite
    polygon.
    """
    poses = np.asarray(poses, dtype=float)
    w, h = camera.image_width_px, camera.image_height_px
    s = np.linspace(0.0, 1.0, points_per_edge, endpoint=False)
    border_px = np.concatenate(
        [
            np.stack([s * w, np.zeros_like(s)], -1),
            np.stack([np.full_like(s, w), s * h], -1),
            np.stack([(1 - s) * w, np.full_like(s, h)], -1),
            np.stack([np.zeros_like(s), (1 - s) * h], -1),
        ]
    )
    R = rotation_world_to_camera(poses[..., PAN], poses[..., TILT])
    K_inv = np.linalg.inv(intrinsics(camera, poses[..., ZOOM]))
    border_h = np.concatenate([border_px, np.ones((len(border_px), 1))], axis=-1)
    rays = np.einsum("...ji,...jk,nk->...ni", R, K_inv, border_h)
    height_m = camera.centre_m[2]
    horizontal = np.linalg.norm(rays[..., :2], axis=-1)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        range_m = np.where(rays[..., 2] < 0, height_m * horizontal / -rays[..., 2], np.inf)
    range_m = np.minimum(range_m, max_range_m)
    return camera.centre_m[:2] + rays[..., :2] / horizontal[..., None] * range_m[..., None]
