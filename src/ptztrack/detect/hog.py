"""OpenCV's HOG people detector (Dalal and Triggs) on small PTZ views.

The default detector scans 64 x 128 px windows. A virtual view is only
160 x 120 px, where a person at the edge of detectability (r0 = 21.29 px, the
recall model of the paper) is about 21 px tall, so the view is upsampled by
``upsample`` (default 6 = 128 / 21.29, rounded) before detection: then such
a person fills the window. Boxes are merged by non-maximum suppression and
returned in view pixels.

The model was trained on windows where the person stands with a 16 px
margin above and below (96 of 128 px), so the feet are 1/8 of a box's height
above its bottom edge and the person is 3/4 of it tall. On the PETS test
excerpt the feet taken that way lie a median 1.6 px (at zoom 1) from the
annotated feet, against 4.5 px for the bottom edge; 1.6 px at 160 px wide is
about 0.3 m on the ground at 20 m.

Searching where people can be
-----------------------------
OpenCV's ``detectMultiScale`` slides the window over every position of
every level of a pyramid of the upsampled view (scales 1.05^k: 36 levels
for 960 x 720 px), then groups the windows that fire. A calibrated camera
knows more: in each pixel row of the view, a person 1.5 to 2.0 m tall
standing there on the walkable ground appears between two heights (the
head/feet homology), and a row that shows no walkable ground holds nobody's
feet. :class:`GroundSearch` scans, at each level, only the windows whose
person (feet 7/8 down the window, 3/4 of its height tall) could be such a
person, and only the rows of the level those windows cover. A window's
score depends only on its own pixels and their neighbours (the gradient),
so each scanned window scores as in a full search of the same levels; the
hits are grouped as ``detectMultiScale`` groups them (OpenCV's
``HOGDescriptor::groupRectangles``, which Python cannot call) and clipped
to the image. Given the upsampled view and its exact resizing, every
window scanned is ``detectMultiScale``, hit for hit (tested). The detector
makes each level from the 160 x 120 view in one bilinear resize instead of
upsampling first and resizing again: the same map from view to level, a
pixel's value off by a few grey levels, at a sixth of the resizing time
(which was a quarter of the search's).

A person is not found by the window of their size alone: the hits that
``detectMultiScale`` groups into one detection have edges within ``delta``
= ``GROUP_EPS`` x (width + height) / 2 of the smaller hit, 0.2 x 0.75 =
0.15 of its height. The search places a person by their feet, 7/8 down the
window: two windows of heights h < h' with the same feet have tops 7/8 (h'
- h) apart, so they group while h' <= (1 + 0.15 / 0.875) h = 1.171 h. The
search takes windows from the shortest person's height / 1.171 to the
tallest's x 1.171 (``SCALE_TOLERANCE``). (Two windows with the same centre
would group up to 1.3 h; the search counted that way until the levels were
resized from the view: 4.1 against 3.4 million pixels scanned per view of
a ``smpl`` run, the same people found at their size.)
"""

import functools
import hashlib
import itertools
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import cv2
import numpy as np
from scipy.sparse.csgraph import connected_components

from ptztrack.detect.parameters import HogParameters
from ptztrack.geometry.area import inside
from ptztrack.geometry.ptz import PTZCamera, apply_homography, head_from_feet_homology, pixels_to_ground
from ptztrack.roles import CameraBackend
from ptztrack.types import Detections

