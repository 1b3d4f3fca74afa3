"""A long run as `ptztrack run --frames N --out DIR` makes it: identities, memory and the time to write.

Runs the scenario (the default synthetic scene, ``smpl``) for ``--frames`` steps in this process, as
``ptztrack run --out`` does (watched as it watches, keeping the view states its folder gets), sampling
the process's resident memory every ``--rss-every`` steps, then writes the run's folder as it does and
times it. It prints and writes (``--json``):

- ``idf1``, ``mota``, ``id_switches_per_100_steps`` over the run;
- ``switches_first_2000`` and ``switches_last_2000``: the identity switches of the run's first and
  last ``--window`` steps, each scored on its own;
- ``rss_mb_at``: step -> resident memory (MB) when that step was decided;
- ``write_s``: seconds to write the folder; ``run_s``: seconds to run the steps;
- ``track_ids_reported``: the distinct track ids the run reported (one person kept as themselves has one);
- ``switch_gaps``: at each identity switch, the steps since the person was last matched to a track and
  since the track that took them was last detected (how long the switched track had gone unseen), as
  percentiles 10, 50 and 90.

    python benchmarks/soak.py [--frames 20000] [--seed 0] [--scenario synthetic] [--window 2000]
                              [--rss-every 1000] [--json PATH]
"""

import argparse
import bisect
import tempfile
import time
from functools import partial
from pathlib import Path

import numpy as np
import psutil

from ptztrack.builders.episode import episode_world, make_policy, run_episode
from ptztrack.cli.run import DETECTOR_MODEL_FILE, run_view
from ptztrack.cli.scenario import build_scenario
from ptztrack.cli.watch import Watch
from ptztrack.evaluate.metrics import clear_metrics, episode_metrics, metric_accumulator
from ptztrack.evaluate.report import write_outputs
from ptztrack.files import run_folder, write_json
from ptztrack.loop.executors import Progress
from ptztrack.view.video import view_renderer


def window_switches(episode, first: int, stop: int) -> int:
    """The identity switches of steps [first, stop) of ``episode``, scored on their own."""
    tracks = episode.tracks[first:stop]
    truth = episode.truth.positions_m[first:stop]
    return int(clear_metrics(truth, [step.ids for step in tracks], [step.mean[:, :2] for step in tracks])["switches"])


def switch_gaps(episode) -> dict[str, list[float]]:
    """At each identity switch, percentiles 10, 50 and 90 of the steps since the person was last matched to a
    track (``person_unmatched_steps``) and of the steps since the track that took them was last detected
    (``track_unseen_steps``: how long the switched track had gone unseen)."""
    accumulator = metric_accumulator(
        episode.truth.positions_m, [step.ids for step in episode.tracks], [step.mean[:, :2] for step in episode.tracks]
    )
    detected_at: dict[int, list[int]] = {}
    hits_of: dict[int, int] = {}
    for step, tracks in enumerate(episode.tracks):
        for track_id, hits in zip(tracks.ids.tolist(), tracks.hits.tolist(), strict=True):
            if hits != hits_of.get(track_id):
                detected_at.setdefault(track_id, []).append(step)
            hits_of[track_id] = hits
    events = accumulator.mot_events.reset_index()
    matched = events.loc[events.Type.isin(["MATCH", "SWITCH"]), ["FrameId", "OId", "HId", "Type"]]
    last_matched, person_gaps, track_gaps = {}, [], []
    for frame, person, track_id, kind in matched.itertuples(index=False):
        if kind == "SWITCH" and person in last_matched:
            person_gaps.append(frame - last_matched[person])
            detections = detected_at.get(int(track_id), [])
            before = bisect.bisect_left(detections, frame)
            if before > 0:
                track_gaps.append(frame - detections[before - 1])
        last_matched[person] = frame
    return {
        name: np.percentile(gaps, [10, 50, 90]).tolist() if gaps else []
        for name, gaps in (("person_unmatched_steps", person_gaps), ("track_unseen_steps", track_gaps))
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=20_000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--scenario", default="synthetic", help="'synthetic' or 'pets' (built in), or a scenario YAML")
    parser.add_argument("--policy", default="smpl")
    parser.add_argument("--window", type=int, default=2000, help="steps of the first and last windows")
    parser.add_argument("--rss-every", type=int, default=1000, help="steps between two memory samples")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    if args.frames < 2 * args.window:
        parser.error(f"--frames {args.frames} must be at least twice --window {args.window}")
    scenario = build_scenario(args.scenario, frames=args.frames)
    world = episode_world(scenario, args.seed)
    policy = make_policy(args.policy, scenario, world)
    process, rss_mb_at = psutil.Process(), {}
    # As `ptztrack run --out` watches its run: the view states it keeps for the folder, a progress bar.
    watch = Watch(None, True, partial(run_view, label=args.policy), Progress("step", quiet=False))

    with watch:
        watched = watch.observe(world, policy)

        def observe(step, context, row) -> None:
            watched(step, context, row)
            if (step + 1) % args.rss_every == 0:
                rss_mb_at[step + 1] = process.memory_info().rss / 2**20

        started_s = time.perf_counter()
        episode = run_episode(scenario, policy, args.seed, world, observer=observe)
        run_s = time.perf_counter() - started_s
    metrics = episode_metrics(episode)
    steps = len(episode.actions)
    with tempfile.TemporaryDirectory() as directory:
        started_s = time.perf_counter()
        with run_folder(Path(directory) / "run", overwrite=False) as folder:
            write_outputs(folder, episode, metrics, f"soak, {args.policy}, seed {args.seed}", view_renderer(world))
            watch.write(folder)
            if world.detector_model is not None:
                world.detector_model.save(folder / DETECTOR_MODEL_FILE)
    write_s = time.perf_counter() - started_s
    document = {
        "scenario": args.scenario,
        "policy": args.policy,
        "seed": args.seed,
        "steps": steps,
        "people": int(episode.truth.positions_m.shape[1]),
        "mota": metrics["mota"],
        "idf1": metrics["idf1"],
        "id_switches_per_100_steps": 100.0 * metrics["switches"] / steps,
        "switches_first_2000": window_switches(episode, 0, args.window),
        "switches_last_2000": window_switches(episode, steps - args.window, steps),
        "track_ids_reported": len(set().union(*(step.ids.tolist() for step in episode.tracks))),
        "switch_gaps": switch_gaps(episode),
        "rss_mb_at": rss_mb_at,
        "run_s": run_s,
        "write_s": write_s,
    }
    for key, value in document.items():
        shown = {k: np.round(v).astype(int).tolist() for k, v in value.items()} if isinstance(value, dict) else value
        print(f"{key:>27}  {shown:.4g}" if isinstance(shown, float) else f"{key:>27}  {shown}")
    if args.json is not None:
        write_json(args.json, document)


if __name__ == "__main__":
    main()
