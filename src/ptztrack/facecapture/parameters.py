"""The face-capture experiment's parameters and their defaults, plain data (times in seconds, lengths in
metres): the road-grid scene, the tracklet tracker, the camera's zoomed view, the schedulers' weights and
the experiment's protocol."""

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class RoadSceneParameters:
    """Parameters of the road-grid scene; times in seconds, lengths in metres. Checked when made:
    a ValueError names the parameter."""

    area_m: float = 40.0
    road_spacing_m: float = 10.0
    duration_s: float = 120.0
    frame_rate_hz: float = 5.0
    people: int = 12
    entry_window_s: tuple[float, float] = (0.0, 90.0)
    speed_m_s: tuple[float, float] = (0.8, 1.6)
    turn_probability: float = 0.5
    meet_radius_m: float = 1.5
    join_probability: float = 0.5
    group_duration_s: tuple[float, float] = (5.0, 25.0)
    refractory_s: float = 5.0
    # How long a walker wants to stay; until then it turns away from the border at intersections.
    # None: it leaves at the first border it walks to.
    stay_s: tuple[float, float] | None = None

    def __post_init__(self):
        for name in ("area_m", "road_spacing_m", "duration_s", "frame_rate_hz", "meet_radius_m"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} must be positive (got {getattr(self, name)!r})")
        for name in ("people", "refractory_s"):
            if not getattr(self, name) >= 0:
                raise ValueError(f"{name} must be at least 0 (got {getattr(self, name)!r})")
        for name in ("turn_probability", "join_probability"):
            if not 0 <= getattr(self, name) <= 1:
                raise ValueError(f"{name} must be a probability in [0, 1] (got {getattr(self, name)!r})")
        for name in ("entry_window_s", "speed_m_s", "group_duration_s", "stay_s"):
            if getattr(self, name) is None:
                continue
            low, high = getattr(self, name)
            if not 0 <= low <= high:
                raise ValueError(f"{name} must be [low, high] with 0 <= low <= high (got {[low, high]})")
        if self.speed_m_s[0] <= 0:
            raise ValueError(f"speed_m_s must be positive (got {list(self.speed_m_s)})")
        if self.entry_window_s[1] > self.duration_s:
            raise ValueError("entry_window_s must end within duration_s")
        # The stepping handles one intersection per step, and a unit within
        # meet_radius_m of an intersection must have it as its next one.
        block_m = self.road_spacing_m / math.sqrt(2)
        if self.speed_m_s[1] / self.frame_rate_hz >= block_m:
            raise ValueError("speed_m_s / frame_rate_hz must stay below road_spacing_m / sqrt(2)")
        if self.meet_radius_m >= block_m:
            raise ValueError("meet_radius_m must stay below road_spacing_m / sqrt(2)")


@dataclass(frozen=True)
class TrackletTrackerParameters:
    """The tracker's parameters (all fixed a priori; the face-capture page of the docs lists their sources).

    zoom_steps : how long a face capture keeps the camera zoomed in; the capture comes at its last step.
    join_horizon_s : how far ahead a predicted meeting counts as Join(v).
    meeting_distance_m : a closest approach within this is a predicted meeting.
    gate_margin_m : gate radius for a unit seen again after a blind gap, on top of the distance the lost
        tracklet walks in the gap at its own speed.
    prior_speed_m_s : the walking speed assumed for a unit not seen at the step before.
    """

    zoom_steps: int = 10
    join_horizon_s: float = 8.0
    meeting_distance_m: float = 2.0
    gate_margin_m: float = 0.5
    prior_speed_m_s: float = 1.2


@dataclass(frozen=True)
class RoadCameraParameters:
    """The road camera (:mod:`ptztrack.facecapture.road_camera`).

    zoomed_half_width_m : half the zoomed view's width on the ground; 0.6 m makes the view 1.2 m wide,
    where a 0.15 m face spans 1/8 of the image (80 px of 640).
    """

    zoomed_half_width_m: float = 0.6


@dataclass(frozen=True)
class SchedulerParameters:
    """The MSG scheduler's alpha and beta (:mod:`ptztrack.facecapture.scheduler`, equation 5).

    source_weight : alpha's boost for a source vertex; sink_weight : beta for a target expected to leave
    within ``sink_horizon_zooms`` zoom durations (else 1).
    """

    source_weight: float = 2.0
    sink_weight: float = 2.0
    sink_horizon_zooms: float = 2.0


@dataclass(frozen=True)
class MsgExperimentParameters:
    """The face-capture experiment (:mod:`ptztrack.facecapture.experiment`).

    scene : the experiment's scenes, walkers who stay a while and meet often, so that a few dozen of them
    reach the paper's range of N_j/s (0-40); people_range : [low, high) of the people drawn per run;
    join_probability_range : [low, high) of the join probability drawn per run.
    zoom_out_score : S_zo, the score a candidate must beat to be zoomed in on (equation 5).
    bin_width : the N_j/s bins' width; key_nj_s : the paper's key ambiguity level ("for moderate
    ambiguity of N_j/s = 15"), the bin centred there.
    """

    scene: RoadSceneParameters = RoadSceneParameters(
        meet_radius_m=3.0,
        group_duration_s=(3.0, 10.0),
        stay_s=(40.0, 90.0),
        duration_s=150.0,
        entry_window_s=(0.0, 60.0),
    )
    people_range: tuple[int, int] = (8, 26)
    join_probability_range: tuple[float, float] = (0.1, 0.95)
    zoom_out_score: float = 5.0
    bin_width: int = 5
    key_nj_s: int = 15