PERSON_IN_WINDOW = 96 / 128  # of the box height
FEET_ABOVE_BOTTOM = 16 / 128  # of the box height
# detectMultiScale's settings: window (64 x 128 px, the default people detector's), stride, padding,
# pyramid step, and the grouping of its hits (at least GROUP_THRESHOLD + 1 hits, edges within GROUP_EPS).
WINDOW_PX = (64, 128)
STRIDE_PX = (8, 8)
PADDING_PX = (8, 8)
LEVEL_SCALE = 1.05
GROUP_THRESHOLD = 2
GROUP_EPS = 0.2
SCALE_TOLERANCE = 1 + GROUP_EPS * (WINDOW_PX[0] + WINDOW_PX[1]) / 2 / WINDOW_PX[1] / (1 - FEET_ABOVE_BOTTOM)
# A person's height in a row is taken every this many pixels across it; the poses whose search is kept.
COLUMN_STEP_PX = 8.0
CACHED_POSES = 512
# The boxes found in the views seen before in this process, by the detector's settings, the pose and the
# image, up to MEMO_VIEWS views: the runs of an experiment that differ only in their seed (smpl's Monte Carlo
# samples) mostly look at the same views, where HOG finds the same boxes.
MEMO_VIEWS = 20_000
_BOXES_SEEN: dict[tuple, tuple[np.ndarray, np.ndarray]] = {}


@dataclass(frozen=True)
class LevelBand:
    """The windows scanned at one level of the pyramid: a run of window rows.

    scale : the level's scale (the upsampled view shrunk by it); size_px : (width, height) of the level;
    first_top_px, last_top_px : the top rows of the first and the last window rows, level pixels.
    """

    scale: float
    size_px: tuple[int, int]
    first_top_px: int
    last_top_px: int


@dataclass
class GroundSearch:
    """Where and at which sizes a HOG detector looks for people in the views of a calibrated camera.

    camera : the PTZ camera model of the views; area_polygon_m : (K, 2) the walkable area on the ground;
    person_heights_m : (shortest, tallest) standing person; tolerance : windows from the shortest
    person's height / tolerance to the tallest's x tolerance are scanned (see the module's notes).
    The windows of a pose are worked out once and kept (for the last ``CACHED_POSES`` poses); ``key``
    tells one search from another (a detector's memo of the views it has seen keys on it).
    """

    camera: PTZCamera
    area_polygon_m: np.ndarray
    person_heights_m: tuple[float, float] = HogParameters.person_heights_m
    tolerance: float = SCALE_TOLERANCE

    def __post_init__(self):
        shortest, tallest = self.person_heights_m
        if not 0 < shortest <= tallest:
            raise ValueError(
                f"person_heights_m must be (shortest, tallest), 0 < shortest <= tallest; got {shortest}, {tallest}"
            )
        if not self.tolerance >= 1:
            raise ValueError(f"tolerance must be at least 1, got {self.tolerance}")
        self._bands = functools.lru_cache(maxsize=CACHED_POSES)(self._bands_at)
        self.key = (
            self.camera,
            np.asarray(self.area_polygon_m, dtype=float).tobytes(),
            shortest,
            tallest,
            self.tolerance,
        )

    def bands(self, pose, upsample: float, upsampled_size_px: tuple[int, int]) -> list[LevelBand]:
        """The windows to scan in the view at ``pose`` (3,) upsampled ``upsample`` times, to (width,
        height) px."""
        pose = np.asarray(pose, dtype=float)
        if pose.shape != (3,) or not np.all(np.isfinite(pose)):
            raise ValueError(f"pose must be (pan_deg, tilt_deg, zoom), all finite; got {pose!r}")
        return self._bands(tuple(pose.tolist()), upsample, tuple(upsampled_size_px))

    def _bands_at(self, pose: tuple, upsample: float, upsampled_size_px: tuple[int, int]) -> list[LevelBand]:
        shortest_px, tallest_px = person_rows_px(self.camera, pose, self.area_polygon_m, self.person_heights_m)
        return level_bands(shortest_px, tallest_px, upsampled_size_px, upsample, self.tolerance)


