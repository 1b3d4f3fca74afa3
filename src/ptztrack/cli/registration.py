"""``ptztrack experiment registration``: the scale-invariant paper's registered PTZ views, and the
closed loop on their poses."""

import argparse
import sys
import tempfile
from pathlib import Path

from ptztrack.builders.registration import reference_index
from ptztrack.cli.scenario import command_scenario
from ptztrack.config import LiveView, PoseError, ScenarioError
from ptztrack.experiments.cells import Execution, run_experiment_cells
from ptztrack.experiments.registration import (
    closed_loop_cells,
    format_closed_loop,
    format_registration,
    live_view_settings,
    registration_views,
    run_closed_loop_cell,
    summarise_registration,
)
from ptztrack.files import write_json
from ptztrack.loop.executors import Progress


def registration_experiment_command(args: argparse.Namespace) -> int:
    scenario = command_scenario(args, args.scenario)
    if scenario.recording is None or scenario.recording.video is None:
        raise ScenarioError(f"{args.scenario}: the registration experiment needs a recording with a video")
    live_view = None if args.exact_views else scenario.camera.live_view or LiveView()
    scenario = scenario.model_copy(update={"camera": scenario.camera.model_copy(update={"live_view": live_view})})
    settings = live_view_settings(scenario)
    with tempfile.TemporaryDirectory() as scratch:
        index_path = args.index or Path(scratch) / "index.npz"
        feedback = scenario.pose_feedback.model_copy(update={"index": str(index_path)})
        scenario = scenario.model_copy(update={"pose_feedback": feedback})
        built = not Path(index_path).exists()
        print(f"{'building' if built else 'reading'} the reference index {index_path}", file=sys.stderr)
        index = reference_index(scenario)
        print(f"{len(index.poses)} reference views; registering {args.views} live views", file=sys.stderr)
        with Progress("view", args.quiet) as progress:
            views = registration_views(scenario, index, args.views, args.seed, progress)
        summary = summarise_registration(views)
        pose_error = PoseError(pan_tilt_sigma_deg=args.pose_noise_deg, zoom_sigma=args.zoom_noise)
        cells = closed_loop_cells(scenario, pose_error, args.policy, args.pose_sources)
        print(f"{len(cells)} closed-loop runs, {args.executor} executor", file=sys.stderr)
        execution = Execution(args.executor, args.workers, args.quiet)
        closed_loop = run_experiment_cells(cells, run_closed_loop_cell, execution)
    print(format_registration(summary, settings, len(index.poses), scenario.pose_feedback.image_size_px))
    print()
    print(format_closed_loop(closed_loop, args.policy, scenario, pose_error))
    if args.json is not None:
        document = {**summary, "live_view_model": settings, "closed_loop": closed_loop, "views_detail": views}
        write_json(args.json, document)
        print(f"wrote {args.json}")
    return 0
