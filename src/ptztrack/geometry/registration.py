"""Where a PTZ camera looks, from its image: SIFT registration against bundle-adjusted reference views.

The scale-invariant tracking paper (its section 3): reference views I_l cover
the field of regard; each is tied to a common reference plane by a
bundle-adjusted homography H_l, and the reference plane to the ground by H_W.
A live view I_t is matched (SIFT, ratio test within each view) against all
of them, the view I_m with most RANSAC inliers (of the two with most
matches) gives the homography H_t, and the live view's image-to-ground map
is the composition of equation 1. The reading chosen:

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
* A real camera's live view is rolled and radially distorted
  (:mod:`ptztrack.geometry.lens`), so the pose is refined together with the
  view's roll and distortion (k1) on the inliers; the tracker's model keeps
  (pan, tilt, zoom). The principal point is not estimated: off the centre
  by d pixels it shifts the view as a turn of d / f does, and a view a few
  tens of degrees wide or narrower cannot tell the two apart, so the
  registered pose absorbs it, which places the view's own pixels right.
"""

import io
import zipfile
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import networkx as nx
import numpy as np
from scipy.optimize import least_squares
from scipy.sparse import lil_matrix

from ptztrack.files import InputError, shown, write_atomically
from ptztrack.geometry.lens import Lens, corner_radius2, pixel_directions, project_directions
from ptztrack.geometry.ptz import PTZCamera, inside_image, intrinsics, rotation_world_to_camera

RATIO_TEST = 0.75
RANSAC_THRESHOLD_PX = 3.0
MIN_INLIERS = 12
# SIFT runs on an image wider than SIFT_HALVED_FROM_PX halved: OpenCV's SIFT doubles its input first, so
# at full size a 640 x 480 view costs over 100 ms, and a PTZ view zoomed past the recording's resolution
# holds no detail at the finest scales anyway. A narrower image (a 160 x 120 stream) keeps its size: halved
# it holds a few dozen features. Keypoints are reported in full-size pixels.
SIFT_IMAGE_SCALE = 0.5
SIFT_HALVED_FROM_PX = 320
# A PTZ view zoomed in on the recording is an enlarged, blurred image: at SIFT's default contrast
# threshold (0.04) a 3.4x view of PETS has 12 features, at 0.01 it has the 1000 asked for (the
# strongest are kept, so a sharp view loses nothing).
SIFT_CONTRAST_THRESHOLD = 0.01
# Reference views whose predicted overlap (from their rough poses) is below this fraction of a view are
# not matched: their matches could only be wrong, and matching every pair costs O(L^2).
MIN_PAIR_OVERLAP = 0.2
# A pair of reference views ties their poses together in bundle adjustment only with this many RANSAC
# inliers: a dozen chance matches can agree on a homography, a few dozen cannot.
MIN_PAIR_INLIERS = 30
# Overlapping reference views share most features, so the ratio test must compare a live feature's two
# nearest neighbours within one reference view: against all views at once, the second nearest is the
# same scene point in another view, and the test rejects nearly everything (98 % of PETS matches).
# One FLANN search for this many neighbours over all views gives every view's two nearest, or shows
# that a view's second nearest lies beyond the last neighbour found.
NEIGHBOURS = 8
# The reference views with most ratio-tested matches whose RANSAC homographies are tried.
CANDIDATE_VIEWS = 2
# Inliers (evenly spread) that refine the live pose: three parameters need far fewer than the hundreds
# a sharp view can have, and the least-squares cost grows with them.
REFINE_POINTS = 100
# Leaves the FLANN search visits, and SIFT features of a live view: as many views register, as
# accurately, with half the features and checks, in two thirds of the time
# (docs/decisions/0002-registration-search-effort.md).
# Reference views keep 1000 features: they are extracted once.
FLANN_CHECKS = 16
LIVE_FEATURES = 500
REFERENCE_FEATURES = 1000
# The live view's radial distortion is estimated with its pose under a zero-mean Gaussian prior on the
# distortion at the image corner (k1 r_corner^2) of this standard deviation, fixed a priori: the wide
# end of a PTZ lens distorts by a few percent at the corner (the PETS camera's own lens by 2.7 % over
# the field of our zoom-1 view), and a narrow view, whose corners lie near its axis, leaves k1 to the prior.
CORNER_DISTORTION_SIGMA = 0.03
# Correspondences per pair of reference views that bundle adjustment uses (evenly spread over the
# inliers): enough to pin three parameters per view many times over, few enough to stay fast.
BUNDLE_POINTS_PER_PAIR = 40