@dataclass
class HogPeopleDetector:
    """The HOG + linear SVM people detector of OpenCV, with its default model.

    upsample : factor applied to the view before detection.
    hit_threshold : SVM score below which a window is not a detection.
    nms_iou : boxes overlapping more than this (intersection over union) are merged.
    search : where people can be in the views (:class:`GroundSearch`); None scans every window
        (OpenCV's ``detectMultiScale``).
    luma : read only an image's luma, ``Y = 0.299 R + 0.587 G + 0.114 B`` (OpenCV's grey), instead of the
        strongest gradient of its three colours: what a video stream keeps at full resolution (its
        colour is at half the resolution each way).
    remember_views : keep the boxes found in each view (``MEMO_VIEWS``), for runs that see a recording's
        views again; a camera's pictures never repeat, and their boxes would only fill the memo.
    """

    upsample: float = HogParameters.upsample
    hit_threshold: float = HogParameters.hit_threshold
    nms_iou: float = HogParameters.nms_iou
    search: GroundSearch | None = None
    luma: bool = False
    remember_views: bool = True
    _hog: cv2.HOGDescriptor = field(init=False, repr=False)

    def __post_init__(self):
        self._hog = cv2.HOGDescriptor()
        self._hog.setSVMDetector(cv2.HOGDescriptor.getDefaultPeopleDetector())
        self._settings = (self.upsample, self.hit_threshold, self.nms_iou, self.search and self.search.key, self.luma)

    def detect(
        self, camera: CameraBackend, step: int, pose, rng: np.random.Generator, believed_pose=None
    ) -> Detections:
        """People in the camera's view at ``pose``: feet and heights from the boxes, SVM scores. The
        search is planned at ``believed_pose`` (None: ``pose``), the pose the system takes the camera
        to be at. A view seen before (the same image, searched from the same pose) gives the boxes
        found then (``MEMO_VIEWS``)."""
        image = camera.image(step, pose)
        if image is None:
            raise RuntimeError("the HOG detector needs a camera backend that renders images")
        planned_at = pose if believed_pose is None else believed_pose
        image = np.ascontiguousarray(image)
        if not self.remember_views:
            return detections_of(*self.boxes(image, planned_at))
        digest = hashlib.blake2b(image.data, digest_size=16).digest()
        key = (self._settings, np.asarray(planned_at, dtype=float).tobytes(), image.shape, digest)
        found = _BOXES_SEEN.get(key)
        if found is None:
            found = self.boxes(image, planned_at)
            if len(_BOXES_SEEN) >= MEMO_VIEWS:
                del _BOXES_SEEN[next(iter(_BOXES_SEEN))]
            _BOXES_SEEN[key] = found
        boxes, scores = found
        return detections_of(boxes, scores.copy())

    def boxes(self, image, pose=None) -> tuple[np.ndarray, np.ndarray]:
        """People in a BGR image taken at ``pose`` (needed with a search): boxes (K, 4) as (left, top,
        width, height) px and SVM scores (K,)."""
        if self.luma and image.ndim == 3:
            image = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
        upsampled_size_px = (round(image.shape[1] * self.upsample), round(image.shape[0] * self.upsample))
        found: np.ndarray | Sequence
        weights: np.ndarray | Sequence
        if self.search is None:
            enlarged = cv2.resize(image, upsampled_size_px, interpolation=cv2.INTER_LINEAR)
            found, weights = self._hog.detectMultiScale(
                enlarged, hitThreshold=self.hit_threshold, winStride=STRIDE_PX, padding=PADDING_PX, scale=LEVEL_SCALE
            )
        else:
            if pose is None:
                raise ValueError("a HOG detector with a ground search needs the pose the image was taken at")
            camera = self.search.camera
            if image.shape[:2] != (camera.image_height_px, camera.image_width_px):
                raise ValueError(
                    f"the image is {image.shape[1]}x{image.shape[0]} px, the search's camera "
                    f"{camera.image_width_px}x{camera.image_height_px} px"
                )
            bands = self.search.bands(pose, self.upsample, upsampled_size_px)
            hits = scan(self._hog, image, bands, self.hit_threshold, cv2.getNumThreads())
            found, weights = group_rectangles(*hits)
            found, weights = clip_boxes(found, weights, upsampled_size_px)
        if len(found) == 0:
            return np.zeros((0, 4)), np.zeros(0)
        boxes, scores = np.asarray(found, dtype=float), np.ravel(weights).astype(float)
        keep = np.ravel(cv2.dnn.NMSBoxes(boxes.tolist(), scores.tolist(), self.hit_threshold, self.nms_iou))
        return boxes[keep] / self.upsample, scores[keep]


