"""``ptztrack follow`` and ``ptztrack experiment follow``: the robot-cameraman paper's follow camera."""

import argparse
import sys
from pathlib import Path

from ptztrack.builders.recording import FOLLOW_PROTOCOL, pets_follow_scenario
from ptztrack.cli.options import RUN_FOLDER_FILES
from ptztrack.cli.scenario import build_scenario, recording_overrides, recording_paths, scenario_file
from ptztrack.cli.watch import Watch
from ptztrack.config import Scenario, load_scenario
from ptztrack.evaluate.report import write_outputs
from ptztrack.experiments.cells import Execution, run_experiment_cells
from ptztrack.experiments.follow import (
    FOLLOW_FIGURES,
    FollowCell,
    follow_cells,
    follow_row,
    follow_run,
    format_follow_experiment,
    format_follow_table,
    otb_cells,
    run_follow_cell,
    run_otb_cell,
    summarise_follow_experiment,
)
from ptztrack.files import check_output_folder, run_folder, write_json
from ptztrack.loop.executors import Progress
from ptztrack.view.video import view_renderer
from ptztrack.view.view_state import ViewState


def _follow_scenario(args: argparse.Namespace, tracker: str = "particle") -> Scenario:
    """The follow camera's scenario: the built-in PETS one, a dataset file's view or a YAML file, with the
    command line's changes."""
    overrides = recording_overrides(recording_paths(args))
    if args.achromatic_bins:
        overrides["follow.achromatic_bins"] = True
    if getattr(args, "target_point_px", None) is not None:
        overrides["follow.target_point_px"] = tuple(args.target_point_px)
    if args.dataset is not None or args.dataset_view is not None:
        overrides["tracker.kind"] = tracker
        return build_scenario(
            args.scenario, dataset=args.dataset, view=args.dataset_view, protocol=FOLLOW_PROTOCOL, overrides=overrides
        )
    if args.scenario == "pets":
        return pets_follow_scenario(tracker, **overrides)
    return load_scenario(scenario_file(args.scenario, ("pets",)), **overrides, **{"tracker.kind": tracker})


def follow_command(args: argparse.Namespace) -> int:
    out = args.out or Path(f"follow-{args.target}")
    check_output_folder(out, "--out", args.overwrite)
    scenario = _follow_scenario(args, args.tracker)
    if args.frames is not None:
        scenario = scenario.model_copy(update={"frames": args.frames})
    label = f"follow person {args.target}, {args.tracker}"

    def view(world, policy) -> ViewState:
        target_point_px = policy.parameters.target_point_px
        steps = world.truth.positions_m.shape[0]
        return ViewState(world, policy, steps, label, view_renderer(world), grid=False, target_point_px=target_point_px)

    with Watch(args.view, True, view, Progress("step", args.quiet), args.view_wait) as watch:
        narrowed, world, episode = follow_run(FollowCell(scenario, args.tracker, args.target, args.seed), watch.observe)
    row = follow_row(narrowed, world, episode)
    frame_range = narrowed.required_recording("the follow camera").frame_range
    first_frame = frame_range[0] if frame_range is not None else 0
    print(f"person {args.target} followed by {args.tracker} from frame {first_frame}, {row['steps']} steps")
    print(format_follow_table([row], FOLLOW_FIGURES))
    title = f"person {args.target}, {args.tracker}: in view {row['in_view_fraction']:.0%}"
    with run_folder(out, args.overwrite) as folder:
        write_outputs(folder, episode, row, title, view_renderer(world))
        watch.write(folder)
    print(f"wrote {', '.join(RUN_FOLDER_FILES)} into {out}")
    return 0


def follow_experiment_command(args: argparse.Namespace) -> int:
    scenario = _follow_scenario(args)
    cells = follow_cells(scenario, args.trackers, args.targets, args.seed)
    otb_runs = otb_cells(scenario, args.trackers, args.otb_tracks, args.seed)
    print(f"{len(cells)} closed-loop runs, {args.executor} executor", file=sys.stderr)
    execution = Execution(args.executor, args.workers, args.quiet)
    people = run_experiment_cells(cells, run_follow_cell, execution)
    print(f"{len(otb_runs)} one-pass runs on the still recording", file=sys.stderr)
    otb_people = run_experiment_cells(otb_runs, run_otb_cell, execution, "run")
    summary = summarise_follow_experiment(people, otb_people)
    print(format_follow_experiment(scenario, summary, args.trackers))
    if args.json is not None:
        write_json(args.json, summary)
        print(f"wrote {args.json}")
    return 0