class RegistrationIndexError(InputError):
    """A reference index file that cannot be read; the message names the file."""


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
        matcher = cv2.FlannBasedMatcher({"algorithm": 1, "trees": 4}, {"checks": FLANN_CHECKS})
        matcher.add([self.descriptors])
        matcher.train()
        object.__setattr__(self, "matcher", matcher)


def sift_features(image_bgr: np.ndarray, features: int) -> tuple[np.ndarray, np.ndarray]:
    """Keypoint positions (K, 2) px and descriptors (K, 128) float32 of an image.

    Positions are in the camera model's pixel coordinates: pixel (row, col) has its centre at
    (col + 0.5, row + 0.5).
    """
    gray = cv2.cvtColor(image_bgr, cv2.COLOR_BGR2GRAY)
    scale = SIFT_IMAGE_SCALE if gray.shape[1] >= SIFT_HALVED_FROM_PX else 1.0
    if scale != 1.0:
        gray = cv2.resize(gray, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)
    detector = cv2.SIFT.create(nfeatures=features, contrastThreshold=SIFT_CONTRAST_THRESHOLD)
    keypoints, descriptors = detector.detectAndCompute(gray, None)
    if descriptors is None:
        return np.zeros((0, 2)), np.zeros((0, 128), dtype=np.float32)
    # OpenCV puts pixel centres at whole coordinates.
    return (np.array([k.pt for k in keypoints], dtype=float) + 0.5) / scale, descriptors


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
    return (
        intrinsics(camera, to_pose[..., 2])
        @ R_b
        @ np.swapaxes(R_a, -1, -2)
        @ np.linalg.inv(intrinsics(camera, from_pose[..., 2]))
    )


def bundle_adjust(
    camera: PTZCamera, initial_poses, matches: list[tuple[int, int, np.ndarray, np.ndarray]]
) -> np.ndarray:
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


def overlapping_pairs(camera: PTZCamera, poses, min_overlap: float = MIN_PAIR_OVERLAP) -> list[tuple[int, int]]:
    """Pairs (i, j), i < j, of views at ``poses`` (L, 3) that share at least ``min_overlap`` of one of them.

    The overlap is the fraction of a 12 x 9 grid of one view's pixels that the rotation homography
    carries, in front of the camera, into the other view; the larger of the two directions counts, so
    a zoomed view inside a wide one overlaps it fully.
    """
    poses = np.asarray(poses, dtype=float)
    u, v = np.meshgrid(np.linspace(0, camera.image_width_px, 12), np.linspace(0, camera.image_height_px, 9))
    grid = np.c_[u.ravel(), v.ravel(), np.ones(u.size)]
    H = rotation_homography(camera, poses[:, None], poses[None, :])  # (L, L, 3, 3): view i -> view j
    mapped = np.einsum("ijab,nb->ijna", H, grid)
    with np.errstate(divide="ignore", invalid="ignore"):
        inside = (mapped[..., 2] > 0) & inside_image(camera, mapped[..., :2] / mapped[..., 2:])
    overlap = inside.mean(axis=-1)
    overlap = np.maximum(overlap, overlap.T)
    return [(int(i), int(j)) for i, j in zip(*np.nonzero(np.triu(overlap >= min_overlap, k=1)), strict=True)]