def person_rows_px(
    camera: PTZCamera, pose, area_polygon_m, person_heights_m: tuple[float, float], column_step_px=COLUMN_STEP_PX
) -> tuple[np.ndarray, np.ndarray]:
    """For each pixel row of the view at ``pose``: the least and the greatest height (px) of a standing
    person, ``person_heights_m`` = (shortest, tallest), whose feet are in that row on the walkable area
    ``area_polygon_m`` (K, 2); two (H,) arrays, NaN where the row shows no walkable ground.

    Each row is taken at its middle, every ``column_step_px`` across (both edges included).
    """
    width_px, height_px = camera.image_width_px, camera.image_height_px
    columns = np.linspace(0.0, width_px, int(np.ceil(width_px / column_step_px)) + 1)
    u, v = np.meshgrid(columns, np.arange(height_px) + 0.5)
    feet_px = np.c_[u.ravel(), v.ravel()]
    ground_m = pixels_to_ground(camera, pose, feet_px)
    walkable = np.isfinite(ground_m[:, 0])
    walkable[walkable] = inside(area_polygon_m, ground_m[walkable])
    heights = [
        feet_px[:, 1] - apply_homography(head_from_feet_homology(camera, pose, height_m), feet_px)[:, 1]
        for height_m in person_heights_m
    ]
    shortest = np.where(walkable, heights[0], np.inf).reshape(u.shape).min(axis=1)
    tallest = np.where(walkable, heights[1], -np.inf).reshape(u.shape).max(axis=1)
    seen = np.isfinite(shortest)
    return np.where(seen, shortest, np.nan), np.where(seen, tallest, np.nan)


def pyramid(size_px: tuple[int, int]) -> list[tuple[float, tuple[int, int]]]:
    """``detectMultiScale``'s levels of an image (width, height) px: (scale, (width, height) of the level)
    for scales 1, 1.05, 1.05^2, ... (multiplied up as OpenCV does) while the level holds a window."""
    levels, scale = [], 1.0
    for _ in range(cv2.HOGDescriptor().nlevels):
        level_px = (round(size_px[0] / scale), round(size_px[1] / scale))
        if level_px[0] < WINDOW_PX[0] or level_px[1] < WINDOW_PX[1]:
            break
        levels.append((scale, level_px))
        scale *= LEVEL_SCALE
    return levels


def level_bands(
    shortest_px, tallest_px, upsampled_size_px: tuple[int, int], upsample: float, tolerance: float
) -> list[LevelBand]:
    """The windows of the pyramid of a view upsampled to ``upsampled_size_px`` whose person could stand
    in the view: where the window's feet row (view px) holds a person from ``shortest_px`` / tolerance
    to ``tallest_px`` x tolerance tall ((H,) per row of the view, NaN: nobody).

    All zeros and infinities give every window of the pyramid.
    """
    shortest_px, tallest_px = np.asarray(shortest_px, dtype=float), np.asarray(tallest_px, dtype=float)
    bands = []
    for scale, level_px in pyramid(upsampled_size_px):
        rows = (level_px[1] + 2 * PADDING_PX[1] - WINDOW_PX[1]) // STRIDE_PX[1] + 1
        tops_px = -PADDING_PX[1] + STRIDE_PX[1] * np.arange(rows)
        # The box a window reports, in upsampled pixels (detectMultiScale rounds as np.rint does).
        box_height_px = np.rint(WINDOW_PX[1] * scale)
        feet_row = np.floor((np.rint(tops_px * scale) + (1 - FEET_ABOVE_BOTTOM) * box_height_px) / upsample)
        person_px = PERSON_IN_WINDOW * box_height_px / upsample
        in_view = (feet_row >= 0) & (feet_row < len(shortest_px))
        row = np.clip(feet_row, 0, len(shortest_px) - 1).astype(int)
        plausible = in_view & (shortest_px[row] <= tolerance * person_px) & (person_px <= tolerance * tallest_px[row])
        scanned = np.flatnonzero(plausible)
        for run in np.split(scanned, np.flatnonzero(np.diff(scanned) > 1) + 1):
            if len(run):
                bands.append(LevelBand(scale, level_px, int(tops_px[run[0]]), int(tops_px[run[-1]])))
    return bands


