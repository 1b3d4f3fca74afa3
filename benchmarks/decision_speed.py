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

In the same run it times Stone Soup's BruteForceSensorManager with its
UncertaintyRewardFunction choosing among as many actions for as many tracks
(see stonesoup_reference.py; needs the ``bench`` extra) and prints the ratio
of the time per (action, track) evaluation.

    OMP_NUM_THREADS=1 python benchmarks/decision_speed.py [--json PATH]
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


def decisions_per_second(policy, states, actions, rng, minimum_s: float = 2.0) -> float:
    count, start = 0, time.perf_counter()
    while time.perf_counter() - start < minimum_s:
        for tracks in states:
            int(np.argmax(policy.rewards(actions, tracks, rng)))
            count += 1
    return count / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", type=Path, help="write the figures of the 7 x 280 case here")
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
        rates = {}
        for method in ("intg", "smpl"):
            policy = make_policy(method, scenario, build_world(scenario, rng))
            policy.rewards(actions, states[0], rng)
            rates[method] = decisions_per_second(policy, states, actions, rng)
        pairs = track_count * len(actions)
        line = (
            f"{size}: intg {rates['intg']:.0f} decisions/s, "
            f"smpl (M={scenario.control.samples}) {rates['smpl']:.1f} decisions/s"
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
        figures[size] = {"intg": rates["intg"], "smpl": rates["smpl"], "stonesoup_ratio": ratios["intg"]}
    if args.json:
        main_size = figures["7x280"]
        write_json(
            args.json,
            {
                "intg_decisions_per_s": main_size["intg"],
                "smpl_decisions_per_s": main_size["smpl"],
                "stonesoup_ratio": main_size["stonesoup_ratio"],
                "sizes": figures,
            },
        )


if __name__ == "__main__":
    main()
