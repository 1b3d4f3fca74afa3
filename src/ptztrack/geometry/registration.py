"""Where a PTZ camera looks, from its image: SIFT registration against bundle-adjusted reference views.

The scale-invariant tracking paper (its section 3): reference views I_l cover
the field of regard; each is tied to a common reference plane by a
bundle-adjusted homography H_l, and the reference plane to the ground by H_W.
A live view I_t is matched (SIFT, ratio test) against all of them, the view
I_m with most matches gives the RANSAC homography H_t, and the live view's
image-to-ground map is the composition of equation 1. The reading chosen:

* H_t maps live pixels to reference-view pixels, H_m reference pixels to the
  reference plane, H_W the reference plane to the ground, so
  image-to-ground = H_W H_m H_t (the paper writes G_t = H_W H_mj^-1 H_t with
  H_mj in the other direction).
* The camera turns about its optical centre, whose position the ground
  calibration gives, so the reference plane is the plane at infinity: H_l =
  R_l^T K_l^-1 takes a pixel to its world ray, and H_W intersects rays from
  the centre with the ground.
* The focal length of the live view (equation 2): with H the homography from
  reference to live pixels in coordinates centred on the principal point,
  H K_m K_m^T H^T = s K_t K_t^T; K = diag(f, f, 1) gives
  f_t^2 = (A_11 + A_22) / (2 A_33) for A = H diag(f_m^2, f_m^2, 1) H^T. The
  printed equation 3 puts h_21, h_22, h_22 in the denominator where the
  third row h_31, h_32, h_33 belongs.
* The rotation then follows from K_t^-1 H K_m R_m (orthogonalised), and with
  it the live pose (pan, tilt, zoom) of the one camera model, whose
  homographies and head/feet homology the tracker uses unchanged.
"""

import io
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np
from scipy.optimize import least_squares
from scipy.sparse import lil_matrix

from ptztrack.files import write_atomically
from ptztrack.geometry.ptz import PTZCamera, intrinsics, rotation_world_to_camera

RATIO_TEST = 0.75
RANSAC_THRESHOLD_PX = 3.0
MIN_INLIERS = 12
# Correspondences per pair of reference views that bundle adjustment uses (evenly spread over the
# inliers): enough to pin three parameters per view many times over, few enough to stay fast.
BUNDLE_POINTS_PER_PAIR = 40


@dataclass(frozen=True)
class ReferenceIndex:
    """Reference views: their bundle-adjusted poses and their SIFT features.

    poses : (L, 3) (pan_deg, tilt_deg, zoom) of each reference view.
    keypoints_px : (F, 2) feature positions; descriptors : (F, 128) float32; view : (F,) reference view of each.
    image_size_px : (width, height) of the views.
    """

    poses: np.ndarray
    keypoints_px: np.ndarray
    descriptors: np.ndarray
    view: np.ndarray
    image_size_px: tuple[int, int]
    matcher: cv2.FlannBasedMatcher = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        # One k-d tree forest over every reference descriptor: a live view is matched against all
        # reference views at once, in tens of milliseconds rather than a brute-force second.
        matcher = cv2.FlannBasedMatcher({"algorithm": 1, "trees": 4}, {"checks": 64})
        matcher.add([self.descriptors])
        matcher.train()
        object.__setattr__(self, "matcher", matcher)


def sift_features(image_bgr: np.ndarray, features: int = 1000) -> tuple[np.ndarray, np.ndarray]:
    """Keypoint positions (K, 2) px and descriptors (K, 128) float32 of an image."""
    gray = cv2.cvtColor(image_bgr, cv2.COLOR_BGR2GRAY)
    keypoints, descriptors = cv2.SIFT_create(nfeatures=features).detectAndCompute(gray, None)
    if descriptors is None:
        return np.zeros((0, 2)), np.zeros((0, 128), dtype=np.float32)
    return np.array([k.pt for k in keypoints], dtype=float), descriptors


def ratio_matches(query: np.ndarray, train: np.ndarray, ratio: float = RATIO_TEST) -> np.ndarray:
    """(M, 2) index pairs (query, train) whose nearest neighbour is clearly nearer than the second (Lowe)."""
    if len(query) < 2 or len(train) < 2:
        return np.zeros((0, 2), dtype=int)
    pairs = cv2.BFMatcher(cv2.NORM_L2).knnMatch(query, train, k=2)
    good = [(m.queryIdx, m.trainIdx) for m, n in pairs if m.distance < ratio * n.distance]
    return np.array(good, dtype=int).reshape(-1, 2)


def rotation_homography(camera: PTZCamera, from_pose, to_pose) -> np.ndarray:
    """Pixels of a view at ``from_pose`` to pixels of a view at ``to_pose`` (same centre): K_b R_b R_a^T K_a^-1."""
    from_pose, to_pose = np.asarray(from_pose, float), np.asarray(to_pose, float)
    R_a = rotation_world_to_camera(from_pose[..., 0], from_pose[..., 1])
    R_b = rotation_world_to_camera(to_pose[..., 0], to_pose[..., 1])
    return intrinsics(camera, to_pose[..., 2]) @ R_b @ np.swapaxes(R_a, -1, -2) @ np.linalg.inv(
        intrinsics(camera, from_pose[..., 2])
    )


