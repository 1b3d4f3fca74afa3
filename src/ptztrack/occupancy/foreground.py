"""Foreground silhouettes of a fixed view and their edges: the occupancy map's evidence from a background model.

Motion edges (:mod:`ptztrack.occupancy.motion_edges`) respond to whatever
changed between two frames: the pavement a walker uncovers as much as the
walker. A background model answers the question the locus asks, where the
person is in the image: each pixel is compared with what that pixel
usually shows. The model is OpenCV's MOG2 (Zivkovic, ICPR 2004), one per
view: every pixel keeps a mixture of up to five Gaussians in colour, with
weights ``pi_m``, means ``mu_m`` and variances ``sigma_m**2``, and learns each
frame at the rate ``alpha``::

    pi_m <- pi_m + alpha * (o_m - pi_m),    alpha = 1 / min(2 n, history)

(``o_m`` is 1 for the component the pixel matches and 0 for the others;
n counts the frames the model has seen: OpenCV's schedule). A pixel ``x``
is background when it lies within ``var_threshold`` of one of the heaviest
components, in squared Mahalanobis distance ``|x - mu_m|**2 / sigma_m**2``;
a shadow when it is a darker copy of such a component (its brightness
ratio to it in [``shadow_threshold``, 1]), which MOG2 marks 127 and the
silhouettes leave out. A morphological opening then removes specks of
sensor noise and a closing joins a body's parts (:func:`clean_silhouettes`).
The silhouettes' edges (:func:`silhouette_edges`) are the pixels where a
ray grazes a person, which is what the locus's touch constraint assumes
(:mod:`ptztrack.occupancy.locus`).

The model is online: a frame's silhouettes come from a model that learned
only the frames before it, in order, from the recording's first
(:class:`ViewForeground`), its lead-in frames included where it has some
(frames before the first that nothing scores). No frame's background is
learned from the frame itself or from a later one, so the experiment's
halves (each scored with a threshold fitted on the other,
:func:`ptztrack.occupancy.evaluation.halves`) see only what a live camera
would have seen by then. Without a lead-in the price is the recording's
first frames: the model has no background on the first (its silhouettes are
empty) and learns fast at first (the schedule above), so that people present
from the start are partly taken into the background until they move off.

The masks are deterministic: the same frames give the same masks whatever
OpenCV's thread count, since MOG2 updates each pixel from that pixel's own
history only (its rows are split between threads, never combined) and the
opening and closing are minima and maxima over fixed neighbourhoods.
"""

import cv2
import numpy as np

from ptztrack.occupancy.multiview import FrameSource, MultiViewRecording
from ptztrack.occupancy.parameters import ForegroundParameters

FOREGROUND = 255  # MOG2's mark for a foreground pixel; shadows are 127 and background 0
# A silhouette pixel is on its edge if one of its 4 neighbours is background: 8-connected edges, one pixel thick.
CROSS = cv2.getStructuringElement(cv2.MORPH_CROSS, (3, 3))


def background_subtractor(parameters: ForegroundParameters) -> cv2.BackgroundSubtractorMOG2:
    """A fresh MOG2 background model with ``parameters`` (OpenCV's other settings at their defaults).

    Parameters
    ----------
    parameters : the model's history, variance threshold and shadow settings.

    Returns
    -------
    cv2.BackgroundSubtractorMOG2
        Its ``apply(image)`` learns an image (height, width, 3) uint8 BGR and returns its mask
        (height, width) uint8: 255 foreground, 127 shadow, 0 background.
    """
    subtractor = cv2.createBackgroundSubtractorMOG2(
        history=parameters.history, varThreshold=parameters.var_threshold, detectShadows=parameters.detect_shadows
    )
    subtractor.setShadowThreshold(parameters.shadow_threshold)
    return subtractor


