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


@dataclass(frozen=True)
class ForegroundParameters:
    """A fixed view's background model and the clean-up of its foreground (:mod:`ptztrack.occupancy.foreground`).

    The model is OpenCV's MOG2 (Zivkovic, "Improved adaptive Gaussian mixture model for background
    subtraction", ICPR 2004); its defaults are OpenCV's (``cv2.createBackgroundSubtractorMOG2``).

    history : frames; the learning rate is ``1 / min(2 n, history)`` at the model's n-th frame
        (OpenCV's schedule), so ``1 / history`` once warmed up. OpenCV's default, 500.
    var_threshold : squared Mahalanobis distance (sigmas squared) within which a pixel is explained
        by a background component. OpenCV's default, 16 (4 sigmas).
    detect_shadows : whether MOG2 marks shadows (then dropped from the silhouettes) rather than
        counting them as foreground. OpenCV's default, True.
    shadow_threshold : the least brightness ratio to its background component (``tau`` of Prati et al.,
        PAMI 2003, whom OpenCV follows) of a pixel that can be a shadow. OpenCV's default, 0.5.
    opening_px, closing_px : sides of the square structuring elements of the morphological opening
        (drops specks of sensor noise) and the closing (joins a body's parts) that follow; the clustering
        baseline's blob boxes use the same (:mod:`ptztrack.occupancy.clustering`), 3 and 9 pixels.
    """

    history: int = 500
    var_threshold: float = 16.0
    detect_shadows: bool = True
    shadow_threshold: float = 0.5
    opening_px: int = 3
    closing_px: int = 9
