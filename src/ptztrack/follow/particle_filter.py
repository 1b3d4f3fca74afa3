"""The robot-cameraman paper's particle filter (Nair et al., IROS 2008, section III-C): one person in the image.

State: ``(x, y, h)`` in the image, the centre of the person's box and its
height in pixels, as in the paper. We keep the image state rather than a
ground position with a height because the measurements (colour and motion)
live in the image, because it needs no calibration to track (the ground
plane only comes in to report a track and to set the zoom), and because the
same filter then runs on a still camera's video (the OTB benchmark). The
camera's own motion is taken out before each step: every particle's box is
carried from the previous view into the current one by the homography of
the two poses.

Each step (:func:`step_filter`):

1. resample the particles by their previous weights, deterministically
   (systematic resampling: one uniform draw, then evenly spaced);
2. predict: every particle moves by its own image velocity, which a white
   acceleration changes, and h by a relative ``scale_sigma`` (see below;
   or the paper's random walk, equation 1: Gaussian steps of ``walk_sigma``
   box heights in x and y);
3. weigh by the product of the colour and motion likelihoods (equations 3-5;
   :mod:`ptztrack.follow.colour_model`, :mod:`ptztrack.follow.motion_image`),
   computed in logarithms so that no weight underflows;
4. output the weighted mean (equation 6), whose colour likelihood
   ``P(z_col | s_t)`` decides on a loss.

Loss and re-initialisation (section III-C7). The reference ``P_ref`` is
"initially set to the maximum likelihood value": the colour likelihood of
the best particle at the first step after the start. (Not the likelihood's
upper bound, 1: a patch's histogram is never the same from one frame to the
next, and from 1 the reference would never come within the 60 % that lets
it adapt.) A loss
is declared when ``P(z_col | s_t) < loss_fraction * P_ref`` (10 %);
``P_ref`` moves towards the last likelihood by ``reference_rate`` per step
whenever that is at least ``adapt_fraction * P_ref`` (60 %). While lost, the
estimate stays where it was last (a controller holds the camera there) and
the filter searches with ``search_particles``, more than when tracking: the
paper's diffuse prior "that also acts as a target detector" and "converges
to the target". Half of them are drawn anew from the diffuse prior at every
step, the other half continue the filter (resampled and walked), so that
particles that land near the person climb onto it while the fresh ones keep
searching. The track is back when the estimate's likelihood passes the loss
threshold again; the particles are then resampled down to ``particles``.
The diffuse prior is Gaussian in x and y around the last estimate,
``search_sigma`` box heights across plus ``walk_sigma`` for every step lost
(the person walks on) up to the image's size, and log-normal in h with
``search_scale_sigma``.

Velocity. The paper's walk has no drift: a person who walks past another of
similar colours leaves the particles to whichever of the two the random
walk favours. With ``acceleration_sigma`` every particle carries its own
image velocity (``particle_velocities_px``), the nearly-constant-velocity
model: each step a white acceleration, drawn per particle, changes its
velocity and moves it by half as much more than its velocity
(:func:`predict_states`). One velocity shared by all particles, the
estimate's, would turn with the boxes a passer-by shares with the person
and carry every particle his way; a particle's own velocity goes on with
whichever of the two it followed, so the posterior splits and the
person's particles stay. The velocities are spread over a walking speed
(``initial_speed_sigma``) at the first step and for the diffuse prior's
particles. Without ``acceleration_sigma`` the particles move by the
estimate's velocity, an exponential average, with weight
``velocity_gain``, of the estimate's steps (0 while lost and after a
recovery), plus the random walk; ``velocity_gain`` 0 is the paper's walk.

Height prior (not in the paper). Where the view is calibrated, a box's height is weighed against
the height of a person standing on its bottom centre: a log-normal prior, ``ln(h / h_standing)``
with spread ``height_log_sigma``. Background-weighted histograms do not count the background a
box takes in, so without it nothing stops a box from growing; the paper's prior on h is none.

Likelihoods: colour from the patches' hue-saturation histograms, motion
``exp(-E^2 / lambda_mot)`` with E the fraction of non-moving pixels under the
patches (the paper's count of non-motion pixels, divided by the pixels there
so that smaller boxes are not favoured).
"""

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from ptztrack.follow import colour_model
from ptztrack.follow.motion_image import MotionImage, first_motion_image, next_motion_image, non_motion_fraction
from ptztrack.follow.parameters import FollowParameters
from ptztrack.geometry.ptz import apply_homography

