"""The locus-based probabilistic occupancy map (LPOM) and its modes: people found on the ground.

Algorithm 1 of Hu, Mutlu and Lanz (ICIAP 2013): every motion pixel of every
view adds its locus (:mod:`ptztrack.occupancy.locus`) for each sampled
height, weighted by its view's weight; the weights are normalised to sum to
1 and a kernel turns the loci into a density (equations 8 and 9). Here the
loci are accumulated on a ground grid (each locus sample adds its ``dt`` to
the cell it falls in) and the grid is smoothed by a Gaussian kernel of
``kernel_sigma_m``, which is the same kernel density estimate evaluated at
the cell centres up to the cell's quantisation.

The paper leaves the camera weight ``w_c`` open. We give each view's loci
in a frame the total weight ``weight_c`` (1 by default): a view's loci are
normalised to a distribution and the map is the weighted mixture of the
views' distributions, so that a view with many motion pixels (a near
person, a textured background, motion edges against a detector's box
outlines) does not drown the others.

The loci of a fixed camera's pixels never change, so :func:`locus_table`
computes them once per view, for the centre ray of each ``block_px`` x
``block_px`` block of pixels, as a sparse matrix (blocks x cells); a frame's
map is then the product of that matrix with the frame's motion-pixel count
per block (:func:`table_map`). Points that are not on the block grid (a
detector's box outlines) go through :func:`locus_entries` directly
(:func:`points_map`).
"""

from dataclasses import dataclass

import numpy as np
from scipy import ndimage, sparse

from ptztrack.geometry.calibration import PinholeCalibration, pixel_rays
from ptztrack.occupancy.locus import ConeModel, person_locus

# Rays per chunk when building a table: about 0.5 GB of temporaries at 4 heights x 48 samples.
RAYS_PER_CHUNK = 20_000


@dataclass(frozen=True)
class GroundGrid:
    """A grid of square cells on the ground plane.

    origin_m : (x, y) of the grid's lower-left corner; cell_m : the cells' side;
    shape : (rows along y, columns along x).
    """

    origin_m: tuple[float, float]
    cell_m: float
    shape: tuple[int, int]

    @staticmethod
    def covering(area_m, cell_m: float) -> "GroundGrid":
        """The grid of ``cell_m`` cells that covers ``area_m`` [[x0, y0], [x1, y1]]."""
        (x0, y0), (x1, y1) = np.asarray(area_m, dtype=float)
        columns, rows = int(np.ceil((x1 - x0) / cell_m)), int(np.ceil((y1 - y0) / cell_m))
        return GroundGrid((float(x0), float(y0)), float(cell_m), (rows, columns))

    @property
    def cells(self) -> int:
        return self.shape[0] * self.shape[1]

    def cell_of(self, points_m) -> tuple[np.ndarray, np.ndarray]:
        """Flat cell index (...,) of ground points (..., 2) and whether each lies on the grid (...,)."""
        points_m = np.asarray(points_m, dtype=float)
        with np.errstate(invalid="ignore"):
            column = np.floor((points_m[..., 0] - self.origin_m[0]) / self.cell_m)
            row = np.floor((points_m[..., 1] - self.origin_m[1]) / self.cell_m)
        inside = (column >= 0) & (column < self.shape[1]) & (row >= 0) & (row < self.shape[0])
        return np.where(inside, row * self.shape[1] + column, 0).astype(np.int64), inside

    def centre_of(self, row, column) -> np.ndarray:
        """Ground points (..., 2) m of the centres of cells (row, column), fractional indices allowed."""
        return np.stack(
            [
                self.origin_m[0] + (np.asarray(column, dtype=float) + 0.5) * self.cell_m,
                self.origin_m[1] + (np.asarray(row, dtype=float) + 0.5) * self.cell_m,
            ],
            axis=-1,
        )


@dataclass(frozen=True)
class LocusSampling:
    """How the loci are sampled: the model, its heights (equation 9) and the tangent points per height.

    heights_m : (H,) the person heights the map integrates over; samples_per_height : tangent-point
    heights per person height (midpoints of equal slices of [0, h]).
    """

    model: ConeModel
    heights_m: tuple[float, ...]
    samples_per_height: int


def sampled_heights(min_height_m: float, max_height_m: float, step_m: float) -> tuple[float, ...]:
    """Algorithm 1's heights ``h = h_min; h < h_max; h += step``, taken at the midpoints of those steps
    (the midpoint rule for equation 9's integral over [h_min, h_max])."""
    count = max(1, int(np.ceil((max_height_m - min_height_m) / step_m - 1e-9)))
    return tuple(float(min_height_m + (index + 0.5) * step_m) for index in range(count))


