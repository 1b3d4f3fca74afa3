"""The occupancy map's and its baseline's parameters and their defaults, plain data that the
configuration maps onto (:mod:`ptztrack.config` takes its defaults from here)."""

from dataclasses import dataclass


@dataclass(frozen=True)
class OccupancyParameters:
    """The occupancy-map detector (LPOM) and the clustering baseline (:mod:`ptztrack.occupancy.detectors`).

    Person model (equation 4, Algorithm 1): heights from min_height_m up to max_height_m in steps of
    height_step_m (at the steps' midpoints), width_m, samples_per_height tangent points per height.
    Map: cell_m, kernel_sigma_m (the Gaussian kernel), block_px (locus tables per block of pixels).
    Modes: separation_m (closest two people), window_m (their mean and covariance); the strength a
    mode needs (a fraction of the frame's strongest) is fitted on the other half of the frames.
    Motion edges: canny_low, canny_high, difference_threshold (grey levels), dilation_px.
    Boxes: outline_points_per_box, min_box_score. Baseline: linkage_m (complete-linkage cut),
    blob_min_area_px (blob boxes of views without detections); the views a cluster needs are fitted
    like the modes' strength.
    """

    min_height_m: float = 1.6
    max_height_m: float = 1.9
    height_step_m: float = 0.1
    width_m: float = 0.5
    samples_per_height: int = 32
    cell_m: float = 0.05
    kernel_sigma_m: float = 0.1
    block_px: int = 4
    separation_m: float = 0.5
    window_m: float = 0.25
    canny_low: float = 50.0
    canny_high: float = 150.0
    difference_threshold: float = 15.0
    dilation_px: int = 2
    outline_points_per_box: int = 64
    min_box_score: float = 0.5
    linkage_m: float = 1.0
    blob_min_area_px: int = 400
