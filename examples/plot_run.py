"""A run drawn with Matplotlib: where everybody walked and where the tracks went, and what the camera did
step by step.

    python examples/plot_run.py [--policy smpl] [--frames 40] [--out run.png]

Left, the ground plane: each person's true path in grey and each track's path in a colour of its own
(its id at its end). Right, per step: the camera's zoom, the people in the scene and the tracks it
reported. Drawn off-screen (Matplotlib's Agg backend) into ``--out``.
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
import numpy as np  # noqa: E402

import ptztrack  # noqa: E402


def track_paths(episode: ptztrack.Episode) -> dict[int, np.ndarray]:
    """Each reported track's ground positions (n, 2) in metres, in step order."""
    paths: dict[int, list] = {}
    for tracks in episode.tracks:
        for track_id, state in zip(tracks.ids.tolist(), tracks.mean, strict=True):
            paths.setdefault(track_id, []).append(state[:2])
    return {track_id: np.array(points) for track_id, points in paths.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--policy", default="smpl")
    parser.add_argument("--frames", type=int, default=40)
    parser.add_argument("--out", type=Path, default=Path("run.png"))
    args = parser.parse_args()

    scenario = ptztrack.scenario_from_dict({"frames": args.frames, "detector": {"kind": "realistic"}})
    episode = ptztrack.run_episode(scenario, args.policy, seed=0)
    metrics = ptztrack.episode_metrics(episode)

    figure, (ground, steps) = plt.subplots(1, 2, figsize=(11, 5))
    area = np.vstack([episode.area_polygon_m, episode.area_polygon_m[:1]])
    ground.plot(area[:, 0], area[:, 1], color="black", linewidth=0.8)
    for person in range(episode.truth.positions_m.shape[1]):
        path = episode.truth.positions_m[:, person]
        ground.plot(path[:, 0], path[:, 1], color="0.7", linewidth=3)
    for track_id, path in track_paths(episode).items():
        (line,) = ground.plot(path[:, 0], path[:, 1], linewidth=1.2)
        ground.annotate(str(track_id), path[-1], color=line.get_color(), fontsize=8)
    ground.set(xlabel="x [m]", ylabel="y [m]", aspect="equal", title="true paths (grey) and tracks")

    step = np.arange(len(episode.poses))
    steps.plot(step, episode.poses[:, 2], label="zoom", drawstyle="steps-post")
    steps.plot(step, episode.truth.present.sum(axis=1), label="people in the scene")
    steps.plot(step, [len(tracks) for tracks in episode.tracks], label="tracks reported")
    steps.set(xlabel="step", title=f"{args.policy}: MOTA {metrics['mota']:.1%}, IDF1 {metrics['idf1']:.1%}")
    steps.legend()

    figure.tight_layout()
    figure.savefig(args.out, dpi=100)
    print(f"wrote {args.out} ({len(track_paths(episode))} tracks of {episode.truth.positions_m.shape[1]} people)")


if __name__ == "__main__":
    main()
