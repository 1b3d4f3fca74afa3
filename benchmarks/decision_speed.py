"""Decisions per second of the information-gain policies, and their cost per (action, track) against Stone Soup.

A decision scores every action of the grid for every track and takes the
best. The tracks are not invented: they are the predicted states (x-, P-) a
closed-loop episode actually produced (default scene, ideal detector, 'intg'
policy), so their covariances are those the policies meet in use (position
standard deviation: median about 0.09 m, 90th percentile about 0.36 m).
Two sizes are timed, single-threaded:

* 7 tracks x 280 actions (the synthetic experiment: 7 pan x 10 tilt x 4 zoom);
* 20 tracks x 462 actions (the paper's real camera: 14 pan x 11 tilt x 3 zoom,
  10.4 deg and 4.3 deg steps, zoom 1x, 6x and 9x; 20 people in the area).

Before timing, it checks the kernels on every recorded state: each
policy's rewards of all actions must agree, to 1e-9 of the largest, with the
plain NumPy evaluation of the same estimator in
``tests/information_gain_reference.py`` (same random draws for 'smpl'), and
the best action must be the same; the script stops if not.

In the same run it times Stone Soup's BruteForceSensorManager with its
UncertaintyRewardFunction choosing among as many actions for as many tracks
(see stonesoup_reference.py; needs the ``bench`` extra) and prints the ratio
of the time per (action, track) evaluation.

    OMP_NUM_THREADS=1 python benchmarks/decision_speed.py [--json PATH]

``--json`` writes ``intg_decisions_per_s``, ``smpl_decisions_per_s`` and
``stonesoup_ratio`` (7 x 280), ``smpl_20x462_decisions_per_s``, and every
figure by size under ``sizes``.
"""

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402  (the thread count must be set before NumPy loads)
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from ptztrack.builders.episode import make_policy, run_episode  # noqa: E402
from ptztrack.builders.world import action_grid, build_world  # noqa: E402
from ptztrack.config import scenario_from_dict  # noqa: E402
from ptztrack.files import write_json  # noqa: E402
from ptztrack.types import Tracks  # noqa: E402

# The NumPy reference is test code, not part of the installed package.
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import information_gain_reference  # noqa: E402

# Rewards may differ from the reference's by rounding only.
REWARD_TOLERANCE = 1e-9

SIZES = {
    "7x280": {"detector": {"kind": "ideal"}, "control": {"beta": 1.0}, "frames": 60},
    "20x462": {
        "detector": {"kind": "ideal"},
        "control": {"beta": 1.0},
        "frames": 60,
        "people": {"count": 20},
        "actions": {
            "pan_deg": {"start": -67.6, "stop": 67.6, "count": 14},
            "tilt_deg": {"start": 15.0, "stop": 58.0, "count": 11},
            "zoom": [1.0, 6.0, 9.0],
        },
    },
}


def recorded_states(scenario, track_count: int, seed: int = 0) -> list[Tracks]:
    """Tracks the closed loop produced, trimmed to ``track_count`` (steps with fewer are skipped)."""
    states = []
    while len(states) < 20:
        for tracks in run_episode(scenario, "intg", seed).tracks[5:]:
            if len(tracks) >= track_count:
                states.append(tracks.select(np.arange(track_count)))
        seed += 1
    return states


def check_against_reference(policy, states, actions) -> float:
    """Stop unless the policy's rewards match the reference's on every state; returns the largest
    difference relative to the state's largest reward."""
    worst = 0.0
    for index, tracks in enumerate(states):
        reward = policy.rewards(actions, tracks, np.random.default_rng(index))
        expected = information_gain_reference.rewards(policy, actions, tracks, np.random.default_rng(index))
        difference = float(np.max(np.abs(reward - expected)) / np.max(np.abs(expected)))
        if difference > REWARD_TOLERANCE or np.argmax(reward) != np.argmax(expected):
            raise SystemExit(
                f"{policy.method}: state {index}: rewards {difference:.1e} apart, best action "
                f"{np.argmax(reward)} against the reference's {np.argmax(expected)}"
            )
        worst = max(worst, difference)
    return worst


def decisions_per_second(policy, states, actions, rng, minimum_s: float = 2.0) -> tuple[float, float]:
    """Decisions per second of wall-clock and of CPU time, each from the fastest of the passes over
    ``states`` made in ``minimum_s`` (at least three): on a shared machine the slower passes
    measure the other processes."""
    wall_s, cpu_s, start = [], [], time.perf_counter()
    while len(wall_s) < 3 or time.perf_counter() - start < minimum_s:
        wall_start, cpu_start = time.perf_counter(), time.process_time()
        for tracks in states:
            int(np.argmax(policy.rewards(actions, tracks, rng)))
        wall_s.append(time.perf_counter() - wall_start)
        cpu_s.append(time.process_time() - cpu_start)
    return len(states) / min(wall_s), len(states) / min(cpu_s)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", type=Path, help="write the figures here")
    args = parser.parse_args()
    sys.path.insert(0, str(Path(__file__).parent))
    try:
        from stonesoup_reference import stonesoup_seconds_per_action_track
    except ImportError:
        stonesoup_seconds_per_action_track = None
        print("Stone Soup is not installed (pip install '.[bench]'): no ratio")
    figures = {}
    for size, overrides in SIZES.items():
        scenario = scenario_from_dict(overrides)
        track_count = scenario.people.count
        actions = np.arange(action_grid(scenario).size)
        states = recorded_states(scenario, track_count)
        rng = np.random.default_rng(0)
        rates, cpu_rates = {}, {}
        for method in ("intg", "smpl"):
            policy = make_policy(method, scenario, build_world(scenario, rng))
            difference = check_against_reference(policy, states, actions)
            print(
                f"{size} {method}: the reference's best action in all {len(states)} recorded states, "
                f"rewards within {difference:.1e} of the largest",
                flush=True,
            )
            rates[method], cpu_rates[method] = decisions_per_second(policy, states, actions, rng)
        pairs = track_count * len(actions)
        line = (
            f"{size}: intg {rates['intg']:.0f} decisions/s (CPU time: {cpu_rates['intg']:.0f}), "
            f"smpl (M={scenario.control.samples}) {rates['smpl']:.1f} decisions/s (CPU time: {cpu_rates['smpl']:.1f})"
        )
        if stonesoup_seconds_per_action_track is not None:
            reference_s = stonesoup_seconds_per_action_track(track_count, len(actions))
            ratios = {method: reference_s * rate * pairs for method, rate in rates.items()}
            line += (
                f"; Stone Soup {reference_s * 1e6:.0f} us per action-track, "
                f"intg {ratios['intg']:.0f}x and smpl {ratios['smpl']:.0f}x faster per action-track"
            )
        else:
            ratios = {"intg": None}
        print(line, flush=True)
        figures[size] = {
            "intg": rates["intg"],
            "smpl": rates["smpl"],
            "intg_cpu": cpu_rates["intg"],
            "smpl_cpu": cpu_rates["smpl"],
            "stonesoup_ratio": ratios["intg"],
        }
    if args.json:
        main_size = figures["7x280"]
        write_json(
            args.json,
            {
                "intg_decisions_per_s": main_size["intg"],
                "smpl_decisions_per_s": main_size["smpl"],
                "stonesoup_ratio": main_size["stonesoup_ratio"],
                "smpl_20x462_decisions_per_s": figures["20x462"]["smpl"],
                "sizes": figures,
            },
        )


if __name__ == "__main__":
    main()