def scan(
    hog: cv2.HOGDescriptor,
    image,
    bands: list[LevelBand],
    hit_threshold: float,
    threads: int = 1,
    interpolation: int = cv2.INTER_LINEAR,
) -> tuple[np.ndarray, np.ndarray]:
    """The windows of ``bands`` that fire on ``image`` resized to each of their levels: boxes (K, 4)
    (left, top, width, height) in the pixels of the upsampled view whose pyramid the bands are of, as
    detectMultiScale reports them before grouping, and their scores (K,).

    Each level is ``image`` resized to the level's size with ``interpolation``; each band is cut out of
    it (:func:`band_rows`) and scanned, and the windows outside the band are dropped. detectMultiScale
    resizes the upsampled view with ``cv2.INTER_LINEAR_EXACT``: given that view and that interpolation,
    the scan is detectMultiScale's. The detector gives the view itself, the same bilinear map to each
    level in one resize instead of two (5-6 times less resizing, the largest level exactly the
    upsampled view). With ``threads`` > 1 the levels are scanned on that many threads (OpenCV lets go
    of the GIL), with the same result.
    """
    levels = [list(same) for _, same in itertools.groupby(bands, key=lambda band: band.size_px)]
    scan_level = functools.partial(_scan_level, hog, image, hit_threshold, interpolation)
    if threads > 1 and len(levels) > 1:
        with ThreadPoolExecutor(threads) as pool:
            found = list(pool.map(scan_level, levels))
    else:
        found = [scan_level(level_bands) for level_bands in levels]
    boxes, scores = zip(*found, strict=True) if found else ((), ())
    return np.concatenate([np.zeros((0, 4)), *boxes]), np.concatenate([np.zeros(0), *scores])