def locus_entries(
    calibration: PinholeCalibration, pixels_px, grid: GroundGrid, sampling: LocusSampling
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every locus sample of the rays through ``pixels_px`` (N, 2) that falls on the grid.

    Returns (pixel index, flat cell index, weight ``dt`` in metres), each (E,).
    """
    centre_m, direction = pixel_rays(calibration, pixels_px)
    position_m, weight_m = person_locus(
        sampling.model, centre_m, direction, sampling.heights_m, sampling.samples_per_height
    )
    cell, inside = grid.cell_of(position_m)
    keep = inside & (weight_m > 0)
    pixel = np.broadcast_to(np.arange(len(direction))[:, None], keep.shape)
    return pixel[keep], cell[keep], weight_m[keep]


@dataclass(frozen=True)
class LocusTable:
    """The loci of one fixed camera's pixels, precomputed per block of pixels.

    block_px : the blocks' side; blocks_shape : (block rows, block columns);
    matrix : (blocks, cells) float32 CSR, the summed locus weight ``dt`` (over the sampled heights)
    of each block's centre ray in each cell.
    """

    block_px: int
    blocks_shape: tuple[int, int]
    matrix: sparse.csr_matrix

    @property
    def megabytes(self) -> float:
        return (self.matrix.data.nbytes + self.matrix.indices.nbytes + self.matrix.indptr.nbytes) / 1e6


def locus_table(
    calibration: PinholeCalibration, image_size_px, grid: GroundGrid, sampling: LocusSampling, block_px: int
) -> LocusTable:
    """:class:`LocusTable` of a camera with an image of ``image_size_px`` (width, height)."""
    width_px, height_px = image_size_px
    blocks_shape = (height_px // block_px, width_px // block_px)
    rows, columns = np.meshgrid(np.arange(blocks_shape[0]), np.arange(blocks_shape[1]), indexing="ij")
    centres_px = np.stack([columns.ravel(), rows.ravel()], axis=-1) * block_px + block_px / 2
    parts = []
    for start in range(0, len(centres_px), RAYS_PER_CHUNK):
        chunk = centres_px[start : start + RAYS_PER_CHUNK]
        pixel, cell, weight = locus_entries(calibration, chunk, grid, sampling)
        parts.append(
            sparse.csr_matrix(
                (weight.astype(np.float32), (pixel, cell)), shape=(len(chunk), grid.cells), dtype=np.float32
            )
        )
    return LocusTable(block_px, blocks_shape, sparse.vstack(parts, format="csr"))


def block_counts(mask, block_px: int) -> np.ndarray:
    """Motion pixels per block: (block rows, block columns) float32 from a (height, width) mask."""
    rows, columns = mask.shape[0] // block_px, mask.shape[1] // block_px
    cropped = np.asarray(mask[: rows * block_px, : columns * block_px], dtype=np.float32)
    return cropped.reshape(rows, block_px, columns, block_px).sum(axis=(1, 3))


def table_map(table: LocusTable, mask) -> np.ndarray:
    """The summed loci (cells,) of a view's motion pixels ``mask`` (height, width) bool."""
    counts = block_counts(mask, table.block_px).ravel()
    active = np.flatnonzero(counts)
    return np.asarray(table.matrix[active].T @ counts[active], dtype=float).ravel()


def points_map(
    calibration: PinholeCalibration, pixels_px, grid: GroundGrid, sampling: LocusSampling, weights=None
) -> np.ndarray:
    """The summed loci (cells,) of the rays through ``pixels_px`` (N, 2), each weighted by ``weights`` (N,)."""
    pixels_px = np.asarray(pixels_px, dtype=float).reshape(-1, 2)
    if len(pixels_px) == 0:
        return np.zeros(grid.cells)
    pixel, cell, weight = locus_entries(calibration, pixels_px, grid, sampling)
    scale = np.ones(len(pixels_px)) if weights is None else np.asarray(weights, dtype=float)
    return np.bincount(cell, weights=weight * scale[pixel], minlength=grid.cells)


def occupancy_map(view_maps, view_weights, grid: GroundGrid, kernel_sigma_m: float) -> np.ndarray:
    """The probabilistic occupancy map (rows, columns): equations 8-9 and Algorithm 1's normalisation.

    view_maps : per view, its summed loci (cells,); view_weights : (views,). Each view's loci are
    scaled to total ``weight_c`` (a view without loci adds nothing), all weights normalised to
    sum to 1, and the grid smoothed by a Gaussian kernel of ``kernel_sigma_m``. The map sums to 1
    over the grid (less what the kernel carries past its edges), or is 0 without any locus.
    """
    total = np.zeros(grid.cells)
    for loci, weight in zip(view_maps, view_weights, strict=True):
        mass = loci.sum()
        if mass > 0:
            total += weight * loci / mass
    if total.sum() > 0:
        total /= total.sum()
    sigma = kernel_sigma_m / grid.cell_m
    return ndimage.gaussian_filter(
        total.reshape(grid.shape), sigma, mode="constant", radius=kernel_reach(kernel_sigma_m, grid.cell_m)
    )


def kernel_reach(kernel_sigma_m: float, cell_m: float) -> int:
    """The cells on each side of the centre that the map's Gaussian kernel weighs: SciPy's default
    cut at 4 sigma (``gaussian_filter``'s ``truncate``)."""
    sigma = kernel_sigma_m / cell_m
    return int(4.0 * sigma + 0.5)


@dataclass(frozen=True)
class Modes:
    """Local maxima of an occupancy map: candidate people on the ground.

    position_m : (K, 2) the map's mean around each maximum; covariance_m2 : (K, 2, 2) its spread there;
    strength : (K,) the map's value at the maximum divided by the map's largest value (in (0, 1]),
    strongest first; views : (K,) how many views see each mode's cell, where the detector says (POM), or None;
    variant : (K,) the index of the detector's setting each mode came from, where several settings' modes are
    pooled (:class:`ptztrack.occupancy.evaluation.PooledDetectors`; strongest first within each), or None.
    """

    position_m: np.ndarray
    covariance_m2: np.ndarray
    strength: np.ndarray
    views: np.ndarray | None = None
    variant: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.strength)

    def select(self, keep) -> "Modes":
        views = None if self.views is None else self.views[keep]
        variant = None if self.variant is None else self.variant[keep]
        return Modes(self.position_m[keep], self.covariance_m2[keep], self.strength[keep], views, variant)

    @staticmethod
    def empty() -> "Modes":
        return Modes(np.zeros((0, 2)), np.zeros((0, 2, 2)), np.zeros(0))


