"""A camera policy of one's own, run by ptztrack beside the paper's strategies.

    python examples/custom_policy.py [--frames 25] [--sequences 3]

The policy follows the most uncertain track: among the actions the mechanics
allow, it takes the one whose view is centred nearest to that track, at the
widest zoom that still shows a person there at least 60 px tall. It is a
plain class with a ``choose`` method (:class:`ptztrack.Policy`); a factory
``(scenario, world) -> policy`` gives it the camera model and the action grid.
"""

import argparse

import numpy as np

import ptztrack
from ptztrack.geometry.ptz import look_at, project_people

MIN_HEIGHT_PX = 60.0


class FollowTheMostUncertain:
    def __init__(self, camera, grid):
        self.camera, self.grid = camera, grid

    def choose(self, context: ptztrack.DecisionContext) -> int:
        tracks = context.tracks
        if len(tracks) == 0:
            return context.current_action
        target_m = tracks.mean[np.argmax(tracks.position_sigma_m), :2]
        poses = self.grid.poses[context.reachable]
        heights_px = project_people(self.camera, poses, target_m[None], 1.75, 0.5).height_px[:, 0]
        tall_enough = heights_px >= MIN_HEIGHT_PX
        wanted = look_at(self.camera, target_m, 1.0)[:2]
        # Nearest centre first; among equals, the widest zoom that is tall enough.
        cost = np.abs(poses[:, :2] - wanted).sum(axis=1) + np.where(tall_enough, poses[:, 2], 100.0)
        return int(context.reachable[np.argmin(cost)])


def follow_the_most_uncertain(scenario, world):
    return FollowTheMostUncertain(world.camera, world.grid)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=25)
    parser.add_argument("--sequences", type=int, default=3)
    args = parser.parse_args()
    scenario = ptztrack.scenario_from_dict({"frames": args.frames, "detector": {"kind": "realistic"}})

    episode = ptztrack.run_episode(scenario, follow_the_most_uncertain, seed=0)
    metrics = ptztrack.episode_metrics(episode)
    print(f"one episode: MOTA {metrics['mota']:.1%}, mean zoom {metrics['zoom']:.2f}")

    strategies = ["fix", "smpl", follow_the_most_uncertain]
    cells = ptztrack.synthetic_cells(scenario, sequences=args.sequences, strategies=strategies)
    rows = ptztrack.execute_cells(cells, ptztrack.cell_metrics, executor="serial")
    title = f"{args.sequences} synthetic sequences of {args.frames} steps, realistic detector"
    print(ptztrack.format_table(ptztrack.summarise(rows), title))


if __name__ == "__main__":
    main()
