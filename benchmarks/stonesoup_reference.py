"""Reference speed of Stone Soup's sensor manager for one (action, track) evaluation.

Our PTZ policy must score one (action, track) pair at least 1000 times faster
than Stone Soup does in the same run. This module measures the Stone Soup side:
``BruteForceSensorManager`` with ``UncertaintyRewardFunction`` choosing the
dwell centre of one ``RadarRotatingBearingRange`` for a set of Gaussian
constant-velocity tracks.

    python benchmarks/stonesoup_reference.py --tracks 7 --actions 280

needs ``pip install "stonesoup==1.9.*"`` (not a dependency of ptztrack).
Stone Soup does no network access on this path.
"""

import argparse
import datetime
import itertools
import time
from dataclasses import dataclass

import numpy as np
from stonesoup.models.transition.linear import (
    CombinedLinearGaussianTransitionModel,
    ConstantVelocity,
)
from stonesoup.predictor.kalman import KalmanPredictor
from stonesoup.sensor.radar.radar import RadarRotatingBearingRange
from stonesoup.sensormanager import BruteForceSensorManager
from stonesoup.sensormanager.reward import UncertaintyRewardFunction
from stonesoup.types.array import CovarianceMatrix, StateVector
from stonesoup.types.state import GaussianState
from stonesoup.types.track import Track
from stonesoup.updater.kalman import ExtendedKalmanUpdater

# Horizontal field of view of the radar beam [deg]. Only tracks inside the beam
# get a Kalman update in UncertaintyRewardFunction; the others are still
# predicted and tested for visibility. 60 deg is a wide-angle PTZ view; a
# narrower beam makes Stone Soup cheaper per pair (a stricter reference).
FOV_DEG = 60.0

# Look-ahead of one decision [s]: the sensor may turn during this time.
DECISION_INTERVAL_S = 1.0


class _CountingReward(UncertaintyRewardFunction):
    """UncertaintyRewardFunction that counts its calls.

    BruteForceSensorManager calls the reward function once per configuration it
    scores, so the count is the number of actions really evaluated. The extra
    cost (one integer increment) is negligible next to one call (~ms).
    """

    calls = 0

    def __call__(self, config, tracks, metric_time, *args, **kwargs):
        self.calls += 1
        return super().__call__(config, tracks, metric_time, *args, **kwargs)


class _CountingUpdater(ExtendedKalmanUpdater):
    """ExtendedKalmanUpdater that counts updates (one per track inside the beam)."""

    calls = 0

    def update(self, hypothesis, **kwargs):
        self.calls += 1
        return super().update(hypothesis, **kwargs)


@dataclass(frozen=True)
class StoneSoupTiming:
    """One measurement of BruteForceSensorManager.choose_actions."""

    num_tracks: int
    requested_actions: int
    evaluated_actions: int  # configurations scored in one decision (counted reward calls)
    seconds_per_decision: float  # [s], minimum over the repeats
    updates_per_decision: int  # Kalman updates in one decision (track inside the beam)

    @property
    def seconds_per_action_track(self) -> float:
        """[s] per (action, track) evaluation."""
        return self.seconds_per_decision / (self.evaluated_actions * self.num_tracks)


def _make_sensor(num_actions: int, fov_deg: float, start: datetime.datetime):
    """Radar at the origin whose dwell-centre generator yields ``num_actions`` bearings.

    DwellActionsGenerator yields the bearings initial - delta, initial - delta +
    resolution, ... up to initial + delta, with delta = interval * rpm / 60 * 2 pi.
    With resolution = 2 pi / N and delta = pi - resolution / 2 these are N
    distinct bearings evenly spread over the full circle, like a pan sweep.
    """
    resolution = 2 * np.pi / num_actions
    half_span = np.pi - resolution / 2  # [rad]
    rpm = 60.0 * half_span / (2 * np.pi * DECISION_INTERVAL_S)
    sensor = RadarRotatingBearingRange(
        position_mapping=(0, 2),
        noise_covar=CovarianceMatrix(np.diag([np.radians(1.0) ** 2, 0.5**2])),  # [rad^2, m^2]
        ndim_state=4,
        position=StateVector([0.0, 0.0]),
        rpm=rpm,
        resolution=resolution,
        fov_angle=np.radians(fov_deg),
        dwell_centre=StateVector([0.0]),
        max_range=np.inf,
    )
    # Without a start time, actions() would take the decision time as start and
    # offer a single (zero-length) action.
    sensor.timestamp = start
    return sensor