def clean_silhouettes(mask_u8, parameters: ForegroundParameters) -> np.ndarray:
    """The silhouettes of a MOG2 mask: its foreground without shadows, opened, then closed.

    Parameters
    ----------
    mask_u8 : (height, width) uint8
        MOG2's mask: 255 foreground, 127 shadow, 0 background.
    parameters : the structuring elements' sides ``opening_px`` and ``closing_px`` (squares).

    Returns
    -------
    np.ndarray
        (height, width) bool, True on the silhouettes.
    """
    foreground = (np.asarray(mask_u8) == FOREGROUND).astype(np.uint8)
    opening = np.ones((parameters.opening_px, parameters.opening_px), np.uint8)
    closing = np.ones((parameters.closing_px, parameters.closing_px), np.uint8)
    foreground = cv2.morphologyEx(foreground, cv2.MORPH_OPEN, opening)
    foreground = cv2.morphologyEx(foreground, cv2.MORPH_CLOSE, closing)
    return foreground > 0


def silhouette_edges(silhouettes) -> np.ndarray:
    """The boundary pixels of silhouettes: those with a background pixel among their 4 neighbours.

    ``edges = S & ~erode(S, cross)``. The image's border is not a boundary (a silhouette cut by the
    frame goes on outside it): the erosion replicates the border's pixels beyond it.

    Parameters
    ----------
    silhouettes : (height, width) bool

    Returns
    -------
    np.ndarray
        (height, width) bool, True on the silhouettes' edges (a subset of the silhouettes).
    """
    silhouettes = np.asarray(silhouettes, dtype=bool)
    inner = cv2.erode(silhouettes.astype(np.uint8), CROSS, borderType=cv2.BORDER_REPLICATE) > 0
    return silhouettes & ~inner


class ViewForeground:
    """The silhouettes and their edges of one fixed view, frame by frame, from a model of its past frames.

    ``silhouettes(t)`` is the mask of frame t against the model that learned frames ``first_frame``,
    ..., t - 1 in order (MOG2 classifies each pixel of t against the components it has, then learns
    t). Asked for frames in order, each frame is learned once; a frame ahead of the next one is
    reached by learning the frames between, and an earlier frame by learning again from
    ``first_frame``, so that the masks depend on the frame alone, not on the order they were asked
    in. The last frame's masks are kept.

    Parameters
    ----------
    frames : the view's images, ``frames(t)`` (height, width, 3) uint8 BGR, from ``t = first_frame``.
    parameters : the model and its clean-up.
    first_frame : the first frame the model learns: 0, or minus the recording's lead-in frames.
    """

    def __init__(self, frames: FrameSource, parameters: ForegroundParameters, first_frame: int = 0):
        self.frames, self.parameters, self.first_frame = frames, parameters, first_frame
        self._subtractor = background_subtractor(parameters)
        self._learned = first_frame  # frames first_frame, ..., _learned - 1 are in the model
        self._last: tuple[int, np.ndarray] | None = None

    def silhouettes(self, frame: int) -> np.ndarray:
        """The silhouettes of ``frame`` (height, width) bool; none on ``first_frame`` (no background yet)."""
        if self._last is not None and self._last[0] == frame:
            return self._last[1]
        if frame < self._learned:
            self._subtractor, self._learned = background_subtractor(self.parameters), self.first_frame
        while self._learned < frame:
            self._subtractor.apply(self.frames(self._learned))
            self._learned += 1
        mask_u8 = self._subtractor.apply(self.frames(frame))
        self._learned = frame + 1
        # MOG2 has no component yet on its first frame: whatever it marks there is not foreground.
        first = frame == self.first_frame
        silhouettes = np.zeros(mask_u8.shape, bool) if first else clean_silhouettes(mask_u8, self.parameters)
        self._last = (frame, silhouettes)
        return silhouettes

    def edges(self, frame: int) -> np.ndarray:
        """The edges of ``frame``'s silhouettes (height, width) bool: the occupancy map's pixels."""
        return silhouette_edges(self.silhouettes(frame))


def view_foregrounds(recording: MultiViewRecording, parameters: ForegroundParameters) -> dict[int, ViewForeground]:
    """A background model per view of ``recording`` that has video, by view index: one set that every
    method reading silhouettes shares (each frame's masks are made once and kept), learning from the
    recording's first lead-in frame."""
    return {
        index: ViewForeground(view.frames, parameters, -recording.lead_in_frames)
        for index, view in enumerate(recording.views)
        if view.frames is not None
    }