def bundle_adjust(camera: PTZCamera, initial_poses, matches: list[tuple[int, int, np.ndarray, np.ndarray]]) -> np.ndarray:
    """Refine the poses of views that share matches, jointly (``scipy.optimize.least_squares``).

    initial_poses : (L, 3); the first view's pose is held fixed (it fixes the gauge: its pose is the
    calibrated one). matches : (i, j, points_i (M, 2), points_j (M, 2)) inlier correspondences.
    Minimises the reprojection error of every correspondence through the rotating-and-zooming
    camera model, with a robust (soft L1, 1 px) loss. Returns (L, 3) poses.
    """
    initial_poses = np.asarray(initial_poses, dtype=float)
    first = np.concatenate([np.full(len(m[2]), m[0]) for m in matches])
    second = np.concatenate([np.full(len(m[2]), m[1]) for m in matches])
    points_first = np.concatenate([m[2] for m in matches])
    points_second = np.concatenate([m[3] for m in matches])

    def residuals(free):
        poses = np.vstack([initial_poses[:1], free.reshape(-1, 3)])
        # All views' homographies to a common frame at once: pixel -> world ray, R^T K^-1.
        to_ray = np.swapaxes(rotation_world_to_camera(poses[:, 0], poses[:, 1]), -1, -2) @ np.linalg.inv(
            intrinsics(camera, poses[:, 2])
        )
        from_ray = np.linalg.inv(to_ray)
        rays = np.einsum("nij,nj->ni", to_ray[first], np.c_[points_first, np.ones(len(first))])
        projected = np.einsum("nij,nj->ni", from_ray[second], rays)
        return (projected[:, :2] / projected[:, 2:] - points_second).ravel()

    # Each correspondence depends on the poses of its two views only: telling least_squares so lets it
    # estimate the Jacobian with a few grouped differences instead of one per parameter.
    sparsity = lil_matrix((2 * len(first), 3 * (len(initial_poses) - 1)), dtype=int)
    for views in (first, second):
        for view in np.unique(views[views > 0]):
            rows = np.flatnonzero(np.repeat(views == view, 2))
            for column in range(3 * (view - 1), 3 * view):
                sparsity[rows, column] = 1
    result = least_squares(
        residuals, initial_poses[1:].ravel(), jac_sparsity=sparsity, loss="soft_l1", f_scale=1.0, x_scale="jac"
    )
    return np.vstack([initial_poses[:1], result.x.reshape(-1, 3)])


def pairwise_matches(keypoints: list, descriptors: list) -> list[tuple[int, int, np.ndarray, np.ndarray]]:
    """RANSAC-inlier correspondences (at most ``BUNDLE_POINTS_PER_PAIR``) between every pair of views with
    enough of them."""
    found = []
    for i in range(len(keypoints)):
        for j in range(i + 1, len(keypoints)):
            pairs = ratio_matches(descriptors[i], descriptors[j])
            if len(pairs) < MIN_INLIERS:
                continue
            points_i, points_j = keypoints[i][pairs[:, 0]], keypoints[j][pairs[:, 1]]
            _, inliers = cv2.findHomography(points_i, points_j, cv2.RANSAC, RANSAC_THRESHOLD_PX)
            if inliers is not None and inliers.sum() >= MIN_INLIERS:
                keep = np.flatnonzero(inliers.ravel())
                keep = keep[np.linspace(0, len(keep) - 1, min(len(keep), BUNDLE_POINTS_PER_PAIR)).astype(int)]
                found.append((i, j, points_i[keep], points_j[keep]))
    return found


def build_index(camera: PTZCamera, images: list[np.ndarray], initial_poses, features: int = 1000) -> ReferenceIndex:
    """Reference views of the field of regard: SIFT, pairwise homographies, bundle adjustment.

    images : the views, taken at poses known roughly (``initial_poses`` (L, 3), the first exactly).
    """
    extracted = [sift_features(image, features) for image in images]
    keypoints = [k for k, _ in extracted]
    descriptors = [d for _, d in extracted]
    poses = bundle_adjust(camera, initial_poses, pairwise_matches(keypoints, descriptors))
    return ReferenceIndex(
        poses=poses,
        keypoints_px=np.concatenate(keypoints),
        descriptors=np.concatenate(descriptors),
        view=np.concatenate([np.full(len(k), index) for index, k in enumerate(keypoints)]),
        image_size_px=(camera.image_width_px, camera.image_height_px),
    )


def save_index(path: str | Path, index: ReferenceIndex) -> None:
    """Write the index as a .npz, atomically (through a temporary file and a rename)."""
    path = Path(path)
    buffer = io.BytesIO()
    np.savez_compressed(
        buffer,
        poses=index.poses,
        keypoints_px=index.keypoints_px,
        descriptors=index.descriptors,
        view=index.view,
        image_size_px=np.asarray(index.image_size_px),
    )
    write_atomically(path, buffer.getvalue())


