"""The probabilistic occupancy map (POM): the posterior probability that each ground cell holds a person.

F. Fleuret, J. Berclaz, R. Lengagne and P. Fua, "Multicamera People Tracking
with a Probabilistic Occupancy Map", IEEE TPAMI 30(2), 2008: each frame on
its own, from binary foreground masks of calibrated views. ``X_k`` in
{0, 1} says whether cell ``k`` is occupied, with independent priors
``P(X_k = 1) = epsilon``. A person at cell ``k`` seen by view ``c``
covers the rectangle ``A_k^c``; the synthetic image of an occupancy ``X`` is
the union of its occupied cells' rectangles, ``A^c = 1 - prod_k (1 - X_k A_k^c)``,
and the foreground mask ``B^c`` of each view depends on ``X`` only through it::

    P(B^c | X) = exp(-Psi(B^c, A^c)) / Z,
    Psi(B, A) = |B (1 - A) + (1 - B) A| / (sigma |A|)

with ``|.|`` the sum over the pixels: the pixels where mask and synthetic
image disagree, counted relative to the synthetic image's area.

The posterior is approximated by the product law ``Q = prod_k q_k`` closest
to it in Kullback-Leibler divergence (mean field), whose fixed point is::

    q_k = 1 / (1 + exp(lambda + sum_c Psi(B^c, A_{k,1}^c) - Psi(B^c, A_{k,0}^c))),
    lambda = log((1 - epsilon) / epsilon),

where the expected distance given ``X_k = xi`` is replaced by the distance to
the average synthetic image given ``X_k = xi``::

    A_{k,xi}^c = 1 - (1 - xi A_k^c) prod_{j != k} (1 - q_j A_j^c).

Both differ from the average synthetic image ``A^c = 1 - prod_j (1 - q_j A_j^c)``
only inside rectangle ``k``: with ``N = 1 - A^c`` and ``n``, ``bn`` the sums
of ``N`` and ``B N`` over the rectangle (integral images, so O(1) per cell)::

    |A_{k,1}| = |A| + n,        |B A_{k,1}| = |B A| + bn,
    |A_{k,0}| = |A| - rho n,    |B A_{k,0}| = |B A| - rho bn,    rho = q_k / (1 - q_k),

and ``|B (1 - A) + (1 - B) A| = |B| + |A| - 2 |B A|``. ``N`` itself is the
exponential of the sum of ``log(1 - q_j)`` over the rectangles covering each
pixel, one 2-D prefix sum of their corners.

Where the paper leaves the iteration open we follow the authors' software:
all cells are updated together from the same average images (one pass of
integral images per iteration, the point of the O(1) update) and each new
value is mixed with the old, ``q <- damping q + (1 - damping) q_new``, which
keeps the joint update from oscillating (all cells that explain the same
blob would otherwise switch on together and off together); it stops when no
``q`` changes by more than the tolerance, or after the maximum number of
iterations. Every ``q`` starts at the prior. ``q`` is kept within
``[Q_FLOOR, 1 - Q_FLOOR]`` so that ``rho`` stays finite and ``|A| > 0``.

Masks are averaged over blocks of pixels (a fraction of foreground per block, which the distance above
takes as it is) and the rectangles are snapped to the blocks, the working resolution: both are made in
:mod:`ptztrack.occupancy.pom_rectangles`, which also gives a view without video the union of its
detector's boxes as its mask and scales its rectangles to the size its detector draws a person. Where
views have boxes, the candidates may be localized by the boxes' feet near them
(:mod:`ptztrack.occupancy.feet`): the cells place a person where the views' masks agree best, the feet
where each view's detector put them.
"""

import copy
from collections.abc import Sequence
from dataclasses import dataclass, replace

import cv2
import numpy as np
from scipy.special import expit

