"""A motion history image for a camera that turns and zooms (Nair et al., IROS 2008, sections III-C1 and III-C4).

The robot-cameraman paper's tracking camera stood still and differenced
consecutive frames into a motion history image (Bobick and Davis): a pixel
is 1 where it changed now and fades over the following frames. A PTZ camera
moves, so the previous frame is first carried into the current view. For a
camera turning about its optical centre every scene point, near or far, maps
from the previous view to the current one by the homography
``K2 R2 R1^T K1^-1`` of the two poses
(:func:`ptztrack.geometry.ptz.rotation_homography`); the previous frame and
its motion history are warped by it, and only then differenced. Pixels the
previous view did not see are *unknown*: they hold no motion and the
likelihood ignores them.

While the camera moves between poses. The closed loop images each step at
the pose the camera lands on (:func:`ptztrack.loop.simulated.run_loop`), so two
frames are two exact views of one centre and the homography registers
them up to resampling. What a real camera adds (the pose known only to the
pose source's accuracy, a frame exposed while turning) misregisters edges
by a pixel or two. So a pixel counts as moving only if it differs by more
than ``threshold`` grey levels from *every* warped previous pixel in its
3 x 3 neighbourhood (the neighbourhood's minimum and maximum, by erosion and
dilation), which absorbs a one-pixel misregistration and the blur that
resampling a zoom change adds, and keeps a walker, who moves several pixels
per frame. The test turns and zooms a camera over a static textured scene
and finds the motion image nearly empty.

The motion image is computed at ``scale`` times the view's resolution
(0.5 by default): motion is coarse, and a quarter of the pixels costs a
quarter of the time.
"""

from dataclasses import dataclass

import cv2
import numpy as np

from ptztrack.track.appearance import pixel_span

NEIGHBOURHOOD = np.ones((3, 3), np.uint8)


@dataclass(frozen=True)
class MotionImage:
    """The motion history after a frame, at ``scale`` times the view's resolution.

    history : (h, w) float32 in [0, 1]: 1 where the pixel moved at this frame, fading by ``decay``
        per frame after; 0 where it has not moved lately or is unknown.
    known : (h, w) bool, pixels the previous view also saw (all False at the first frame).
    grey : (h, w) float32, this frame in grey levels, to difference the next one against.
    scale : the resolution relative to the view's.
    sums : (h + 1, w + 1, 2) float64, the integral images of ``known`` and ``history`` (box sums by
        four look-ups).
    """

    history: np.ndarray
    known: np.ndarray
    grey: np.ndarray
    scale: float
    sums: np.ndarray


def motion_image_of(history, known, grey, scale: float) -> MotionImage:
    """The motion image with its integral images, of (h, w) float32 history, bool known and float32 grey."""
    sums = cv2.integral(cv2.merge([known.astype(np.float32), history]), sdepth=cv2.CV_64F)
    return MotionImage(history, known, grey, scale, sums)


def _grey(image_bgr, scale: float) -> np.ndarray:
    grey = cv2.cvtColor(np.ascontiguousarray(image_bgr, dtype=np.uint8), cv2.COLOR_BGR2GRAY)
    if scale != 1.0:
        grey = cv2.resize(grey, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)
    return grey.astype(np.float32)


def first_motion_image(image_bgr, scale: float = 0.5) -> MotionImage:
    """The motion image of the first frame: nothing known, nothing moving."""
    grey = _grey(image_bgr, scale)
    return motion_image_of(np.zeros_like(grey), np.zeros(grey.shape, bool), grey, scale)


