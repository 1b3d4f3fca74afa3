"""The scenario's follow section: the follow camera's person, its motion limits and its particle filter."""

from typing import Annotated, Literal

from pydantic import Field, model_validator

from ptztrack.config.fields import NonNegativeFloat, PositiveFloat, _Strict, _Zoom, at_most, at_most_items

_FollowPixels = Annotated[NonNegativeFloat, at_most(8192, "pixels")]
_PARTICLE_TIME = "time: every particle is scored on every patch each step"
Fraction = Annotated[float, Field(gt=0, lt=1)]
Patch = tuple[
    Annotated[float, Field(ge=0, le=1)],
    Annotated[float, Field(ge=0, le=1)],
    Annotated[float, Field(gt=0, le=1)],
    Annotated[float, Field(gt=0, le=1)],
]


class Follow(_Strict):
    """The follow camera (the robot-cameraman paper, Nair et al. 2008): one person kept at an image point and size.

    The ``tracker.kind`` 'particle' (the paper's particle filter), 'csrt' or 'mil' (OpenCV's) follows
    the person and the policy 'follow' moves the camera. Each default's source is in the docs
    (the follow camera's parameters); none was tuned on PETS.

    target_id : the annotated person followed; the tracker starts from their first annotated box.
    target_point_px : (x*, y*) where the middle of the person should be; null: the image centre.
    target_height_px : the person's height wanted in the image.
    max_speed_deg_s, max_acceleration_deg_s2 : of pan and of tilt; max_zoom_speed (per s),
    max_zoom_acceleration (per s^2) : of the natural logarithm of the zoom; zoom_range : [lowest, highest].
    smoothing_cutoff_hz : the tracker's output low-pass filter.
    particles, search_particles : tracking, and searching after a loss.
    patches : [left, top, width, height] in units of the person's box (default: the head, and the torso
    and the legs each split into a left and a right half).
    histogram_bins : N of the N x N hue-saturation histograms; samples_per_patch : grid points per axis.
    achromatic_bins : N more bins by value for pixels too grey or dark to have a hue (Perez et al.);
    false: the paper's hue-saturation histograms alone.
    background_area_ratio : weigh the histograms' bins down by how common they are in the ring around
    the first box, out to a box of this many times its area (Comaniciu et al.'s background-weighted
    histogram, their 3); null: the paper's unweighted histograms.
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
    search_heights : spread of the diffuse prior after a loss, in box heights; search_scale : of its height.
    motion_threshold : grey levels; motion_memory_s : how long the motion history lasts;
    motion_scale : the motion image's resolution relative to the view's.
    """

    target_id: int | None = None
    target_point_px: tuple[_FollowPixels, _FollowPixels] | None = None
    target_height_px: Annotated[PositiveFloat, at_most(8192, "pixels")] = 160.0
    max_speed_deg_s: Annotated[PositiveFloat, at_most(1000, "degrees per second")] = 30.0
    max_acceleration_deg_s2: Annotated[PositiveFloat, at_most(10_000, "degrees per second squared")] = 30.0
    max_zoom_speed: Annotated[PositiveFloat, at_most(100, "per second")] = 0.7
    max_zoom_acceleration: Annotated[PositiveFloat, at_most(1000, "per second squared")] = 0.7
    zoom_range: tuple[_Zoom, _Zoom] = (1.0, 4.0)
    smoothing_cutoff_hz: Annotated[PositiveFloat, at_most(1000, "hertz")] = 1.0
    particles: Annotated[int, Field(ge=1), at_most(100_000, _PARTICLE_TIME)] = 100
    search_particles: Annotated[int, Field(ge=2), at_most(100_000, _PARTICLE_TIME)] = 400
    patches: Annotated[tuple[Patch, ...], at_most_items(100, _PARTICLE_TIME)] = (
        (0.3, 0.0, 0.4, 0.15),
        (0.15, 0.15, 0.35, 0.35),
        (0.5, 0.15, 0.35, 0.35),
        (0.2, 0.5, 0.3, 0.5),
        (0.5, 0.5, 0.3, 0.5),
    )
    histogram_bins: int = Field(10, ge=1, le=64)
    achromatic_bins: bool = False
    background_area_ratio: Annotated[float, Field(gt=1), at_most(10_000, "box areas")] | None = 3.0
    height_log_sigma: PositiveFloat | None = 0.1
    samples_per_patch: Annotated[int, Field(ge=1), at_most(1000, _PARTICLE_TIME)] = 20
    lambda_colour: Annotated[PositiveFloat, at_most(1e6, "a likelihood scale")] = 5 / 20
    lambda_loss: Annotated[PositiveFloat, at_most(1e6, "a likelihood scale")] = 5 / 3
    lambda_motion: Annotated[PositiveFloat, at_most(1e6, "a likelihood scale")] = 0.434
    walk_heights_per_s: Annotated[PositiveFloat, at_most(1000, "box heights per second")] = 1.0
    scale_change_per_s: Annotated[PositiveFloat, at_most(100, "per second")] = 0.2
    prediction: Literal["constant_velocity", "particle_velocity", "random_walk"] = "particle_velocity"
    acceleration_heights_per_s2: Annotated[PositiveFloat, at_most(1000, "box heights per second squared")] = 1.0
    initial_speed_heights_per_s: Annotated[PositiveFloat, at_most(1000, "box heights per second")] = 0.75
    loss_fraction: Fraction = 0.1
    adapt_fraction: Fraction = 0.6
    reference_time_constant_s: Annotated[PositiveFloat, at_most(86_400, "seconds")] = 2.0
    search_heights: Annotated[PositiveFloat, at_most(1000, "box heights")] = 1.0
    search_scale: Annotated[PositiveFloat, at_most(100, "a relative spread")] = 0.2
    motion_threshold: Annotated[NonNegativeFloat, at_most(255, "grey levels")] = 15.0
    motion_memory_s: Annotated[PositiveFloat, at_most(86_400, "seconds")] = 0.3
    motion_scale: Annotated[float, Field(gt=0, le=1)] = 0.5

    @model_validator(mode="after")
    def _consistent(self):
        if self.zoom_range[1] < self.zoom_range[0]:
            raise ValueError(f"zoom_range must be [lowest, highest] (got {list(self.zoom_range)})")
        if self.adapt_fraction <= self.loss_fraction:
            raise ValueError(
                f"adapt_fraction ({self.adapt_fraction}) must be above loss_fraction ({self.loss_fraction})"
            )
        if not self.patches:
            raise ValueError("patches must hold at least one [left, top, width, height]")
        for number, (left, top, width, height) in enumerate(self.patches):
            if left + width > 1 or top + height > 1:
                raise ValueError(f"patch {number} {[left, top, width, height]} reaches outside the box")
        return self