def _make_tracks(num_tracks: int, rng: np.random.Generator, start: datetime.datetime):
    """Tracks with one Gaussian (x, vx, y, vy) state [m, m/s] at random bearings, 10-60 m away."""
    bearings = rng.uniform(-np.pi, np.pi, num_tracks)
    ranges = rng.uniform(10.0, 60.0, num_tracks)
    velocities = rng.normal(0.0, 1.0, (num_tracks, 2))
    covar = CovarianceMatrix(np.diag([0.5**2, 0.2**2, 0.5**2, 0.2**2]))
    return {
        Track([GaussianState(StateVector([r * np.cos(b), v[0], r * np.sin(b), v[1]]), covar, timestamp=start)])
        for b, r, v in zip(bearings, ranges, velocities, strict=True)
    }


def measure_stonesoup(
    num_tracks: int, num_actions: int, repeats: int = 3, seed: int = 0, fov_deg: float = FOV_DEG
) -> StoneSoupTiming:
    """Time Stone Soup choosing one dwell centre among ~num_actions for num_tracks tracks."""
    if num_tracks < 1 or num_actions < 1 or repeats < 1:
        raise ValueError("num_tracks, num_actions and repeats must be >= 1")
    start = datetime.datetime(2024, 1, 1)
    decision_time = start + datetime.timedelta(seconds=DECISION_INTERVAL_S)
    sensor = _make_sensor(num_actions, fov_deg, start)
    tracks = _make_tracks(num_tracks, np.random.default_rng(seed), start)

    transition = CombinedLinearGaussianTransitionModel([ConstantVelocity(0.05), ConstantVelocity(0.05)])  # [m^2/s^3]
    # The updater takes the measurement model from each simulated detection,
    # i.e. the radar's model for the candidate dwell centre.
    updater = _CountingUpdater(measurement_model=None)
    reward = _CountingReward(predictor=KalmanPredictor(transition), updater=updater)
    manager = BruteForceSensorManager(sensors={sensor}, reward_function=reward)

    # What the manager will enumerate: the product over the sensor's generators.
    enumerated = len(list(itertools.product(*sensor.actions(decision_time))))

    best = np.inf
    counts = set()
    for _ in range(repeats):
        reward.calls = updater.calls = 0
        t0 = time.perf_counter()
        manager.choose_actions(tracks, decision_time)
        best = min(best, time.perf_counter() - t0)
        counts.add((reward.calls, updater.calls))
    # choose_actions acts on copies of the sensor, so every repeat does the same work.
    if len(counts) != 1 or next(iter(counts))[0] != enumerated:
        raise RuntimeError(f"inconsistent action counts: {counts}, enumerated {enumerated}")
    evaluated, updates = counts.pop()
    return StoneSoupTiming(num_tracks, num_actions, evaluated, best, updates)


def stonesoup_seconds_per_action_track(
    num_tracks: int, num_actions: int, repeats: int = 3, seed: int = 0, *, fov_deg: float = FOV_DEG
) -> float:
    """Seconds Stone Soup's BruteForceSensorManager + UncertaintyRewardFunction spends per
    (action, track) evaluation, choosing among ~num_actions actions for num_tracks Gaussian tracks.

    One RadarRotatingBearingRange with a single actionable property (its dwell
    centre), so the manager scores single actions, not combinations; its
    generator is set up to offer exactly num_actions bearings over 360 deg.
    Times ``choose_actions`` (minimum over ``repeats``, time.perf_counter) and
    divides by the counted reward-function calls times num_tracks. Runs the full
    action count (no subsampling). Returns seconds [s].
    """
    return measure_stonesoup(num_tracks, num_actions, repeats, seed, fov_deg).seconds_per_action_track


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tracks", type=int, default=7)
    parser.add_argument("--actions", type=int, default=280)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--fov-deg", type=float, default=FOV_DEG)
    args = parser.parse_args()
    timing = measure_stonesoup(args.tracks, args.actions, args.repeats, args.seed, args.fov_deg)
    print(f"tracks: {timing.num_tracks}  actions requested: {timing.requested_actions}  fov: {args.fov_deg:g} deg")
    print(f"actions evaluated: {timing.evaluated_actions}")
    print(
        f"Kalman updates per decision: {timing.updates_per_decision} "
        f"(of {timing.evaluated_actions * timing.num_tracks} action-track pairs)"
    )
    print(f"seconds per decision: {timing.seconds_per_decision:.4f}")
    print(f"seconds per action-track evaluation: {timing.seconds_per_action_track:.3e}")


if __name__ == "__main__":
    main()