# A box is never smaller than this many pixels high: the random walk would otherwise shrink one
# that lost its person to nothing.
MIN_HEIGHT_PX = 8.0
# The reference histograms are sampled this much more densely per axis than the particles' ones.
REFERENCE_OVERSAMPLING = 4
# The height prior treats a box no one could stand in as this many spreads off, not as impossible: were
# every particle so, their weights would otherwise all vanish.
MAX_HEIGHT_Z = 10.0

# The height (n,) px of a person standing on feet pixels (n, 2) of a view, NaN where no one can stand.
StandingHeight = Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class ParticleFilterParameters:
    """The filter's parameters, per step (the builder converts rates at the frame rate; the scenario's
    ``follow`` section gives them and their sources).

    particles, search_particles : while tracking, and while lost.
    patches : (K, 4) (left, top, width, height) in box units (:mod:`ptztrack.follow.colour_model`).
    histogram_bins : N of the N x N hue-saturation histograms; achromatic_bins : N more bins by value for
    greys (:func:`ptztrack.follow.colour_model.colour_bins`); samples_per_patch : grid points per patch axis.
    background_ring_scale : the background-weighted histograms' ring, the box scaled by this much
    (:func:`ptztrack.follow.colour_model.background_weights`); None: unweighted, the paper's.
    lambda_colour, lambda_motion : equations 3 and 4.
    lambda_loss : the colour likelihood's lambda in the loss test (``likelihood``, ``P_ref``).
    height_log_sigma : the spread of ``ln(h / h_standing)``, h_standing the calibrated height of a
    person standing on the box's feet (the height prior, see the module); None: no prior, the paper's.
    walk_sigma : random-walk step of x and y in box heights; scale_sigma : relative step of h.
    velocity_gain : the weight of the last step in the velocity's exponential average; 0: no velocity.
    acceleration_sigma : box heights per step^2: every particle carries its own velocity, changed each
    step by this white acceleration (the nearly-constant-velocity model); None: the particles share the
    estimate's velocity (``velocity_gain``). initial_speed_sigma : box heights per step, the spread of
    the particles' velocities at the first step and of the diffuse prior's.
    loss_fraction, adapt_fraction, reference_rate : the loss test and the adaptation of ``P_ref``.
    search_sigma, search_scale_sigma : the diffuse prior after a loss (see the module).
    motion_threshold : grey levels; motion_decay : per step; motion_scale : resolution of the motion image.
    """

    particles: int
    search_particles: int
    patches: np.ndarray
    histogram_bins: int
    achromatic_bins: bool
    samples_per_patch: int
    background_ring_scale: float | None
    lambda_colour: float
    lambda_motion: float
    lambda_loss: float
    height_log_sigma: float | None
    walk_sigma: float
    scale_sigma: float
    velocity_gain: float
    acceleration_sigma: float | None
    initial_speed_sigma: float
    loss_fraction: float
    adapt_fraction: float
    reference_rate: float
    search_sigma: float
    search_scale_sigma: float
    motion_threshold: float
    motion_decay: float
    motion_scale: float


def smoothing_pole(cutoff_hz: float, frame_rate_hz: float) -> float:
    """The output filter's pole ``exp(-2 pi f_c / frame_rate)`` for the cut-off ``f_c`` (Hz)."""
    return float(np.exp(-2 * np.pi * cutoff_hz / frame_rate_hz))