from ptztrack.occupancy.feet import localized_by_feet, recording_feet_m
from ptztrack.occupancy.foreground import ViewForeground
from ptztrack.occupancy.lpom import GroundGrid, Modes, map_modes
from ptztrack.occupancy.multiview import CameraView, MultiViewRecording
from ptztrack.occupancy.parameters import PomParameters
from ptztrack.occupancy.pom_rectangles import PersonBoxes, blocked_boxes, boxes_mask, cell_boxes_px, working_mask

Q_FLOOR = 1e-9
# The signs of a rectangle's corners (top-left, top-right, bottom-left, bottom-right) in a 2-D
# difference array (and in an integral image's box sum).
CORNER_SIGNS = np.array([1.0, -1.0, -1.0, 1.0])


def integral_image(image, out: np.ndarray | None = None) -> np.ndarray:
    """(rows + 1, columns + 1) float64: entry (y, x) is the sum of ``image[:y, :x]`` (a zero first row and
    column), written into ``out`` when given (OpenCV's integral, which is some twenty times NumPy's cumsum)."""
    image = np.asarray(image)
    if image.dtype not in (np.uint8, np.float32, np.float64):
        image = image.astype(np.float64)
    return cv2.integral(np.ascontiguousarray(image), out, sdepth=cv2.CV_64F)


def flat_corners(boxes, columns: int) -> np.ndarray:
    """(4, K) flat indices into a (rows + 1, columns + 1) integral image of the corners (top-left, top-right,
    bottom-left, bottom-right) of boxes (K, 4) (left, top, right, bottom)."""
    left, top, right, bottom = np.asarray(boxes, dtype=np.int64).reshape(-1, 4).T
    stride = columns + 1
    return np.stack([top * stride + left, top * stride + right, bottom * stride + left, bottom * stride + right])