def next_motion_image(
    previous: MotionImage, image_bgr, homography, threshold: float = 15.0, decay: float = 1 / 3
) -> MotionImage:
    """The motion image of a frame (h, w, 3) uint8 BGR whose view the previous frame's maps into by
    ``homography`` (3, 3), in the view's pixels (centre of pixel (i, j) at (j + 0.5, i + 0.5)).

    threshold : grey levels a pixel must differ by from its warped 3 x 3 neighbourhood to move.
    decay : how much of the history fades per frame (1 / frames it lasts).
    """
    grey = _grey(image_bgr, previous.scale)
    height, width = grey.shape
    # From the view's pixel coordinates to OpenCV's at this scale (pixel centres at integers) and back.
    to_scaled = np.array([[previous.scale, 0, -0.5], [0, previous.scale, -0.5], [0, 0, 1]])
    scaled_homography = to_scaled @ np.asarray(homography, dtype=float) @ np.linalg.inv(to_scaled)
    warped = cv2.warpPerspective(
        cv2.merge([previous.grey, previous.history]), scaled_homography, (width, height), flags=cv2.INTER_LINEAR
    )
    warped_grey, warped_history = cv2.split(warped)
    known = _seen_before(scaled_homography, (width, height))
    # OpenCV's element-wise operations: several times faster than NumPy's on these images.
    rose = cv2.compare(cv2.subtract(grey, cv2.dilate(warped_grey, NEIGHBOURHOOD)), threshold, cv2.CMP_GT)
    fell = cv2.compare(cv2.subtract(cv2.erode(warped_grey, NEIGHBOURHOOD), grey), threshold, cv2.CMP_GT)
    moving = cv2.bitwise_and(cv2.bitwise_or(rose, fell), known)
    faded = cv2.max(cv2.subtract(warped_history, float(decay)), 0.0)
    history = cv2.max(faded, moving * np.float32(1 / 255))
    return motion_image_of(cv2.multiply(history, known * np.float32(1 / 255)), known > 0, grey, previous.scale)


def _seen_before(homography, size) -> np.ndarray:
    """(h, w) uint8 255 where the previous view (the same size) maps with its 3 x 3 neighbourhood, else 0.

    The previous image's rectangle maps to a convex quadrilateral when the camera turns by less
    than the field of view; a turn beyond it leaves nothing known.
    """
    width, height = size
    corners = np.array([[0, 0], [width - 1, 0], [width - 1, height - 1], [0, height - 1]], dtype=float)
    mapped = np.c_[corners, np.ones(4)] @ np.asarray(homography).T
    known = np.zeros((height, width), np.uint8)
    if np.all(mapped[:, 2] > 0):
        polygon = np.round(mapped[:, :2] / mapped[:, 2:] * 16).astype(np.int32)  # 4 fractional bits
        cv2.fillConvexPoly(known, polygon, 255, lineType=cv2.LINE_8, shift=4)
    return cv2.erode(known, NEIGHBOURHOOD)


def non_motion_fraction(motion: MotionImage, boxes_px) -> np.ndarray:
    """E of equation 4 per candidate: the fraction of the known pixels under its boxes that do not move.

    boxes_px : (..., K, 4) (left, top, width, height) in the view's pixels, the K patches of each
    candidate (...). Motion counts as ``history`` (a pixel that moved a few frames ago counts in
    part). The paper counts non-motion pixels; a fraction keeps the likelihood from favouring
    smaller boxes, which have fewer pixels. A candidate with no known pixel gets 1 (no motion seen).
    Returns (...) in [0, 1].
    """
    boxes = np.asarray(boxes_px, dtype=float) * motion.scale
    height, width = motion.history.shape
    col0, col1 = pixel_span(boxes[..., 0], boxes[..., 0] + boxes[..., 2], width)
    row0, row1 = pixel_span(boxes[..., 1], boxes[..., 1] + boxes[..., 3], height)

    sums = motion.sums
    box_sums = sums[row1, col1] - sums[row0, col1] - sums[row1, col0] + sums[row0, col0]  # (..., K, 2)
    known, moving = np.moveaxis(np.sum(box_sums, axis=-2), -1, 0)
    return np.where(known > 0, 1.0 - moving / np.maximum(known, 1.0), 1.0)