def particle_filter_parameters(settings: FollowParameters, frame_rate_hz: float) -> ParticleFilterParameters:
    """The filter's per-step parameters from the follow camera's (rates per second) at ``frame_rate_hz``."""
    step_s = 1.0 / frame_rate_hz
    return ParticleFilterParameters(
        particles=settings.particles,
        search_particles=settings.search_particles,
        patches=np.asarray(settings.patches, dtype=float),
        histogram_bins=settings.histogram_bins,
        achromatic_bins=settings.achromatic_bins,
        samples_per_patch=settings.samples_per_patch,
        background_ring_scale=None if settings.background_area_ratio is None else settings.background_area_ratio**0.5,
        lambda_colour=settings.lambda_colour,
        lambda_loss=settings.lambda_loss,
        lambda_motion=settings.lambda_motion,
        height_log_sigma=settings.height_log_sigma,
        walk_sigma=settings.walk_heights_per_s * step_s,
        scale_sigma=settings.scale_change_per_s * step_s,
        velocity_gain=(
            1.0 - smoothing_pole(settings.smoothing_cutoff_hz, frame_rate_hz)
            if settings.prediction == "constant_velocity"
            else 0.0
        ),
        acceleration_sigma=(
            settings.acceleration_heights_per_s2 * step_s**2 if settings.prediction == "particle_velocity" else None
        ),
        initial_speed_sigma=settings.initial_speed_heights_per_s * step_s,
        loss_fraction=settings.loss_fraction,
        adapt_fraction=settings.adapt_fraction,
        reference_rate=min(1.0, step_s / settings.reference_time_constant_s),
        search_sigma=settings.search_heights,
        search_scale_sigma=settings.search_scale,
        motion_threshold=settings.motion_threshold,
        motion_decay=min(1.0, step_s / settings.motion_memory_s),
        motion_scale=settings.motion_scale,
    )


@dataclass(frozen=True)
class ParticleFilter:
    """The filter after a step.

    particles : (P, 3) states (x_px, y_px, h_px) in the current view; weights : (P,), summing to 1.
    estimate : (3,) the weighted mean (equation 6); likelihood : its colour likelihood P(z_col | s_t).
    reference : (K, B) the patches' reference histograms (B bins), weighted by ``bin_weights`` (B,)
    as every candidate's are; aspect : box width / height.
    reference_likelihood : P_ref (None before the first step); lost_steps : steps lost (0 while tracking).
    motion : the motion history image; velocity_px : (2,) the estimate's velocity, px per step;
    particle_velocities_px : (P, 2) each particle's velocity, px per step (with ``acceleration_sigma``).
    """

    particles: np.ndarray
    weights: np.ndarray
    estimate: np.ndarray
    likelihood: float
    reference: np.ndarray
    bin_weights: np.ndarray
    aspect: float
    reference_likelihood: float | None
    lost_steps: int
    motion: MotionImage
    velocity_px: np.ndarray
    particle_velocities_px: np.ndarray

    @property
    def lost(self) -> bool:
        return self.lost_steps > 0

    def box_px(self) -> np.ndarray:
        """(4,) (left, top, width, height) of the estimate."""
        return colour_model.box_of_states(self.estimate, self.aspect)

    def centre_covariance_px2(self) -> np.ndarray:
        """(2, 2) px^2: the weighted covariance of the particles' box centres."""
        offset = self.particles[:, :2] - self.weights @ self.particles[:, :2]
        return (self.weights[:, None] * offset).T @ offset


def systematic_resample(weights, count: int, rng: np.random.Generator) -> np.ndarray:
    """Indices (count,) drawn by systematic resampling: points ``(u + i) / count`` on the cumulative weights."""
    cumulative = np.cumsum(weights)
    points = (rng.random() + np.arange(count)) / count * cumulative[-1]
    return np.minimum(np.searchsorted(cumulative, points, side="right"), len(cumulative) - 1)


def carry_states(states, homography) -> np.ndarray:
    """States (..., 3) of one view in another: the box's top and bottom centres through ``homography`` (3, 3)."""
    states = np.asarray(states, dtype=float)
    x, y, h = states[..., 0], states[..., 1], states[..., 2]
    ends = np.stack([np.stack([x, y - h / 2], -1), np.stack([x, y + h / 2], -1)], axis=-2)
    top, bottom = np.moveaxis(apply_homography(homography, ends.reshape(-1, 2)).reshape(ends.shape), -2, 0)
    return np.concatenate([(top + bottom) / 2, np.linalg.norm(bottom - top, axis=-1, keepdims=True)], axis=-1)


