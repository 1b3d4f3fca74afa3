"""A motion history image for a camera that turns and zooms (seed 003, section III-C1 and III-C4).

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
the pose the camera lands on (:func:`ptztrack.loop.run_loop`), so two
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
    """

    history: np.ndarray
    known: np.ndarray
    grey: np.ndarray
    scale: float


def _grey(image_bgr, scale: float) -> np.ndarray:
    grey = cv2.cvtColor(np.ascontiguousarray(image_bgr, dtype=np.uint8), cv2.COLOR_BGR2GRAY)
    if scale != 1.0:
        grey = cv2.resize(grey, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)
    return grey.astype(np.float32)


def first_motion_image(image_bgr, scale: float = 0.5) -> MotionImage:
    """The motion image of the first frame: nothing known, nothing moving."""
    grey = _grey(image_bgr, scale)
    return MotionImage(np.zeros_like(grey), np.zeros(grey.shape, bool), grey, scale)


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
    stacked = np.dstack([previous.grey, previous.history, np.ones_like(grey)])
    warped = cv2.warpPerspective(
        stacked, scaled_homography, (width, height), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT
    )
    known = cv2.erode((warped[..., 2] > 0.999).astype(np.uint8), NEIGHBOURHOOD).astype(bool)
    highest = cv2.dilate(warped[..., 0], NEIGHBOURHOOD)
    lowest = cv2.erode(warped[..., 0], NEIGHBOURHOOD)
    moving = ((grey > highest + threshold) | (grey < lowest - threshold)) & known
    history = np.where(moving, np.float32(1.0), np.maximum(warped[..., 1] - np.float32(decay), 0.0))
    return MotionImage(np.where(known, history, np.float32(0.0)), known, grey, previous.scale)


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

    def box_sums(image) -> np.ndarray:
        integral = cv2.integral(image, sdepth=cv2.CV_64F)
        return np.sum(
            integral[row1, col1] - integral[row0, col1] - integral[row1, col0] + integral[row0, col0], axis=-1
        )

    known = box_sums(motion.known.astype(np.float32))
    moving = box_sums(motion.history)
    return np.where(known > 0, 1.0 - moving / np.maximum(known, 1.0), 1.0)
