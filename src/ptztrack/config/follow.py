"""The scenario's follow section: the follow camera's person, its motion limits and its particle filter."""

from typing import Annotated, Literal

from pydantic import Field, model_validator

from ptztrack.config.fields import NonNegativeFloat, PositiveFloat, _Strict, _Zoom, at_most, at_most_items
from ptztrack.follow.parameters import FollowSettings

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
    """The follow camera's section: :class:`~ptztrack.follow.parameters.FollowSettings`, whose fields
    it validates and whose defaults it takes (their meaning is given there).

    The ``tracker.kind`` 'particle' (the paper's particle filter), 'csrt' or 'mil' (OpenCV's) follows
    the person and the policy 'follow' moves the camera.
    """

    target_id: int | None = FollowSettings.target_id
    target_point_px: tuple[_FollowPixels, _FollowPixels] | None = FollowSettings.target_point_px
    target_height_px: Annotated[PositiveFloat, at_most(8192, "pixels")] = FollowSettings.target_height_px
    max_speed_deg_s: Annotated[PositiveFloat, at_most(1000, "degrees per second")] = FollowSettings.max_speed_deg_s
    max_acceleration_deg_s2: Annotated[PositiveFloat, at_most(10_000, "degrees per second squared")] = (
        FollowSettings.max_acceleration_deg_s2
    )
    max_zoom_speed: Annotated[PositiveFloat, at_most(100, "per second")] = FollowSettings.max_zoom_speed
    max_zoom_acceleration: Annotated[PositiveFloat, at_most(1000, "per second squared")] = (
        FollowSettings.max_zoom_acceleration
    )
    zoom_range: tuple[_Zoom, _Zoom] = FollowSettings.zoom_range
    smoothing_cutoff_hz: Annotated[PositiveFloat, at_most(1000, "hertz")] = FollowSettings.smoothing_cutoff_hz
    particles: Annotated[int, Field(ge=1), at_most(100_000, _PARTICLE_TIME)] = FollowSettings.particles
    search_particles: Annotated[int, Field(ge=2), at_most(100_000, _PARTICLE_TIME)] = FollowSettings.search_particles
    patches: Annotated[tuple[Patch, ...], at_most_items(100, _PARTICLE_TIME)] = FollowSettings.patches
    histogram_bins: int = Field(FollowSettings.histogram_bins, ge=1, le=64)
    achromatic_bins: bool = FollowSettings.achromatic_bins
    background_area_ratio: Annotated[float, Field(gt=1), at_most(10_000, "box areas")] | None = (
        FollowSettings.background_area_ratio
    )
    height_log_sigma: PositiveFloat | None = FollowSettings.height_log_sigma
    samples_per_patch: Annotated[int, Field(ge=1), at_most(1000, _PARTICLE_TIME)] = FollowSettings.samples_per_patch
    lambda_colour: Annotated[PositiveFloat, at_most(1e6, "a likelihood scale")] = FollowSettings.lambda_colour
    lambda_loss: Annotated[PositiveFloat, at_most(1e6, "a likelihood scale")] = FollowSettings.lambda_loss
    lambda_motion: Annotated[PositiveFloat, at_most(1e6, "a likelihood scale")] = FollowSettings.lambda_motion
    walk_heights_per_s: Annotated[PositiveFloat, at_most(1000, "box heights per second")] = (
        FollowSettings.walk_heights_per_s
    )
    scale_change_per_s: Annotated[PositiveFloat, at_most(100, "per second")] = FollowSettings.scale_change_per_s
    prediction: Literal["constant_velocity", "particle_velocity", "random_walk"] = FollowSettings.prediction
    acceleration_heights_per_s2: Annotated[PositiveFloat, at_most(1000, "box heights per second squared")] = (
        FollowSettings.acceleration_heights_per_s2
    )
    initial_speed_heights_per_s: Annotated[PositiveFloat, at_most(1000, "box heights per second")] = (
        FollowSettings.initial_speed_heights_per_s
    )
    loss_fraction: Fraction = FollowSettings.loss_fraction
    adapt_fraction: Fraction = FollowSettings.adapt_fraction
    reference_time_constant_s: Annotated[PositiveFloat, at_most(86_400, "seconds")] = (
        FollowSettings.reference_time_constant_s
    )
    search_heights: Annotated[PositiveFloat, at_most(1000, "box heights")] = FollowSettings.search_heights
    search_scale: Annotated[PositiveFloat, at_most(100, "a relative spread")] = FollowSettings.search_scale
    motion_threshold: Annotated[NonNegativeFloat, at_most(255, "grey levels")] = FollowSettings.motion_threshold
    motion_memory_s: Annotated[PositiveFloat, at_most(86_400, "seconds")] = FollowSettings.motion_memory_s
    motion_scale: Annotated[float, Field(gt=0, le=1)] = FollowSettings.motion_scale

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