def carry_velocities(states, velocities_px, homography, carried_states) -> np.ndarray:
    """Velocities (..., 2) px per step of states (..., 3) in the view that ``homography`` (3, 3) maps
    them into, where they are ``carried_states`` (:func:`carry_states`): where the next position
    maps, less where the position maps."""
    states = np.asarray(states, dtype=float)
    moved = np.concatenate([states[..., :2] + velocities_px, states[..., 2:]], axis=-1)
    return carry_states(moved, homography)[..., :2] - carried_states[..., :2]


def start_filter(image_bgr, box_px, parameters: ParticleFilterParameters) -> ParticleFilter:
    """A filter on the person in ``box_px`` (left, top, width, height) of the view (h, w, 3) uint8 BGR.

    The reference histograms are the box's patches; every particle starts on the box.
    """
    left, top, width, height = (float(value) for value in box_px)
    state = np.array([left + width / 2, top + height / 2, height])
    bins = colour_model.colour_bins(image_bgr, parameters.histogram_bins, parameters.achromatic_bins)
    patches = colour_model.patch_boxes(np.asarray(box_px, dtype=float), parameters.patches)
    total_bins = colour_model.bin_count(parameters.histogram_bins, parameters.achromatic_bins)
    reference = colour_model.patch_histograms(
        bins, patches, total_bins, REFERENCE_OVERSAMPLING * parameters.samples_per_patch
    )
    bin_weights = (
        np.ones(total_bins)
        if parameters.background_ring_scale is None
        else colour_model.background_weights(bins, box_px, total_bins, parameters.background_ring_scale)
    )
    return ParticleFilter(
        particles=np.tile(state, (parameters.particles, 1)),
        weights=np.full(parameters.particles, 1.0 / parameters.particles),
        estimate=state,
        likelihood=1.0,
        reference=colour_model.weigh_histograms(reference, bin_weights),
        bin_weights=bin_weights,
        aspect=width / height,
        reference_likelihood=None,
        lost_steps=0,
        motion=first_motion_image(image_bgr, parameters.motion_scale),
        velocity_px=np.zeros(2),
        particle_velocities_px=np.zeros((parameters.particles, 2)),
    )


