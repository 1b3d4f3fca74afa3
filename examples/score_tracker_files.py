"""Scoring another tracker's output with ptztrack's metrics: a run's MOTChallenge files, and a second
tracker's file on the same truth, scored the same way.

    python examples/score_tracker_files.py [--frames 30] [--noise-m 0.3] [--out scored-run]

The run (``smpl``, realistic detector) writes ``truth_mot.txt`` and ``tracks_mot.txt`` into ``--out``, the
files of ``ptztrack run --out``. The second "tracker" is made up here so that the script needs nothing
else: it reports every person at every frame, ``--noise-m`` metres off (Gaussian, each axis), with an id
that changes halfway through for every third person. :func:`ptztrack.score_files` scores both files
against the one truth (positions on the ground, matched within 1 m), as ``ptztrack score TRUTH TRACKS``
does, and the first score equals the run's own metrics.
"""

import argparse
from pathlib import Path

import numpy as np

import ptztrack

SHOWN = {  # key: (heading, format)
    "mota": ("MOTA", "{:.1%}"),
    "motp_m": ("MOTP [m]", "{:.3f}"),
    "idf1": ("IDF1", "{:.1%}"),
    "switches": ("ID switches", "{:d}"),
    "false_positives": ("false pos.", "{:d}"),
    "misses": ("misses", "{:d}"),
}


def noisy_tracker_rows(truth_rows: np.ndarray, noise_m: float, rng: np.random.Generator) -> np.ndarray:
    """MOTChallenge rows (N, 10) of a tracker that sees the truth's rows (N, 10) ``noise_m`` off; every third
    person's id changes at the middle frame."""
    rows = truth_rows.copy()
    rows[:, 7:9] += rng.normal(0.0, noise_m, size=(len(rows), 2))
    middle = np.median(rows[:, 0])
    switched = (rows[:, 1] % 3 == 0) & (rows[:, 0] > middle)
    rows[switched, 1] += 1000
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=30)
    parser.add_argument("--noise-m", type=float, default=0.3)
    parser.add_argument("--out", type=Path, default=Path("scored-run"))
    args = parser.parse_args()

    scenario = ptztrack.scenario_from_dict({"frames": args.frames, "detector": {"kind": "realistic"}})
    episode = ptztrack.run_episode(scenario, "smpl", seed=0)
    run_metrics = ptztrack.episode_metrics(episode)
    ptztrack.write_outputs(args.out, episode, run_metrics)
    truth_path, tracks_path = args.out / "truth_mot.txt", args.out / "tracks_mot.txt"

    other_path = args.out / "other_tracker_mot.txt"
    other = noisy_tracker_rows(np.loadtxt(truth_path, delimiter=","), args.noise_m, np.random.default_rng(0))
    np.savetxt(other_path, other, delimiter=",", fmt=["%d", "%d", "%d", "%d", "%d", "%d", "%d", "%.4f", "%.4f", "%d"])

    scores = {
        "ptztrack smpl": ptztrack.score_files(truth_path, tracks_path),
        f"noisy ({args.noise_m} m)": ptztrack.score_files(truth_path, other_path),
    }
    run_score = scores["ptztrack smpl"]
    print(
        f"scored against {truth_path}: {run_score['frames']} frames, {run_score['people']} people, "
        f"matched within {run_score['gate_m']} m"
    )
    print(f"{'':16}" + "".join(f"{heading:>12}" for heading, _ in SHOWN.values()))
    for name, score in scores.items():
        print(f"{name:16}" + "".join(f"{form.format(score[key]):>12}" for key, (_, form) in SHOWN.items()))
    same = all(np.isclose(run_score[key], run_metrics[key]) for key in SHOWN)
    print(f"the run's own metrics {'agree' if same else 'DISAGREE'} with its files' scores")


if __name__ == "__main__":
    main()
