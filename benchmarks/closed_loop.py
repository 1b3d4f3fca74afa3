"""Closed-loop speed and metrics of every policy on the default synthetic scene.

Runs every policy with both detectors over a number of seeds and prints,
per cell, the mean metrics and the closed-loop steps per second
(scene, detection, tracking and decision together, metrics excluded, single
process).

    python benchmarks/closed_loop.py [--seeds 12] [--frames 50]
"""

import argparse
import time

import numpy as np

from ptztrack import registry
from ptztrack.builders.episode import run_episode
from ptztrack.config import scenario_from_dict
from ptztrack.evaluate.metrics import episode_metrics

COLUMNS = ("mota", "motp_m", "idf1", "height_px", "detections", "zoom")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=12)
    parser.add_argument("--frames", type=int, default=50)
    args = parser.parse_args()
    print(f"{'detector':<10}{'policy':<8}" + "".join(f"{c:>11}" for c in COLUMNS) + f"{'steps/s':>10}")
    for detector in ("ideal", "realistic"):
        scenario = scenario_from_dict({"detector": {"kind": detector}, "frames": args.frames})
        for policy in registry.names("policies"):
            start = time.perf_counter()
            episodes = [run_episode(scenario, policy, seed) for seed in range(args.seeds)]
            steps_per_s = args.seeds * args.frames / (time.perf_counter() - start)
            rows = [episode_metrics(episode) for episode in episodes]
            means = [np.mean([row[c] for row in rows]) for c in COLUMNS]
            print(f"{detector:<10}{policy:<8}" + "".join(f"{m:>11.3f}" for m in means) + f"{steps_per_s:>10.0f}")


if __name__ == "__main__":
    main()