def step_filter(
    state: ParticleFilter,
    image_bgr,
    homography,
    parameters: ParticleFilterParameters,
    rng: np.random.Generator,
    standing_height_px: StandingHeight | None = None,
) -> ParticleFilter:
    """One step on the next view (h, w, 3) uint8 BGR, into which the previous view maps by ``homography``.

    standing_height_px : the view's calibration, for the height prior (with ``height_log_sigma``).
    """
    motion = next_motion_image(
        state.motion, image_bgr, homography, parameters.motion_threshold, parameters.motion_decay
    )
    last = carry_states(state.estimate, homography)
    carried = carry_states(state.particles, homography)
    velocity_px = carry_velocities(state.estimate, state.velocity_px, homography, last)
    velocities = carry_velocities(state.particles, state.particle_velocities_px, homography, carried)
    if state.reference_likelihood is None:  # the first step: the person's velocity is not known yet
        velocities = _initial_velocities(carried, parameters, rng)
    if state.lost:
        kept = systematic_resample(state.weights, parameters.search_particles // 2, rng)
        image_size_px = image_bgr.shape[1::-1]
        fresh = _diffuse_prior(
            last, state.lost_steps, parameters.search_particles - len(kept), image_size_px, parameters, rng
        )
        particles, velocities = predict_states(carried[kept], velocities[kept], np.zeros(2), parameters, rng)
        particles = np.vstack([particles, fresh])
        velocities = np.vstack([velocities, _initial_velocities(fresh, parameters, rng)])
    else:
        chosen = systematic_resample(state.weights, parameters.particles, rng)
        particles, velocities = predict_states(carried[chosen], velocities[chosen], velocity_px, parameters, rng)
    # The weighted mean's box lies within the particles' boxes' extent: one region of bins serves both.
    region = _ColourRegion.of(image_bgr, particles, state.aspect, parameters)
    colour = region.log_likelihood(particles, state, parameters)
    log_weights = colour + _motion_log_likelihood(motion, particles, state.aspect, parameters)
    if standing_height_px is not None and parameters.height_log_sigma is not None:
        log_weights += height_log_prior(particles, standing_height_px, parameters.height_log_sigma)
    weights = np.exp(log_weights - log_weights.max())
    weights /= weights.sum()
    estimate = weights @ particles
    # The loss test's likelihoods: the same sum of squared distances over lambda_loss.
    to_loss = parameters.lambda_colour / parameters.lambda_loss
    estimate_colour = region.log_likelihood(estimate[None], state, parameters)[0]
    likelihood = float(np.exp(to_loss * estimate_colour))
    reference = state.reference_likelihood
    if reference is None:  # the first step: P_ref is the best particle's likelihood
        reference = float(np.exp(to_loss * colour.max()))
    elif not state.lost and state.likelihood >= parameters.adapt_fraction * reference:
        reference += parameters.reference_rate * (state.likelihood - reference)
    found = likelihood >= parameters.loss_fraction * reference
    lost_steps = 0 if found else state.lost_steps + 1
    if state.lost or lost_steps:
        velocity_px = np.zeros(2)
    elif parameters.acceleration_sigma is not None:
        velocity_px = weights @ velocities
    else:
        gain = parameters.velocity_gain
        velocity_px = gain * (estimate[:2] - last[:2]) + (1 - gain) * velocity_px
    if state.lost and found:
        survivors = systematic_resample(weights, parameters.particles, rng)
        particles, velocities = particles[survivors], velocities[survivors]
        weights = np.full(parameters.particles, 1.0 / parameters.particles)
    return replace(
        state,
        particles=particles,
        weights=weights,
        estimate=estimate if lost_steps == 0 else last,
        likelihood=likelihood,
        reference_likelihood=reference,
        lost_steps=lost_steps,
        motion=motion,
        velocity_px=velocity_px,
        particle_velocities_px=velocities,
    )


def height_log_prior(states, standing_height_px: StandingHeight, log_sigma: float) -> np.ndarray:
    """Log prior (n,) of states (n, 3): ``-z^2 / 2``, ``z = ln(h / h_standing) / log_sigma``, h_standing the
    height of a person standing on the box's bottom centre; a box whose feet no one can stand on
    (beyond the horizon) counts as ``MAX_HEIGHT_Z`` spreads off."""
    feet_px = np.c_[states[:, 0], states[:, 1] + states[:, 2] / 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.log(states[:, 2] / standing_height_px(feet_px)) / log_sigma
    return -0.5 * np.minimum(np.nan_to_num(z, nan=MAX_HEIGHT_Z) ** 2, MAX_HEIGHT_Z**2)


def predict_states(states, velocities, shared_velocity_px, parameters, rng: np.random.Generator):
    """States (P, 3) and their velocities (P, 2) one step on. With ``acceleration_sigma``, each particle
    moves by its own velocity, which a white acceleration changes (the nearly-constant-velocity model);
    otherwise every particle moves by the shared velocity (2,) plus equation 1's random walk."""
    if parameters.acceleration_sigma is None:
        moved = states + np.r_[shared_velocity_px, 0.0]
        return _random_walk(moved, parameters.walk_sigma, parameters.scale_sigma, rng), np.zeros_like(velocities)
    acceleration_px = parameters.acceleration_sigma * states[:, 2:] * rng.standard_normal(velocities.shape)
    moved = np.c_[states[:, :2] + velocities + acceleration_px / 2, states[:, 2]]
    return _random_walk(moved, 0.0, parameters.scale_sigma, rng), velocities + acceleration_px


def _initial_velocities(states, parameters, rng: np.random.Generator) -> np.ndarray:
    """Velocities (n, 2) px per step for states (n, 3) whose person's velocity is not known: a walking
    speed's spread, ``initial_speed_sigma`` box heights per step per axis (zero without own velocities)."""
    if parameters.acceleration_sigma is None:
        return np.zeros((len(states), 2))
    return parameters.initial_speed_sigma * states[:, 2:] * rng.standard_normal((len(states), 2))


def _random_walk(states, walk_sigma: float, scale_sigma: float, rng: np.random.Generator) -> np.ndarray:
    """Equation 1: states (P, 3) plus Gaussian steps, ``walk_sigma`` heights in x and y, ``scale_sigma`` of h."""
    steps = rng.standard_normal(states.shape)
    h = states[:, 2:]
    moved = states + np.c_[walk_sigma * h * steps[:, :2], scale_sigma * h * steps[:, 2:]]
    moved[:, 2] = np.maximum(moved[:, 2], MIN_HEIGHT_PX)
    return moved


def _diffuse_prior(last, lost_steps: int, count: int, image_size_px, parameters, rng) -> np.ndarray:
    """``count`` states (count, 3) around the last estimate (3,), wider the longer the person is lost, but
    never wider than the image (``image_size_px`` (width, height)), beyond which a particle is wasted."""
    steps = rng.standard_normal((count, 3))
    spread_px = (parameters.search_sigma + parameters.walk_sigma * lost_steps) * last[2]
    centres = last[:2] + min(spread_px, max(image_size_px)) * steps[:, :2]
    heights = np.maximum(last[2] * np.exp(parameters.search_scale_sigma * steps[:, 2]), MIN_HEIGHT_PX)
    return np.c_[centres, heights]


class _ColourRegion(NamedTuple):
    """The colour bins (h, w) of the part of a view that some states' patches span, and its top-left
    corner (col, row) in the view; empty where they span none of it."""

    bins: np.ndarray
    origin: np.ndarray

    @classmethod
    def of(cls, image_bgr, states, aspect: float, parameters) -> "_ColourRegion":
        boxes = colour_model.patch_boxes(colour_model.box_of_states(states, aspect), parameters.patches)
        image_height, image_width = image_bgr.shape[:2]
        low = np.floor(boxes[..., :2].min(axis=(0, 1)))
        high = np.ceil((boxes[..., :2] + boxes[..., 2:]).max(axis=(0, 1)))
        (col0, row0), (col1, row1) = (np.clip(c, 0, [image_width, image_height]).astype(int) for c in (low, high))
        region = image_bgr[row0 : max(row0, row1), col0 : max(col0, col1)]
        bins = (
            colour_model.colour_bins(region, parameters.histogram_bins, parameters.achromatic_bins)
            if region.size
            else np.zeros((0, 0), int)
        )
        return cls(bins, np.array([col0, row0]))

    def log_likelihood(self, states, target: ParticleFilter, parameters) -> np.ndarray:
        """Log colour likelihoods (n,) of states (n, 3) whose patches lie within the region, against the
        target's reference histograms."""
        boxes = colour_model.box_of_states(states, target.aspect)
        boxes = colour_model.patch_boxes(boxes, parameters.patches) - [*self.origin, 0, 0]
        total_bins = colour_model.bin_count(parameters.histogram_bins, parameters.achromatic_bins)
        if self.bins.size:
            histograms = colour_model.patch_histograms(self.bins, boxes, total_bins, parameters.samples_per_patch)
        else:
            histograms = np.zeros(boxes.shape[:-1] + (total_bins,))
        histograms = colour_model.weigh_histograms(histograms, target.bin_weights)
        return colour_model.colour_log_likelihood(
            colour_model.bhattacharyya_distance(target.reference, histograms), parameters.lambda_colour
        )


def _motion_log_likelihood(motion: MotionImage, states, aspect: float, parameters) -> np.ndarray:
    """Log of equation 4, ``-E^2 / lambda_mot``, (n,) for states (n, 3)."""
    boxes = colour_model.patch_boxes(colour_model.box_of_states(states, aspect), parameters.patches)
    return -(non_motion_fraction(motion, boxes) ** 2) / parameters.lambda_motion
