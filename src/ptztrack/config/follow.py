"""The scenario's follow section: the follow camera's person, its motion limits and its particle filter."""

from typing import Annotated, Literal

from pydantic import Field, model_validator

from ptztrack.config.fields import NonNegativeFloat, PositiveFloat, _Strict, _Zoom, at_most, at_most_items
from ptztrack.follow.parameters import FollowParameters

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
    """The follow camera's section: :class:`~ptztrack.follow.parameters.FollowParameters`, whose fields
    it validates and whose defaults it takes (their meaning is given there).

    The ``tracker.kind`` 'particle' (the paper's particle filter), 'csrt' or 'mil' (OpenCV's) follows
    the person and the policy 'follow' moves the camera.
    """

    target_id: int | None = FollowParameters.target_id
    target_point_px: tuple[_FollowPixels, _FollowPixels] | None = FollowParameters.target_point_px
    target_height_px: Annotated[PositiveFloat, at_most(8192, "pixels")] = FollowParameters.target_height_px
    max_speed_deg_s: Annotated[PositiveFloat, at_most(1000, "degrees per second")] = FollowParameters.max_speed_deg_s
    max_acceleration_deg_s2: Annotated[PositiveFloat, at_most(10_000, "degrees per second squared")] = (
        FollowParameters.max_acceleration_deg_s2
    )
    max_zoom_speed: Annotated[PositiveFloat, at_most(100, "per second")] = FollowParameters.max_zoom_speed
    max_zoom_acceleration: Annotated[PositiveFloat, at_most(1000, "per second squared")] = (
        FollowParameters.max_zoom_acceleration
    )
    zoom_range: tuple[_Zoom, _Zoom] = FollowParameters.zoom_range
    smoothing_cutoff_hz: Annotated[PositiveFloat, at_most(1000, "hertz")] = FollowParameters.smoothing_cutoff_hz
    particles: Annotated[int, Field(ge=1), at_most(100_000, _PARTICLE_TIME)] = FollowParameters.particles
    search_particles: Annotated[int, Field(ge=2), at_most(100_000, _PARTICLE_TIME)] = FollowParameters.search_particles
    patches: Annotated[tuple[Patch, ...], at_most_items(100, _PARTICLE_TIME)] = FollowParameters.patches
    histogram_bins: int = Field(FollowParameters.histogram_bins, ge=1, le=64)
    achromatic_bins: bool = FollowParameters.achromatic_bins
    background_area_ratio: Annotated[float, Field(gt=1), at_most(10_000, "box areas")] | None = (
        FollowParameters.background_area_ratio
    )
    height_log_sigma: PositiveFloat | None = FollowParameters.height_log_sigma
    samples_per_patch: Annotated[int, Field(ge=1), at_most(1000, _PARTICLE_TIME)] = FollowParameters.samples_per_patch
    lambda_colour: Annotated[PositiveFloat, at_most(1e6, "a likelihood scale")] = FollowParameters.lambda_colour
    lambda_loss: Annotated[PositiveFloat, at_most(1e6, "a likelihood scale")] = FollowParameters.lambda_loss
    lambda_motion: Annotated[PositiveFloat, at_most(1e6, "a likelihood scale")] = FollowParameters.lambda_motion
    walk_heights_per_s: Annotated[PositiveFloat, at_most(1000, "box heights per second")] = (
        FollowParameters.walk_heights_per_s
    )
    scale_change_per_s: Annotated[PositiveFloat, at_most(100, "per second")] = FollowParameters.scale_change_per_s
    prediction: Literal["constant_velocity", "particle_velocity", "random_walk"] = FollowParameters.prediction
    acceleration_heights_per_s2: Annotated[PositiveFloat, at_most(1000, "box heights per second squared")] = (
        FollowParameters.acceleration_heights_per_s2
    )
    initial_speed_heights_per_s: Annotated[PositiveFloat, at_most(1000, "box heights per second")] = (
        FollowParameters.initial_speed_heights_per_s
    )
    loss_fraction: Fraction = FollowParameters.loss_fraction
    adapt_fraction: Fraction = FollowParameters.adapt_fraction
    reference_time_constant_s: Annotated[PositiveFloat, at_most(86_400, "seconds")] = (
        FollowParameters.reference_time_constant_s
    )
    search_heights: Annotated[PositiveFloat, at_most(1000, "box heights")] = FollowParameters.search_heights
    search_scale: Annotated[PositiveFloat, at_most(100, "a relative spread")] = FollowParameters.search_scale
    motion_threshold: Annotated[NonNegativeFloat, at_most(255, "grey levels")] = FollowParameters.motion_threshold
    motion_memory_s: Annotated[PositiveFloat, at_most(86_400, "seconds")] = FollowParameters.motion_memory_s
    motion_scale: Annotated[float, Field(gt=0, le=1)] = FollowParameters.motion_scale

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
