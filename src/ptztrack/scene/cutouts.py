"""Real pedestrians cut out of an annotated recording, to be pasted into rendered views.

A rendered cone body is not a person to a detector that was trained on real pixels in every respect
(:mod:`ptztrack.scene.render`); a pedestrian cut out of a real recording is, but for the scale, the
place and the surroundings it is pasted into. :func:`cut_people` takes a fixed camera's frames and its
annotated boxes: a per-pixel median of the frames is the empty scene (the background model), and a
person's pixels are those around their box that differ from it (the foreground mask, cleaned and
softened into an alpha matte). Only people alone (their widened box meets no other box), wholly in the
image and at least ``min_height_px`` tall are cut, and only runs of consecutive frames of one person
(:class:`CutoutTrack`: a walk, its gait included). :func:`paste_people` scales a cutout so that its
annotated box is the person's projected height, stands its box's bottom centre on their projected
feet and pastes the far people first (the painter's algorithm), mirrored where the recorded person
walked the other way across the image.
"""

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from ptztrack.geometry.calibration import PinholeCalibration, camera_centre_m

MARGIN_X, MARGIN_TOP, MARGIN_BOTTOM = 0.2, 0.05, 0.05  # a cut's region: the box widened by these fractions
DIFFERENCE_THRESHOLD = 30  # grey levels: a pixel is foreground where a colour differs this much from the median
BACKGROUND_FRAMES = 100  # at most this many frames, evenly spaced, make the median
MIN_FOREGROUND, MAX_FOREGROUND = 0.25, 0.9  # of the box's area: a mask outside is not a person alone
MIN_RUN = 8  # consecutive frames of one person, at least
ALPHA_BLUR_PX = 1.0


@dataclass(frozen=True)
class Cutout:
    """One person cut out of one frame: ``image`` (h, w, 3) uint8 BGR and ``alpha`` (h, w) float32 in
    [0, 1], the person's matte; ``feet_px`` (2,) the annotated box's bottom centre and ``height_px`` its
    height, in the cut's pixels."""

    image: np.ndarray
    alpha: np.ndarray
    feet_px: np.ndarray
    height_px: float


@dataclass(frozen=True)
class CutoutTrack:
    """One person's cutouts over consecutive frames, and whether they walked rightwards in the image."""

    person_id: int
    cutouts: tuple[Cutout, ...]
    moving_right: bool


def median_background(frames: Sequence[np.ndarray]) -> np.ndarray:
    """The per-pixel median (h, w, 3) uint8 of frames (each (h, w, 3) uint8): the empty scene where
    people pass a pixel less than half the time."""
    return np.median(np.stack(frames), axis=0).astype(np.uint8)


def isolated_boxes(frame, boxes_px, image_size_px, min_height_px: float) -> np.ndarray:
    """Which annotated boxes (K, 4) (left, top, width, height) px, of frames (K,), can be cut: their
    widened region (the box plus the margins) lies in the image and meets no other box of the frame, and
    the box is at least ``min_height_px`` tall; (K,) bool."""
    frame, boxes_px = np.asarray(frame), np.asarray(boxes_px, dtype=float).reshape(-1, 4)
    region = cut_regions(boxes_px)
    width_px, height_px = image_size_px
    usable = (
        (region[:, 0] >= 0)
        & (region[:, 1] >= 0)
        & (region[:, 2] <= width_px)
        & (region[:, 3] <= height_px)
        & (boxes_px[:, 3] >= min_height_px)
    )
    for index in np.flatnonzero(usable):
        others = np.flatnonzero((frame == frame[index]) & (np.arange(len(frame)) != index))
        left, top, width, height = boxes_px[others].T
        meets = (
            (left < region[index, 2])
            & (left + width > region[index, 0])
            & (top < region[index, 3])
            & (top + height > region[index, 1])
        )
        usable[index] = not meets.any()
    return usable