def map_modes(pom, grid: GroundGrid, separation_m: float, window_m: float, min_strength: float) -> Modes:
    """The modes of ``pom`` (rows, columns) at least ``min_strength`` times its largest value.

    A mode is a cell that holds the largest value within ``separation_m`` of it (two people stand
    no closer). Its position and covariance are the mean and
    covariance of the map over the disc of radius ``window_m`` around it (sub-cell position; the
    covariance is the measurement noise the tracker gets), with at least a cell's uniform variance.
    """
    peak = pom.max(initial=0.0)
    if peak <= 0:
        return Modes.empty()
    neighbourhood = _disc(separation_m, grid.cell_m)
    largest = ndimage.maximum_filter(pom, footprint=neighbourhood, mode="constant")
    rows, columns = np.nonzero((pom == largest) & (pom >= min_strength * peak))
    strongest_first = np.argsort(-pom[rows, columns], kind="stable")
    rows, columns = rows[strongest_first], columns[strongest_first]
    d_row, d_column = np.nonzero(_disc(window_m, grid.cell_m))
    d_row, d_column = d_row - d_row.max() // 2, d_column - d_column.max() // 2
    window_rows, window_columns = rows[:, None] + d_row, columns[:, None] + d_column
    on_grid = (
        (window_rows >= 0) & (window_rows < pom.shape[0]) & (window_columns >= 0) & (window_columns < pom.shape[1])
    )
    mass = np.where(
        on_grid, pom[np.clip(window_rows, 0, pom.shape[0] - 1), np.clip(window_columns, 0, pom.shape[1] - 1)], 0
    )
    mass = mass / mass.sum(axis=1, keepdims=True)
    points_m = grid.centre_of(window_rows, window_columns)
    mean_m = np.einsum("kw,kwd->kd", mass, points_m)
    offset_m = points_m - mean_m[:, None, :]
    covariance_m2 = np.einsum("kw,kwd,kwe->kde", mass, offset_m, offset_m) + grid.cell_m**2 / 12 * np.eye(2)
    return Modes(mean_m, covariance_m2, pom[rows, columns] / peak)


def most_modes(grid: GroundGrid, separation_m: float) -> int:
    """The most modes :func:`map_modes` can find on ``grid``: a mode holds the largest value within
    ``separation_m``, so two modes that close hold the same value, which a map of sums of loci does not
    repeat; the others lie farther apart, at most one in each square of side ``separation_m / sqrt(2)``
    (whose diagonal is ``separation_m``)."""
    side_m = separation_m / np.sqrt(2)
    rows, columns = (int(np.ceil(cells * grid.cell_m / side_m)) for cells in grid.shape)
    return min(grid.cells, rows * columns)


def disc_reach(radius_m: float, cell_m: float) -> int:
    """r: the disc of ``radius_m`` on cells of ``cell_m`` spans (2r + 1, 2r + 1) cells (:func:`_disc`)."""
    return int(np.floor(radius_m / cell_m))


def _disc(radius_m: float, cell_m: float) -> np.ndarray:
    """(2r + 1, 2r + 1) bool: the cells whose centres lie within ``radius_m`` of the middle one."""
    reach = disc_reach(radius_m, cell_m)
    d_row, d_column = np.mgrid[-reach : reach + 1, -reach : reach + 1]
    return np.hypot(d_row, d_column) * cell_m <= radius_m