def pairwise_matches(keypoints: list, descriptors: list, pairs) -> list[tuple[int, int, np.ndarray, np.ndarray]]:
    """RANSAC-inlier correspondences (at most ``BUNDLE_POINTS_PER_PAIR``, evenly spread) between the
    views of each pair (i, j) that has at least ``MIN_PAIR_INLIERS`` of them."""
    found = []
    for i, j in pairs:
        matched = ratio_matches(descriptors[i], descriptors[j])
        if len(matched) < MIN_PAIR_INLIERS:
            continue
        points_i, points_j = keypoints[i][matched[:, 0]], keypoints[j][matched[:, 1]]
        _, inliers = cv2.findHomography(points_i, points_j, cv2.RANSAC, RANSAC_THRESHOLD_PX)
        if inliers is not None and inliers.sum() >= MIN_PAIR_INLIERS:
            keep = np.flatnonzero(inliers.ravel())
            keep = keep[np.linspace(0, len(keep) - 1, min(len(keep), BUNDLE_POINTS_PER_PAIR)).astype(int)]
            found.append((int(i), int(j), points_i[keep], points_j[keep]))
    return found


def tied_to_first(view_count: int, matches) -> np.ndarray:
    """(L,) bool: views joined to view 0 through matched pairs. Only these get their pose from bundle
    adjustment; a view in no pair, or in a group of its own, would keep its rough pose."""
    graph = nx.Graph()
    graph.add_nodes_from(range(view_count))
    graph.add_edges_from((i, j) for i, j, _, _ in matches)
    tied = np.zeros(view_count, dtype=bool)
    tied[list(nx.node_connected_component(graph, 0))] = True
    return tied


