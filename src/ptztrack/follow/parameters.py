"""The follow camera's parameters and their defaults, plain data that the configuration maps onto
(:mod:`ptztrack.config` takes its defaults from here); rates are per second, and
:func:`ptztrack.follow.particle_filter.particle_filter_parameters` turns the filter's into per-step
values at a frame rate."""

from dataclasses import dataclass
from typing import Literal


@dataclass(frozen=True)
class FollowParameters:
    """The follow camera (the robot-cameraman paper, Nair et al. 2008): one person kept at an image point
    and size. Each default's source is in the docs (the follow camera's parameters); none was tuned on PETS.

    target_id : the annotated person followed; the tracker starts from their first annotated box.
    target_point_px : (x*, y*) where the middle of the person should be; None: the image centre.
    target_height_px : the person's height wanted in the image.
    max_speed_deg_s, max_acceleration_deg_s2 : the camera's largest speed and acceleration of pan and of
    tilt; max_zoom_speed, max_zoom_acceleration : its largest speed (per second) and acceleration (per
    second squared) of the natural logarithm of the zoom; zoom_range : [lowest, highest].
    smoothing_cutoff_hz : the tracker's output low-pass filter.
    particles, search_particles : tracking, and searching after a loss.
    patches : [left, top, width, height] in units of the person's box (default: the head, and the torso
    and the legs each split into a left and a right half).
    histogram_bins : N of the N x N hue-saturation histograms; samples_per_patch : grid points per axis.
    achromatic_bins : N more bins by value for pixels too grey or dark to have a hue (Perez et al.);
    False: the paper's hue-saturation histograms alone.
    background_area_ratio : weigh the histograms' bins down by how common they are in the ring around
    the first box, out to a box of this many times its area (Comaniciu et al.'s background-weighted
    histogram, their 3); None: the paper's unweighted histograms.
    lambda_colour, lambda_motion : equations 3 and 4 (lambda_colour: K / 20 for K patches, Perez et al.'s
    exp(-20 D^2) on the patches' mean).
    lambda_loss : the colour likelihood's lambda in the loss test, exp(-sum_p B_p^2 / lambda_loss): the
    weights stay sharp (``lambda_colour``) while the loss test tolerates the appearance changes of a
    walking person (K / 3: 1.0 for three patches, chosen on the even-numbered PETS people).
    walk_heights_per_s : random-walk spread of the box position, box heights per second;
    scale_change_per_s : relative random-walk spread of its height per second.
    prediction : 'particle_velocity' (every particle carries its own image velocity, changed each step
    by a white acceleration: the nearly-constant-velocity model), 'constant_velocity' (the random walk
    about the estimate's image velocity, averaged with the output filter's cut-off
    ``smoothing_cutoff_hz``) or 'random_walk' (the paper's, no drift).
    acceleration_heights_per_s2 : the particles' white acceleration (with 'particle_velocity'), box
    heights per second squared; initial_speed_heights_per_s : the spread of their velocities per axis
    when the person's velocity is not known (the first step, the diffuse prior after a loss).
    loss_fraction, adapt_fraction : the loss test (P < loss_fraction P_ref) and when P_ref adapts.
    reference_time_constant_s : how slowly P_ref adapts.
    height_log_sigma : the spread of the height prior where the view is calibrated: a box h px tall weighs
    ``exp(-z^2 / 2)``, ``z = ln(h / h_standing) / height_log_sigma``, h_standing the height in pixels of a
    person standing on its bottom centre; None: no prior, the paper's.
    search_heights : spread of the diffuse prior after a loss, in box heights; search_scale : of its height.
    motion_threshold : grey levels; motion_memory_s : how long the motion history lasts;
    motion_scale : the motion image's resolution relative to the view's.
    """

    target_id: int | None = None
    target_point_px: tuple[float, float] | None = None
    target_height_px: float = 160.0
    max_speed_deg_s: float = 30.0
    max_acceleration_deg_s2: float = 30.0
    max_zoom_speed: float = 0.7
    max_zoom_acceleration: float = 0.7
    zoom_range: tuple[float, float] = (1.0, 4.0)
    smoothing_cutoff_hz: float = 1.0
    particles: int = 100
    search_particles: int = 400
    patches: tuple[tuple[float, float, float, float], ...] = (
        (0.3, 0.0, 0.4, 0.15),
        (0.15, 0.15, 0.35, 0.35),
        (0.5, 0.15, 0.35, 0.35),
        (0.2, 0.5, 0.3, 0.5),
        (0.5, 0.5, 0.3, 0.5),
    )
    histogram_bins: int = 10
    achromatic_bins: bool = False
    background_area_ratio: float | None = 3.0
    height_log_sigma: float | None = 0.1
    samples_per_patch: int = 20
    lambda_colour: float = 5 / 20
    lambda_loss: float = 5 / 3
    lambda_motion: float = 0.434
    walk_heights_per_s: float = 1.0
    scale_change_per_s: float = 0.2
    prediction: Literal["constant_velocity", "particle_velocity", "random_walk"] = "particle_velocity"
    acceleration_heights_per_s2: float = 1.0
    initial_speed_heights_per_s: float = 0.75
    loss_fraction: float = 0.1
    adapt_fraction: float = 0.6
    reference_time_constant_s: float = 2.0
    search_heights: float = 1.0
    search_scale: float = 0.2
    motion_threshold: float = 15.0
    motion_memory_s: float = 0.3
    motion_scale: float = 0.5
