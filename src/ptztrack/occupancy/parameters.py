"""The occupancy map's and its baseline's parameters and their defaults, plain data that the
configuration maps onto (:mod:`ptztrack.config` takes its defaults from here)."""

from dataclasses import dataclass

from ptztrack.scene.parameters import PersonParameters


@dataclass(frozen=True)
class MotionEdgeParameters:
    """A view's motion edges (:mod:`ptztrack.occupancy.motion_edges`), with
    :class:`OccupancyParameters`' values (its defaults are theirs).

    canny_low, canny_high : Canny's hysteresis thresholds (grey levels of the gradient);
    difference_threshold : grey levels of change that count as motion; dilation_px : how far
    (square neighbourhood of this half-size) from a changed pixel an edge still counts.
    """

    canny_low: float
    canny_high: float
    difference_threshold: float
    dilation_px: int


@dataclass(frozen=True)
class ConeShapeParameters:
    """The default person of the locus model (:class:`ptztrack.occupancy.locus.ConeModel`, equation 4):
    legs together as one cone from the feet (0.10 m radius at 0.5 m width) to the hips at half the
    height, the torso widening to the shoulders (0.25 m radius, so the model is 0.5 m wide, the
    synthetic scene's person width), then narrowing through the neck to the top of the head. Knot
    heights follow the usual proportions of an adult body (hips at about 0.5 of the height, shoulders
    at 0.8, chin at 0.87).

    height_fraction : the knots' heights as fractions of the person's height; radius_fraction : the
    radius at each knot as a fraction of the width.
    """

    height_fraction: tuple[float, ...] = (0.0, 0.5, 0.8, 0.87, 0.93, 1.0)
    radius_fraction: tuple[float, ...] = (0.2, 0.34, 0.5, 0.2, 0.2, 0.08)


@dataclass(frozen=True)
class OccupancyParameters:
    """The occupancy-map detector (LPOM) and the clustering baseline (:mod:`ptztrack.occupancy.detectors`).

    The person model (equation 4, Algorithm 1). min_height_m, max_height_m, height_step_m : the heights of
    the people the loci are drawn for, metres: from min_height_m up to max_height_m in steps of
    height_step_m, each taken at its step's midpoint. width_m : the person model's widest diameter,
    metres. samples_per_height : how many heights of the tangent point (where a ray touches the model)
    are sampled per person height h: the midpoints of that many equal slices of [0, h].

    The map. cell_m : the side of the ground grid's square cells, metres. kernel_sigma_m : the standard
    deviation of the Gaussian kernel the map is smoothed by, metres. block_px : the side in pixels of the
    square blocks of a view the locus tables are kept for (one table per block, not per pixel).

    Its modes (the people found). separation_m : the closest two people stand, metres: a mode is the
    largest cell within this distance. window_m : the radius in metres of the disc a mode's position
    and covariance are the map's mean and covariance over. candidate_strength : modes weaker than this
    fraction of the frame's strongest are not even candidates, well below any strength the fit may ask
    for (the strength a mode needs, a fraction of the frame's strongest, is fitted on the other half of
    the frames).

    The motion edges (:class:`MotionEdgeParameters`). canny_low, canny_high : Canny's hysteresis
    thresholds on the gradient's magnitude (an edge starts above canny_high and goes on above canny_low).
    difference_threshold : the grey levels a pixel must change by between frames to count as motion.
    dilation_px : the half-size in pixels of the square neighbourhood of a changed pixel within which an
    edge still counts as moving.

    The boxes of a view's detector. outline_points_per_box : in a view without frames, the points evenly
    spaced along each box's outline whose loci stand in for the motion edges (the same number for every
    box, so that a near person's large box weighs no more than a far one's small box). min_box_score :
    boxes scored lower are ignored (by the baseline too).

    The clustering baseline (the views a cluster needs are fitted like the modes' strength). linkage_m :
    the complete-linkage clustering's cut, metres: the farthest apart two views' feet of one person may
    lie. blob_min_area_px : the smallest moving region in pixels that makes a blob box, in views without
    a detector's boxes.
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
    candidate_strength: float = 0.02


@dataclass(frozen=True)
class PomParameters:
    """The probabilistic occupancy map (POM) of Fleuret, Berclaz, Lengagne and Fua (TPAMI 2008),
    :mod:`ptztrack.occupancy.pom`.

    Model: prior is each cell's prior probability of being occupied (epsilon), 0.01, the default of the authors' POM
    software (released with the paper), where nothing fits it (the occupancy experiment fits it on annotated frames:
    :func:`ptztrack.occupancy.evaluation.fitted_prior`); sigma scales the pseudo-distance Psi between a foreground
    mask and a synthetic image, 0.01, that software's value too (there the spread of a Gaussian on the same
    normalised distance, here its scale as in the paper's equation). A person at a cell is a vertical cylinder
    height_m tall and width_m across, whose projection's bounding box is the cell's rectangle: 1.75 m,
    PersonParameters.height_m (the middle of OccupancyParameters' heights, 1.6-1.9 m, the synthetic room's
    people), and 0.5 m, OccupancyParameters.width_m (the cone model's widest diameter, the room's person
    width). Grid: cell_m, 0.25 m, half a person's width (the
    prior is per cell, so it goes with the cell).
    Working resolution: the masks are averaged over block_px x block_px pixel blocks and the rectangles
    snapped to the blocks; 4 makes the room's 1024 x 768 views 256 x 192, near the 360 x 288 video of
    the paper's sequences.
    Iterations: all cells are updated together from the same average synthetic images, each new value
    mixed with the old as ``q <- damping q + (1 - damping) q_new``; damping 0.8, max_iterations 100 and
    tolerance 1e-4 (the largest change of a q that counts as converged) are the authors' software's
    defaults (the paper gives the fixed point, not the iteration).
    Boxes: a detector's boxes with a score of at least min_box_score make a view's mask
    (OccupancyParameters.min_box_score). Candidates: a cell is a candidate when its q is the largest
    within separation_m and at least candidate_probability; its position is the q-weighted mean over
    window_m. The paper reads people off the cells' q themselves: the posterior's explaining away
    already keeps one person from lighting two cells, so separation_m only merges the cells around
    one, its 8 neighbours, 0.375 m (1.5 cells); LPOM's 0.5 m would take the second of two people
    0.6 m apart, whose cells' centres can be 0.5 m apart, for the first's. window_m as
    OccupancyParameters'; candidate_probability 0.02, below the smallest threshold the experiment's
    fit tries, 0.05, as LPOM's candidates. min_probability: the detections' q, 0.5 (more likely there
    than not), where no threshold is fitted.
    Feet: a candidate localized by the views' box feet (:mod:`ptztrack.occupancy.feet`) takes each
    view's feet nearest to it within feet_gate_m, 1.0 m, OccupancyParameters.linkage_m (the farthest
    apart the baseline lets one person's feet lie in two views).
    """

    prior: float = 0.01
    sigma: float = 0.01
    height_m: float = PersonParameters.height_m
    width_m: float = OccupancyParameters.width_m
    cell_m: float = 0.25
    block_px: int = 4
    damping: float = 0.8
    max_iterations: int = 100
    tolerance: float = 1e-4
    min_box_score: float = 0.5
    separation_m: float = 0.375
    window_m: float = 0.25
    candidate_probability: float = 0.02
    min_probability: float = 0.5
    feet_gate_m: float = 1.0


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