def load_index(path: str | Path) -> ReferenceIndex:
    """Read an index written by :func:`save_index`; a missing or malformed file raises ValueError naming it."""
    try:
        with np.load(path) as data:
            return ReferenceIndex(
                poses=data["poses"],
                keypoints_px=data["keypoints_px"],
                descriptors=data["descriptors"],
                view=data["view"],
                image_size_px=tuple(int(x) for x in data["image_size_px"]),
            )
    except FileNotFoundError:
        raise ValueError(f"{path}: no such registration index") from None
    except (KeyError, ValueError, OSError) as error:
        raise ValueError(f"{path}: not a registration index ({error})") from None


def focal_from_homography(H_reference_to_live: np.ndarray, reference_focal_px: float) -> float:
    """Equation 2 solved for the live focal length; H in pixel coordinates centred on the principal point."""
    A = H_reference_to_live @ np.diag([reference_focal_px**2, reference_focal_px**2, 1.0]) @ H_reference_to_live.T
    return float(np.sqrt((A[0, 0] + A[1, 1]) / (2.0 * A[2, 2])))


def pose_from_rotation(R: np.ndarray) -> tuple[float, float]:
    """(pan_deg, tilt_deg) of a world-to-camera rotation (its roll ignored: the mount is level)."""
    forward = R[2] / np.linalg.norm(R[2])
    return float(np.rad2deg(np.arctan2(forward[0], forward[1]))), float(np.rad2deg(np.arcsin(-forward[2])))


@dataclass(frozen=True)
class Registration:
    """A registered live view: the pose of the camera model that explains it, and how well.

    pose : (pan_deg, tilt_deg, zoom), from equation 2 and the homography's rotation, refined on the
    inliers; focal_px : its focal length; view : the reference view used;
    inliers : RANSAC inliers of H_t.
    """

    pose: np.ndarray
    focal_px: float
    view: int
    inliers: int


def register(camera: PTZCamera, index: ReferenceIndex, image_bgr: np.ndarray, features: int = 1000) -> Registration | None:
    """Register a live view against the index; None when no reference view shares enough features."""
    keypoints, descriptors = sift_features(image_bgr, features)
    if len(descriptors) < MIN_INLIERS:
        return None
    pairs = np.array(
        [(m.queryIdx, m.trainIdx) for m, n in index.matcher.knnMatch(descriptors, k=2) if m.distance < RATIO_TEST * n.distance],
        dtype=int,
    ).reshape(-1, 2)
    if len(pairs) < MIN_INLIERS:
        return None
    views = index.view[pairs[:, 1]]
    best = int(np.bincount(views).argmax())
    chosen = pairs[views == best]
    if len(chosen) < MIN_INLIERS:
        return None
    H_live_to_reference, inliers = cv2.findHomography(
        keypoints[chosen[:, 0]], index.keypoints_px[chosen[:, 1]], cv2.RANSAC, RANSAC_THRESHOLD_PX
    )
    if H_live_to_reference is None or inliers.sum() < MIN_INLIERS:
        return None
    reference_pose = index.poses[best]
    K_reference = intrinsics(camera, reference_pose[2])
    centred = np.array([[1.0, 0.0, -camera.principal_point_px[0]], [0.0, 1.0, -camera.principal_point_px[1]], [0, 0, 1]])
    H_reference_to_live = centred @ np.linalg.inv(H_live_to_reference) @ np.linalg.inv(centred)
    focal_px = focal_from_homography(H_reference_to_live, K_reference[0, 0])
    K_live = np.diag([focal_px, focal_px, 1.0])
    relative = np.linalg.inv(K_live) @ H_reference_to_live @ np.diag([K_reference[0, 0], K_reference[0, 0], 1.0])
    U, _, Vt = np.linalg.svd(relative)
    rotation = U @ Vt
    if np.linalg.det(rotation) < 0:
        rotation = -rotation
    R_live = rotation @ rotation_world_to_camera(reference_pose[0], reference_pose[1])
    pan_deg, tilt_deg = pose_from_rotation(R_live)
    keep = inliers.ravel().astype(bool)
    pose = refine_pose(
        camera,
        reference_pose,
        index.keypoints_px[chosen[keep, 1]],
        keypoints[chosen[keep, 0]],
        np.array([pan_deg, tilt_deg, focal_px / camera.f_min_px]),
    )
    return Registration(pose, pose[2] * camera.f_min_px, best, int(keep.sum()))


def refine_pose(camera: PTZCamera, reference_pose, reference_px, live_px, initial_pose) -> np.ndarray:
    """The live (pan_deg, tilt_deg, zoom) that best maps reference points (M, 2) onto live points (M, 2)
    through the rotating camera: 3 parameters instead of the homography's 8, so a few dozen
    correspondences pin the pose far better than the homography they came from."""

    def residuals(pose):
        H = rotation_homography(camera, reference_pose, pose)
        projected = reference_px @ H[:, :2].T + H[:, 2]
        return (projected[:, :2] / projected[:, 2:] - live_px).ravel()

    return least_squares(residuals, initial_pose, loss="soft_l1", f_scale=1.0, x_scale=[1.0, 1.0, 0.01]).x
