"""Synthetic people walking on the ground plane (paper section 5.1).

The paper gives only "a 15 x 15 m area, 7 targets following random
trajectories mimicking human motion". Here each person walks at a constant
speed drawn from ``speed_m_s`` and turns smoothly: the turn rate is an
Ornstein-Uhlenbeck process (time constant 2 s, stationary spread
``turn_rate_sigma_deg_s``), and a person whose path 2 s ahead would leave
the area turns towards its centre at up to 60 deg/s, so trajectories stay
inside without sharp reflections.

Camera mounting (the paper does not say): by default the PTZ head is 7 m
above the ground, 4 m behind the middle of one edge of the area, at
(7.5, -4, 7) m, with a 640 x 480 image and f_min = 400 px (77 deg horizontal
field of view at zoom 1). At zoom 1, aimed at the area, it sees 96 % of the
area with head and feet in the image, and a person looks 50 px tall on
average, close to the 49 px the paper reports for its 'fix' strategy.
"""

import numpy as np

from ptztrack.scene.parameters import CrowdParameters
from ptztrack.types import GroundTruth

TURN_TIME_CONSTANT_S = 2.0
LOOKAHEAD_S = 2.0
MAX_STEERING_RATE_DEG_S = 60.0
BORDER_MARGIN_M = 0.5


def _wrap_angle(angle_rad):
    return (angle_rad + np.pi) % (2 * np.pi) - np.pi


def walk_people(
    people: CrowdParameters, area_m: tuple[float, float], frames: int, frame_rate_hz: float, rng: np.random.Generator
) -> GroundTruth:
    """Draw the trajectories of ``people.count`` walkers in the area ``[0, w] x [0, d]``.

    With ``people.enter_leave`` each person enters through a random point of
    the border at a random frame, stays ``stay_s`` seconds (steering away from
    the border) and then walks on until it crosses the border and is gone.
    """
    count = people.count
    dt_s = 1.0 / frame_rate_hz
    area = np.asarray(area_m, dtype=float)
    speed = rng.uniform(*people.speed_m_s, size=count)
    heights_m = rng.uniform(*people.height_m, size=count)
    widths_m = np.full(count, people.width_m)
    decay = np.exp(-dt_s / TURN_TIME_CONSTANT_S)
    turn_sigma = np.deg2rad(people.turn_rate_sigma_deg_s) * np.sqrt(1 - decay**2)
    max_steer_rad = np.deg2rad(MAX_STEERING_RATE_DEG_S) * dt_s

    if people.enter_leave:
        stay_frames = np.round(rng.uniform(*people.stay_s, size=count) * frame_rate_hz).astype(int)
        entry_frame = rng.integers(0, max(frames // 2, 1), size=count)
        position = _border_points(area, rng, count)
        towards_inside = rng.uniform(0.25, 0.75, size=(count, 2)) * area - position
        heading = np.arctan2(towards_inside[:, 1], towards_inside[:, 0])
    else:
        stay_frames = np.full(count, frames)
        entry_frame = np.zeros(count, dtype=int)
        position = rng.uniform(BORDER_MARGIN_M, area - BORDER_MARGIN_M, size=(count, 2))
        heading = rng.uniform(-np.pi, np.pi, size=count)
    turn_rate = rng.normal(0.0, np.deg2rad(people.turn_rate_sigma_deg_s), size=count)

    positions_m = np.full((frames, count, 2), np.nan)
    headings = np.zeros((frames, count))
    gone = np.zeros(count, dtype=bool)
    centre = area / 2
    for frame in range(frames):
        entered = frame >= entry_frame
        present = entered & ~gone
        positions_m[frame, present] = position[present]
        headings[frame] = heading

        staying = frame < entry_frame + stay_frames
        ahead = position + LOOKAHEAD_S * speed[:, None] * np.stack([np.cos(heading), np.sin(heading)], -1)
        leaving_soon = np.any((ahead < BORDER_MARGIN_M) | (ahead > area - BORDER_MARGIN_M), axis=-1)
        steer = staying & leaving_soon
        to_centre = np.arctan2(centre[1] - position[:, 1], centre[0] - position[:, 0])
        correction = np.clip(_wrap_angle(to_centre - heading), -max_steer_rad, max_steer_rad)
        turn_rate = decay * turn_rate + turn_sigma * rng.standard_normal(count)
        heading = heading + np.where(steer, correction, turn_rate * dt_s)

        moving = entered & ~gone
        step = speed[:, None] * dt_s * np.stack([np.cos(heading), np.sin(heading)], -1)
        position = np.where(moving[:, None], position + step, position)
        outside = np.any((position < 0) | (position > area), axis=-1)
        gone |= moving & ~staying & outside
        position = np.where((staying & moving)[:, None], np.clip(position, 0.0, area), position)

    for leader in range(0, 2 * people.pairs, 2):
        positions_m[:, leader + 1] = _beside(positions_m[:, leader], headings[:, leader], people.pair_spacing_m, area)
    return GroundTruth(positions_m=positions_m, heights_m=heights_m, widths_m=widths_m, frame_rate_hz=frame_rate_hz)


def _beside(leader_m, heading_rad, spacing_m: float, area: np.ndarray) -> np.ndarray:
    """Where somebody walking ``spacing_m`` to the left of a leader at ``leader_m`` (T, 2) is (T, 2),
    kept inside the area; absent (NaN) where the leader is."""
    left = np.stack([-np.sin(heading_rad), np.cos(heading_rad)], axis=-1)
    return np.clip(leader_m + spacing_m * left, 0.0, area)


def _border_points(area: np.ndarray, rng: np.random.Generator, count: int) -> np.ndarray:
    """Uniform random points on the border of the area rectangle; (count, 2)."""
    perimeter = 2 * (area[0] + area[1])
    s = rng.uniform(0, perimeter, size=count)
    w, d = area
    return np.select(
        [s[:, None] < w, s[:, None] < w + d, s[:, None] < 2 * w + d],
        [
            np.stack([s, np.zeros(count)], -1),
            np.stack([np.full(count, w), s - w], -1),
            np.stack([2 * w + d - s, np.full(count, d)], -1),
        ],
        np.stack([np.zeros(count), perimeter - s], -1),
    )