def corner_sums(flat_integral: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """The sums (K,) over boxes given by their :func:`flat_corners` of the image whose integral image,
    flattened, is ``flat_integral``."""
    return flat_integral[corners[3]] - flat_integral[corners[1]] - flat_integral[corners[2]] + flat_integral[corners[0]]


def box_sums(integral, boxes) -> np.ndarray:
    """The sums (K,) of the image whose :func:`integral_image` is ``integral`` over boxes (K, 4)
    (left, top, right, bottom), each covering ``[left, right) x [top, bottom)``."""
    return corner_sums(np.ravel(integral), flat_corners(boxes, np.shape(integral)[1] - 1))


class _ViewSolver:
    """One view's part of the iterations: its visible cells' rectangles and work buffers.

    cells : (M,) the visible cells; corners : (4, M) flat indices of their rectangles' corners
    (top-left, top-right, bottom-left, bottom-right) into a (rows + 1, columns + 1) integral image.
    The difference array of ``log N`` needs only the corners inside the (rows, columns) image (the
    others change no pixel of it): ``inside`` (4M,) marks them among ``corners.ravel()``, ``unique``
    their distinct flat indices into the image and ``slot`` where each adds. The buffers are kept
    from one iteration to the next (fresh large arrays would cost a page fault per page).
    """

    def __init__(self, boxes: PersonBoxes, index: int):
        rows, columns = self.shape = boxes.shapes[index]
        self.cells = np.flatnonzero(boxes.visible[index])
        view_boxes = boxes.boxes[index, self.cells]
        self.corners = flat_corners(view_boxes, columns)
        left, top, right, bottom = view_boxes.T.astype(np.int64)
        corner_rows = np.stack([top, top, bottom, bottom]).ravel()
        corner_columns = np.stack([left, right, left, right]).ravel()
        self.inside = (corner_rows < rows) & (corner_columns < columns)
        self.unique, self.slot = np.unique(
            corner_rows[self.inside] * columns + corner_columns[self.inside], return_inverse=True
        )
        self.delta = np.zeros((rows, columns))
        self.log_absent = np.zeros((rows + 1, columns + 1))
        self.absent = np.zeros((rows, columns), np.float32)
        self.masked = np.zeros((rows, columns), np.float32)
        self.absent_integral = np.zeros((rows + 1, columns + 1))
        self.masked_integral = np.zeros((rows + 1, columns + 1))

    def distance_change(self, mask: np.ndarray, total_mask: float, q: np.ndarray, sigma: float) -> np.ndarray:
        """``Psi(B, A_{k,1}) - Psi(B, A_{k,0})`` (M,) for the visible cells, given all cells' q and the
        view's mask (rows, columns) float32 of ``total_mask`` foreground."""
        rows, columns = self.shape
        q_view = q[self.cells]
        # log N = sum of log(1 - q) over the rectangles covering a pixel: a difference array's 2-D prefix sum.
        weights = (CORNER_SIGNS[:, None] * np.log1p(-q_view)[None, :]).ravel()[self.inside]
        self.delta.fill(0.0)
        self.delta.ravel()[self.unique] = np.bincount(self.slot, weights, minlength=len(self.unique))
        integral_image(self.delta, self.log_absent)
        np.exp(self.log_absent[1:, 1:], out=self.absent, casting="same_kind")  # N = 1 - A
        np.multiply(mask, self.absent, out=self.masked)
        integral_image(self.absent, self.absent_integral)
        integral_image(self.masked, self.masked_integral)
        absent_flat, masked_flat = self.absent_integral.ravel(), self.masked_integral.ravel()
        total_a = rows * columns - absent_flat[-1]  # |A|
        total_ba = total_mask - masked_flat[-1]  # |B A|
        n = corner_sums(absent_flat, self.corners)
        bn = corner_sums(masked_flat, self.corners)
        rho = q_view / (1.0 - q_view)
        area_1, overlap_1 = total_a + n, total_ba + bn
        # |A_{k,0}| > 0 whenever another visible cell has q > 0; the floor guards its rounding.
        area_0, overlap_0 = np.maximum(total_a - rho * n, Q_FLOOR), total_ba - rho * bn
        psi_1 = (total_mask + area_1 - 2 * overlap_1) / (sigma * area_1)
        psi_0 = (total_mask + area_0 - 2 * overlap_0) / (sigma * area_0)
        return psi_1 - psi_0


@dataclass(frozen=True)
class PomResult:
    """The mean-field posterior: q (cells,) the probability that each cell is occupied; iterations run;
    converged, whether the last iteration changed no q by more than the tolerance; change, that largest change."""

    q: np.ndarray
    iterations: int
    converged: bool
    change: float


class PomSolver:
    """The mean-field iterations of the POM (module docstring) over fixed rectangles (``posterior(masks)``).

    Each view's corners, index tables and work buffers are prepared once, for every frame.
    """

    def __init__(self, boxes: PersonBoxes):
        self.boxes = boxes
        self.views = [_ViewSolver(boxes, index) for index in range(len(boxes.shapes))]

    def posterior(self, masks: Sequence[np.ndarray | None], parameters: PomParameters) -> PomResult:
        """Iterate the fixed point from the prior.

        masks : per view, its working mask (:func:`~ptztrack.occupancy.pom_rectangles.working_mask`, rows x
        columns of ``boxes.shapes``, values in [0, 1]) or None where the view has nothing this frame (it is
        left out). Uses ``prior``, ``sigma``, ``damping``, ``max_iterations`` and ``tolerance``.
        """
        used = []
        for view, mask in zip(self.views, masks, strict=True):
            if mask is None or len(view.cells) == 0:
                continue
            mask = np.asarray(mask, dtype=np.float32)
            if mask.shape != view.shape:
                raise ValueError(f"a mask is {mask.shape[0]} x {mask.shape[1]}, its view's working image {view.shape}")
            used.append((view, mask, float(mask.sum(dtype=np.float64))))
        cells = self.boxes.visible.shape[1]
        q = np.full(cells, float(np.clip(parameters.prior, Q_FLOOR, 1 - Q_FLOOR)))
        log_prior_ratio = np.log((1 - parameters.prior) / parameters.prior)
        change, iterations = np.inf, 0
        while iterations < parameters.max_iterations and change >= parameters.tolerance:
            evidence = np.zeros(cells)
            for view, mask, total_mask in used:
                evidence[view.cells] += view.distance_change(mask, total_mask, q, parameters.sigma)
            updated = parameters.damping * q + (1 - parameters.damping) * expit(-(log_prior_ratio + evidence))
            updated = np.clip(updated, Q_FLOOR, 1 - Q_FLOOR)
            change = float(np.max(np.abs(updated - q), initial=0.0))
            q, iterations = updated, iterations + 1
        return PomResult(q, iterations, change < parameters.tolerance, change)


def pom_posterior(boxes: PersonBoxes, masks: Sequence[np.ndarray | None], parameters: PomParameters) -> PomResult:
    """:meth:`PomSolver.posterior` of one frame (a solver of its own: for many frames keep a :class:`PomSolver`)."""
    return PomSolver(boxes).posterior(masks, parameters)


def pom_modes(
    q_map, grid: GroundGrid, separation_m: float, window_m: float, min_probability: float, view_counts=None
) -> Modes:
    """The candidates of a POM ``q_map`` (rows, columns): cells whose q is the largest within
    ``separation_m`` and at least ``min_probability``, strongest first.

    Positions and covariances as :func:`ptztrack.occupancy.lpom.map_modes` (the q-weighted mean and
    spread over the disc of ``window_m``); the strength is the cell's q itself (a probability, not
    relative to the frame's largest); with ``view_counts`` (cells,), the views that see each cell, a
    candidate's ``views`` are those of the cell its position lies in.
    """
    peak = float(np.max(q_map, initial=0.0))
    if peak < min_probability or peak <= 0:
        return Modes.empty()
    modes = map_modes(q_map, grid, separation_m, window_m, min_probability / peak)
    views = None
    if view_counts is not None:
        cells, on_grid = grid.cell_of(modes.position_m)
        views = np.where(on_grid, np.asarray(view_counts)[cells], 0)
    return Modes(modes.position_m, modes.covariance_m2, modes.strength * peak, views)


class PomDetector:
    """The POM and its candidates for frames of ``recording`` (``detect(frame, masks)``).

    The cells' rectangles (:func:`~ptztrack.occupancy.pom_rectangles.person_boxes`) are computed on
    construction, for every view; each view needs its image size. A view's mask at a frame is the one given,
    else the silhouettes of its background model in ``foregrounds`` (by view index:
    :func:`~ptztrack.occupancy.foreground.view_foregrounds`, learned online on the frames before), else the
    union of its detector's boxes (:func:`~ptztrack.occupancy.pom_rectangles.boxes_mask`); a view with none
    is left out.
    """

    def __init__(
        self,
        recording: MultiViewRecording,
        parameters: PomParameters,
        foregrounds: dict[int, ViewForeground] | None = None,
    ):
        self.recording, self.parameters = recording, parameters
        self.foreground = foregrounds or {}
        self.grid = GroundGrid.covering(recording.area_m, parameters.cell_m)
        for view in recording.views:
            if view.image_size_px is None:
                raise ValueError(f"{view.name}: POM needs the view's image size (its rectangles and masks)")
        self.boxes_px = cell_boxes_px(
            [view.calibration for view in recording.views], self.grid, parameters.height_m, parameters.width_m
        )
        self._use_boxes(None)
        self.feet_variances_m2: np.ndarray | None = None
        self.last: PomResult | None = None

    def _use_boxes(self, box_scales) -> None:
        self.boxes = blocked_boxes(
            self.boxes_px, [_size(view) for view in self.recording.views], self.parameters.block_px, box_scales
        )
        self.solver = PomSolver(self.boxes)
        self.view_counts = self.boxes.visible.sum(axis=0)  # (cells,) the views that see each cell

    def _copy(self, **attributes) -> "PomDetector":
        """A shallow copy with ``attributes`` replaced and no last result."""
        other = copy.copy(self)
        for name, value in attributes.items():
            setattr(other, name, value)
        other.last = None
        return other

    def with_prior(self, prior: float) -> "PomDetector":
        """This detector with another prior ``epsilon``, sharing its rectangles, solver and background models."""
        return self._copy(parameters=replace(self.parameters, prior=prior))

    def with_box_scales(self, box_scales) -> "PomDetector":
        """This detector with each view's rectangles scaled about their feet by its row of ``box_scales``
        (views, 2) (width factor, height factor; :func:`~ptztrack.occupancy.pom_rectangles.fitted_box_scales`):
        new rectangles and solver."""
        other = self._copy()
        other._use_boxes(box_scales)
        return other

    def with_feet_variances(self, variances_m2) -> "PomDetector":
        """This detector with its candidates localized by the views' box feet near them
        (:func:`~ptztrack.occupancy.feet.localized_by_feet`, within ``feet_gate_m``), each view's feet of
        variance ``variances_m2`` (views,) m^2 per axis (:func:`~ptztrack.occupancy.feet.fitted_feet_variances`)."""
        return self._copy(feet_variances_m2=np.asarray(variances_m2, dtype=float))

    def with_masks_from_boxes(self) -> "PomDetector":
        """This detector with every view that has a detector's boxes taking its mask from them, its
        silhouettes unused."""
        boxless = {
            index: model for index, model in self.foreground.items() if self.recording.views[index].boxes is None
        }
        return self._copy(foreground=boxless)

    def box_mask_views(self) -> list[int]:
        """The views whose mask is the union of their detector's boxes (they have boxes and no silhouettes)."""
        return [
            index
            for index, view in enumerate(self.recording.views)
            if view.boxes is not None and index not in self.foreground
        ]

    def view_masks(self, frame: int, masks: Sequence[np.ndarray | None] | None = None) -> list[np.ndarray | None]:
        """Per view, its working mask at ``frame``: from ``masks`` (full-resolution, per view, None where
        not given), its silhouettes or its boxes; None where it has none."""
        given: list[np.ndarray | None] = list(masks) if masks is not None else [None] * len(self.recording.views)
        for index, model in self.foreground.items():
            if given[index] is None:
                given[index] = model.silhouettes(frame)
        working: list[np.ndarray | None] = []
        for view, mask in zip(self.recording.views, given, strict=True):
            if mask is None and view.boxes is not None:
                mask = boxes_mask(view.boxes[frame], _size(view), self.parameters.min_box_score)
            working.append(None if mask is None else working_mask(mask, self.parameters.block_px))
        return working

    def detect(self, frame: int, masks: Sequence[np.ndarray | None] | None = None) -> tuple[np.ndarray, Modes]:
        """The POM (rows, columns) at ``frame`` and its candidates (strength: q), given per view a
        full-resolution foreground mask (height, width) or None (its boxes, if any, stand in).

        The detections are the candidates of at least ``min_probability`` (or of a threshold fitted
        on other frames), localized by the views' box feet where the detector has their variances
        (:meth:`with_feet_variances`); ``last`` keeps the frame's :class:`PomResult` (iterations, convergence).
        """
        parameters = self.parameters
        self.last = self.solver.posterior(self.view_masks(frame, masks), parameters)
        q_map = self.last.q.reshape(self.grid.shape)
        modes = pom_modes(
            q_map,
            self.grid,
            parameters.separation_m,
            parameters.window_m,
            parameters.candidate_probability,
            self.view_counts,
        )
        if self.feet_variances_m2 is not None:
            feet_m = recording_feet_m(self.recording, frame, parameters.min_box_score)
            modes = localized_by_feet(modes, feet_m, self.feet_variances_m2, parameters.feet_gate_m)
        return q_map, modes


def _size(view: CameraView) -> tuple[int, int]:
    assert view.image_size_px is not None
    return view.image_size_px