def _scan_level(
    hog: cv2.HOGDescriptor, image, hit_threshold: float, interpolation: int, bands: list[LevelBand]
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`scan` of bands of one level."""
    size_px = bands[0].size_px
    same = size_px == (image.shape[1], image.shape[0])
    level = image if same else cv2.resize(image, size_px, interpolation=interpolation)
    boxes, scores = [np.zeros((0, 4))], [np.zeros(0)]
    for band in bands:
        top, bottom, padding_px = band_rows(band)
        found, weights = hog.detect(
            level[top:bottom], hitThreshold=hit_threshold, winStride=STRIDE_PX, padding=padding_px
        )
        if len(found) == 0:
            continue
        corners = np.asarray(found, dtype=float).reshape(-1, 2) + [0, top]
        keep = (corners[:, 1] >= band.first_top_px) & (corners[:, 1] <= band.last_top_px)
        size = np.rint(np.multiply(WINDOW_PX, band.scale))
        boxes.append(np.c_[np.rint(corners[keep] * band.scale), np.broadcast_to(size, (keep.sum(), 2))])
        scores.append(np.ravel(weights)[keep])
    return np.concatenate(boxes), np.concatenate(scores)


def band_rows(band: LevelBand) -> tuple[int, int, tuple[int, int]]:
    """The rows [top, bottom) of the level that a band is cut out of, and the padding to scan them with.

    A window's score reads its own pixels and, for the gradient, their neighbours. The cut starts one
    stride above the band's first window, so that its windows keep their place on the level's grid (the
    window in that margin is dropped), and ends one row below its last. A band that reaches into the
    level's padding (a window above its top or below its bottom) is cut to that edge and scanned with
    detectMultiScale's padding, as the level itself is.
    """
    first, last, height = band.first_top_px, band.last_top_px, band.size_px[1]
    top = max(0, first - STRIDE_PX[1])
    bottom = min(height, last + WINDOW_PX[1] + 1)
    padded = first < 0 or last + WINDOW_PX[1] > height
    return top, bottom, PADDING_PX if padded else (PADDING_PX[0], 0)


def group_rectangles(
    boxes, scores, threshold: int = GROUP_THRESHOLD, eps: float = GROUP_EPS
) -> tuple[np.ndarray, np.ndarray]:
    """OpenCV's ``HOGDescriptor::groupRectangles``: boxes (K, 4) (left, top, width, height) whose edges
    lie within ``eps`` of their mean size of each other are grouped (and so on, transitively); each
    group of more than ``threshold`` boxes gives its mean box (rounded) with its best score, unless it
    lies inside another such group's box and that group has more boxes (or it has fewer than 3).
    Returns boxes (M, 4) and scores (M,).
    """
    boxes, scores = np.asarray(boxes, dtype=float).reshape(-1, 4), np.asarray(scores, dtype=float)
    if len(boxes) == 0:
        return boxes, scores
    left, top, width, height = boxes.T
    delta = eps * (np.minimum.outer(width, width) + np.minimum.outer(height, height)) / 2
    right, bottom = left + width, top + height
    similar = np.ones_like(delta, dtype=bool)
    for edge in (left, top, right, bottom):
        similar &= np.abs(np.subtract.outer(edge, edge)) <= delta
    groups, label = connected_components(similar, directed=False)
    count = np.bincount(label, minlength=groups)
    mean = np.rint(np.stack([np.bincount(label, boxes[:, k], groups) for k in range(4)], axis=-1) / count[:, None])
    best = np.full(groups, -np.inf)
    np.maximum.at(best, label, scores)
    big = count > threshold
    margin = np.rint(eps * mean[:, 2:])
    # within[i, j]: group i's box lies in group j's, grown by j's margin.
    within = (
        (mean[:, None, 0] >= mean[None, :, 0] - margin[None, :, 0])
        & (mean[:, None, 1] >= mean[None, :, 1] - margin[None, :, 1])
        & (mean[:, None, 0] + mean[:, None, 2] <= mean[None, :, 0] + mean[None, :, 2] + margin[None, :, 0])
        & (mean[:, None, 1] + mean[:, None, 3] <= mean[None, :, 1] + mean[None, :, 3] + margin[None, :, 1])
    )
    outvoted = (count[None, :] > np.maximum(3, count[:, None])) | (count[:, None] < 3)
    inner = within & outvoted & big[None, :] & ~np.eye(groups, dtype=bool)
    keep = big & ~inner.any(axis=1)
    return mean[keep], best[keep]


def clip_boxes(boxes, scores, size_px: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Boxes (K, 4) (left, top, width, height) cut to the image (width, height), as detectMultiScale
    does last; boxes left with no area are dropped. Returns boxes and their scores."""
    boxes, scores = np.asarray(boxes, dtype=float).reshape(-1, 4), np.asarray(scores, dtype=float)
    low = np.maximum(boxes[:, :2], 0)
    high = np.minimum(boxes[:, :2] + boxes[:, 2:], size_px)
    keep = np.all(high > low, axis=1)
    return np.c_[low, high - low][keep], scores[keep]


def feet_and_height_px(boxes) -> tuple[np.ndarray, np.ndarray]:
    """The feet points (K, 2) and person heights (K,) of HOG boxes (K, 4) (left, top, width, height)."""
    boxes = np.asarray(boxes, dtype=float).reshape(-1, 4)
    feet_px = np.stack([boxes[:, 0] + boxes[:, 2] / 2, boxes[:, 1] + (1 - FEET_ABOVE_BOTTOM) * boxes[:, 3]], axis=-1)
    return feet_px, PERSON_IN_WINDOW * boxes[:, 3]


def detections_of(boxes: np.ndarray, scores: np.ndarray) -> Detections:
    """The detections of HOG's boxes (K, 4) px (left, top, width, height) and SVM scores (K,): feet and
    heights from the boxes, no known person."""
    feet_px, height_px = feet_and_height_px(boxes)
    return Detections(feet_px, height_px, np.full(len(feet_px), -1), scores)