def build_index(
    camera: PTZCamera, images: list[np.ndarray], initial_poses, features: int = REFERENCE_FEATURES
) -> ReferenceIndex:
    """Reference views of the field of regard: SIFT, pairwise homographies, bundle adjustment.

    images : the views, taken at poses known roughly (``initial_poses`` (L, 3), the first exactly).
    Views that no chain of well-matched pairs ties to the first are left out of the index (a view
    mostly outside the scene, or of a featureless region, cannot be placed); the index keeps the
    others in their order.
    """
    initial_poses = np.asarray(initial_poses, dtype=float)
    extracted = [sift_features(image, features) for image in images]
    matches = pairwise_matches(
        [k for k, _ in extracted], [d for _, d in extracted], overlapping_pairs(camera, initial_poses)
    )
    tied = tied_to_first(len(images), matches)
    renumbered = np.cumsum(tied) - 1
    kept_matches = [(renumbered[i], renumbered[j], a, b) for i, j, a, b in matches if tied[i]]
    poses = bundle_adjust(camera, initial_poses[tied], kept_matches)
    kept = [extracted[view] for view in np.flatnonzero(tied)]
    return ReferenceIndex(
        poses=poses,
        keypoints_px=np.concatenate([k for k, _ in kept]),
        descriptors=np.concatenate([d for _, d in kept]),
        view=np.concatenate([np.full(len(k), view) for view, (k, _) in enumerate(kept)]),
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
    """Read an index written by :func:`save_index`; a missing or malformed file raises
    :class:`RegistrationIndexError` naming it."""
    try:
        with np.load(path) as data:
            index = ReferenceIndex(
                poses=data["poses"],
                keypoints_px=data["keypoints_px"],
                descriptors=data["descriptors"],
                view=data["view"],
                image_size_px=(int(data["image_size_px"][0]), int(data["image_size_px"][1])),
            )
    except FileNotFoundError:
        raise RegistrationIndexError(f"{path}: no such registration index") from None
    except (KeyError, ValueError, OSError, IndexError, TypeError, EOFError, zipfile.BadZipFile, zlib.error) as error:
        raise RegistrationIndexError(f"{path}: not a registration index ({shown(str(error))})") from None
    features = len(index.keypoints_px)
    consistent = (
        index.poses.ndim == 2
        and index.poses.shape[1] == 3
        and index.keypoints_px.shape == (features, 2)
        and index.descriptors.shape == (features, 128)
        and index.view.shape == (features,)
        and np.issubdtype(index.view.dtype, np.integer)
        and np.all((index.view >= 0) & (index.view < len(index.poses)))
    )
    finite = all(np.all(np.isfinite(array)) for array in (index.poses, index.keypoints_px, index.descriptors))
    if not (consistent and finite and min(index.image_size_px) > 0):
        raise RegistrationIndexError(
            f"{path}: not a registration index (its arrays' shapes, view numbers or values are inconsistent)"
        )
    return index


def focal_from_homography(H_reference_to_live: np.ndarray, reference_focal_px: float) -> float:
    """Equation 2 solved for the live focal length; H in pixel coordinates centred on the principal point."""
    A = H_reference_to_live @ np.diag([reference_focal_px**2, reference_focal_px**2, 1.0]) @ H_reference_to_live.T
    return float(np.sqrt((A[0, 0] + A[1, 1]) / (2.0 * A[2, 2])))


def pose_from_rotation(R: np.ndarray) -> tuple[float, float]:
    """(pan_deg, tilt_deg) of a world-to-camera rotation: the direction of its optical axis, whatever its roll."""
    forward = R[2] / np.linalg.norm(R[2])
    return float(np.rad2deg(np.arctan2(forward[0], forward[1]))), float(np.rad2deg(np.arcsin(-forward[2])))


@dataclass(frozen=True)
class Registration:
    """A registered live view: the pose of the camera model that explains it, and how well.

    pose : (pan_deg, tilt_deg, zoom), from equation 2 and the homography's rotation, refined on the
    inliers with the view's roll and distortion; focal_px : its focal length; view : the reference
    view used; inliers : correspondences the refined camera fits; roll_deg, k1 : the view's roll and
    radial distortion, which the tracker's model does not use.
    """

    pose: np.ndarray
    focal_px: float
    view: int
    inliers: int
    roll_deg: float
    k1: float


def within_view_ratio_matches(index: ReferenceIndex, descriptors: np.ndarray, ratio: float = RATIO_TEST) -> np.ndarray:
    """(M, 2) index pairs (live feature, reference feature) that pass Lowe's ratio test within the
    reference feature's view: its distance is below ``ratio`` times that of the next nearest feature of
    the same view (or of the last of the ``NEIGHBOURS`` found, when none of them is of that view)."""
    found = index.matcher.knnMatch(descriptors, k=NEIGHBOURS)
    found = [row for row in found if len(row) == NEIGHBOURS]
    if not found:
        return np.zeros((0, 2), dtype=int)
    query = np.array([row[0].queryIdx for row in found])
    train = np.array([[m.trainIdx for m in row] for row in found])  # (Q, N), nearest first
    distance = np.array([[m.distance for m in row] for row in found])
    views = index.view[train]
    same_view = views[:, :, None] == views[:, None, :]  # (Q, N, N)
    earlier = np.tril(np.ones((NEIGHBOURS, NEIGHBOURS), dtype=bool), k=-1)
    first_of_view = ~(same_view & earlier).any(axis=2)
    later_same = same_view & earlier.T
    next_distance = np.where(later_same, distance[:, None, :], np.inf).min(axis=2)
    next_distance = np.minimum(next_distance, np.where(later_same.any(axis=2), np.inf, distance[:, -1:]))
    passed = first_of_view & (distance < ratio * next_distance)
    rows, columns = np.nonzero(passed)
    return np.c_[query[rows], train[rows, columns]]


def register(
    camera: PTZCamera, index: ReferenceIndex, image_bgr: np.ndarray, features: int = LIVE_FEATURES
) -> Registration | None:
    """Register a live view against the index; None when no reference view shares enough features.

    Of the reference views with most ratio-tested matches, the one whose RANSAC homography has most
    inliers is the paper's I_m.
    """
    keypoints, descriptors = sift_features(image_bgr, features)
    if len(descriptors) < MIN_INLIERS:
        return None
    pairs = within_view_ratio_matches(index, descriptors)
    views = index.view[pairs[:, 1]]
    votes = np.bincount(views, minlength=len(index.poses))
    best, H_live_to_reference, best_inliers = -1, np.eye(3), (np.zeros((0, 2)), np.zeros((0, 2)))
    for view in np.argsort(-votes, kind="stable")[:CANDIDATE_VIEWS]:
        if votes[view] < MIN_INLIERS:
            break
        chosen = pairs[views == view]
        live_px, reference_px = keypoints[chosen[:, 0]], index.keypoints_px[chosen[:, 1]]
        H, inliers = cv2.findHomography(live_px, reference_px, cv2.RANSAC, RANSAC_THRESHOLD_PX)
        if H is not None and inliers.sum() >= MIN_INLIERS and (best < 0 or inliers.sum() > len(best_inliers[0])):
            keep = inliers.ravel().astype(bool)
            best, H_live_to_reference, best_inliers = int(view), H, (live_px[keep], reference_px[keep])
    if best < 0:
        return None
    reference_pose = index.poses[best]
    K_reference = intrinsics(camera, reference_pose[2])
    centred = np.array(
        [[1.0, 0.0, -camera.principal_point_px[0]], [0.0, 1.0, -camera.principal_point_px[1]], [0, 0, 1]]
    )
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
    rolled = R_live @ rotation_world_to_camera(pan_deg, tilt_deg).T
    roll_deg = float(np.rad2deg(np.arctan2(rolled[1, 0], rolled[0, 0])))
    live_px, reference_px = best_inliers
    directions = pixel_directions(camera, reference_pose, Lens(), reference_px)
    spread = np.linspace(0, len(live_px) - 1, min(len(live_px), REFINE_POINTS)).astype(int)
    initial = np.array([pan_deg, tilt_deg, focal_px / camera.f_min_px, roll_deg, 0.0])
    refined = refine_view(camera, directions[spread], live_px[spread], initial)
    pose, lens = refined[:3], Lens(roll_deg=float(refined[3]), k1=float(refined[4]))
    # The homography of a narrow view leaves its perspective part (and so eq. 2) poorly pinned; the
    # five-parameter camera is not, but the inliers must then fit it, as they fit a true rotation.
    fitted = np.linalg.norm(project_directions(camera, pose, lens, directions) - live_px, axis=1)
    fitting = int(np.count_nonzero(fitted <= RANSAC_THRESHOLD_PX))
    if fitting < max(MIN_INLIERS, len(live_px) / 2):
        return None
    return Registration(pose, pose[2] * camera.f_min_px, best, fitting, lens.roll_deg, lens.k1)


def refine_view(camera: PTZCamera, directions, live_px, initial) -> np.ndarray:
    """The live (pan_deg, tilt_deg, zoom, roll_deg, k1) that best projects world directions (M, 3)
    onto their live points (M, 2): 5 parameters instead of the homography's 8, so a few dozen
    correspondences pin the view far better than the homography they came from. Soft-L1 loss (1 px);
    k1 under its prior (``CORNER_DISTORTION_SIGMA`` at the corner; Gaussian within one sigma, where
    the loss leaves it quadratic)."""

    def residuals(view):
        lens = Lens(roll_deg=view[3], k1=view[4])
        projected = project_directions(camera, view[:3], lens, directions)
        prior = view[4] * corner_radius2(camera, view[2]) / CORNER_DISTORTION_SIGMA
        return np.r_[(projected - live_px).ravel(), prior]

    scale = [1.0, 1.0, 0.01, 1.0, 0.1]
    return least_squares(residuals, initial, loss="soft_l1", f_scale=1.0, x_scale=scale).x