def cut_regions(boxes_px) -> np.ndarray:
    """The regions (K, 4) (x0, y0, x1, y1) whole pixels cut around boxes (K, 4) (left, top, width, height)."""
    left, top, width, height = np.asarray(boxes_px, dtype=float).reshape(-1, 4).T
    return np.stack(
        [
            np.floor(left - MARGIN_X * width),
            np.floor(top - MARGIN_TOP * height),
            np.ceil(left + (1 + MARGIN_X) * width),
            np.ceil(top + (1 + MARGIN_BOTTOM) * height),
        ],
        axis=-1,
    ).astype(int)


def person_matte(patch: np.ndarray, background: np.ndarray, box_px) -> np.ndarray | None:
    """The matte (h, w) float32 in [0, 1] of the person in ``patch`` (h, w, 3) uint8 over the same region of
    the background model, their box (left, top, width, height) in the patch's pixels; None where the
    foreground is not one person (less than MIN_FOREGROUND or more than MAX_FOREGROUND of the box).

    Foreground: a colour differs from the background by more than DIFFERENCE_THRESHOLD; closed by a disc
    of a sixth of the box's width (clothes the colour of the ground behind them leave gaps), its holes
    filled, and only the connected parts that reach into the box's middle third kept (not a passing
    shadow, a neighbour's elbow or noise); blurred by ALPHA_BLUR_PX.
    """
    difference = np.abs(patch.astype(np.int16) - background.astype(np.int16)).max(axis=2)
    mask = (difference > DIFFERENCE_THRESHOLD).astype(np.uint8)
    left, top, width, height = (int(round(value)) for value in box_px)
    side = max(3, 2 * round(width / 12) + 1)
    mask = cv2.morphologyEx(mask, cv2.MORPH_CLOSE, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (side, side)))
    count, labels = cv2.connectedComponents(mask)
    middle = labels[top + height // 3 : top + 2 * height // 3, left + width // 3 : left + 2 * width // 3]
    keep = np.isin(labels, np.setdiff1d(np.unique(middle), [0])).astype(np.uint8)
    # Holes: the background pixels that the border cannot reach.
    outside = np.pad(1 - keep, 1, constant_values=1)
    cv2.floodFill(outside, None, (0, 0), 2)
    keep[outside[1:-1, 1:-1] == 1] = 1
    share = keep.sum() / max(width * height, 1)
    if not MIN_FOREGROUND <= share <= MAX_FOREGROUND:
        return None
    return cv2.GaussianBlur(keep.astype(np.float32), (0, 0), ALPHA_BLUR_PX)


def cut_people(
    frames: Iterable[tuple[int, np.ndarray]],
    frame_count: int,
    annotation_frame,
    person_id,
    boxes_px,
    min_height_px: float = 60.0,
) -> list[CutoutTrack]:
    """The people of a fixed camera's recording, cut out (see the module's docstring).

    frames : (index, (h, w, 3) uint8 BGR) of every frame in order, read once; frame_count : how many;
    annotation_frame, person_id : (K,) the annotations' 0-based frames and people; boxes_px : (K, 4)
    (left, top, width, height) px. Returns the runs of at least MIN_RUN consecutive frames of a person
    alone, in the order of their people and frames.
    """
    annotation_frame, person_id = np.asarray(annotation_frame), np.asarray(person_id)
    boxes_px = np.asarray(boxes_px, dtype=float).reshape(-1, 4)
    every = max(1, frame_count // BACKGROUND_FRAMES)
    regions = cut_regions(boxes_px)
    samples: list[np.ndarray] = []
    patches: dict[int, np.ndarray] = {}
    usable: np.ndarray | None = None
    for index, image in frames:
        if usable is None:
            usable = isolated_boxes(annotation_frame, boxes_px, (image.shape[1], image.shape[0]), min_height_px)
        if index % every == 0:
            samples.append(image)
        for cut in np.flatnonzero(usable & (annotation_frame == index)):
            x0, y0, x1, y1 = regions[cut]
            patches[int(cut)] = image[y0:y1, x0:x1].copy()
    if not samples:
        return []
    background = median_background(samples)
    cutouts: dict[int, Cutout] = {}
    for row, patch in patches.items():
        x0, y0, x1, y1 = regions[row]
        left, top, width, height = boxes_px[row]
        box_in_patch = (left - x0, top - y0, width, height)
        alpha = person_matte(patch, background[y0:y1, x0:x1], box_in_patch)
        if alpha is not None:
            feet_px = np.array([left - x0 + width / 2, top - y0 + height])
            cutouts[row] = Cutout(patch, alpha, feet_px, float(height))
    return _runs(cutouts, annotation_frame, person_id, boxes_px)


def _runs(cutouts: dict[int, Cutout], annotation_frame, person_id, boxes_px) -> list[CutoutTrack]:
    """The runs of consecutive frames of one person among the cut rows, MIN_RUN long at least."""
    tracks = []
    for person in np.unique(person_id):
        rows = [int(row) for row in np.flatnonzero(person_id == person) if int(row) in cutouts]
        rows.sort(key=lambda row: annotation_frame[row])
        run: list[int] = []
        for row in [*rows, None]:
            if row is not None and run and annotation_frame[row] == annotation_frame[run[-1]] + 1:
                run.append(row)
                continue
            if len(run) >= MIN_RUN:
                centre_px = boxes_px[run, 0] + boxes_px[run, 2] / 2
                tracks.append(
                    CutoutTrack(int(person), tuple(cutouts[r] for r in run), bool(centre_px[-1] >= centre_px[0]))
                )
            run = [row] if row is not None else []
    return tracks


def paste_people(
    background: np.ndarray,
    calibration: PinholeCalibration,
    boxes_px,
    feet_m,
    cutouts: Sequence[Cutout],
    mirrored: Sequence[bool],
) -> np.ndarray:
    """The background (h, w, 3) uint8 with people pasted over it, far ones first.

    boxes_px : (N, 4) each person's box in the view (left, top, width, height; its bottom centre the
    feet, its height the person's: :func:`~ptztrack.scene.render.person_boxes`); feet_m : (N, 2) their
    ground positions, for the order; cutouts : (N,) the cutout each is drawn as, scaled so that its
    annotated height is the box's, its feet on the box's; mirrored : (N,) flipped left to right.
    """
    image = background.astype(np.float32)
    boxes_px = np.asarray(boxes_px, dtype=float).reshape(-1, 4)
    feet_m = np.asarray(feet_m, dtype=float).reshape(-1, 2)
    range_m = np.linalg.norm(np.c_[feet_m, np.zeros(len(feet_m))] - camera_centre_m(calibration), axis=-1)
    height_px, width_px = image.shape[:2]
    for person in np.argsort(-range_m):
        cutout, (left, top, box_width, box_height) = cutouts[person], boxes_px[person]
        scale = box_height / cutout.height_px
        size = (max(1, round(cutout.image.shape[1] * scale)), max(1, round(cutout.image.shape[0] * scale)))
        if size[0] > 4 * width_px or size[1] > 4 * height_px:
            continue  # nearer the camera than anybody is ever recorded
        interpolation = cv2.INTER_AREA if scale < 1 else cv2.INTER_LINEAR
        patch = cv2.resize(cutout.image, size, interpolation=interpolation).astype(np.float32)
        alpha = cv2.resize(cutout.alpha, size, interpolation=interpolation)
        feet_x = cutout.feet_px[0] * size[0] / cutout.image.shape[1]
        if mirrored[person]:
            patch, alpha, feet_x = patch[:, ::-1], alpha[:, ::-1], size[0] - feet_x
        x0 = int(round(left + box_width / 2 - feet_x))
        y0 = int(round(top + box_height - cutout.feet_px[1] * size[1] / cutout.image.shape[0]))
        # The part of the patch inside the image.
        u0, v0 = max(0, -x0), max(0, -y0)
        u1, v1 = min(size[0], width_px - x0), min(size[1], height_px - y0)
        if u1 <= u0 or v1 <= v0:
            continue
        weight = alpha[v0:v1, u0:u1, None]
        target = image[y0 + v0 : y0 + v1, x0 + u0 : x0 + u1]
        target[:] = weight * patch[v0:v1, u0:u1] + (1 - weight) * target
    return np.clip(np.rint(image), 0, 255).astype(np.uint8)
