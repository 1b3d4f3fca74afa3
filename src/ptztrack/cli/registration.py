"""``ptztrack experiment registration``: the scale-invariant paper's registered PTZ views, and the
closed loop on their poses."""

import argparse
import sys
import tempfile
from pathlib import Path

from ptztrack.builders.registration import reference_index
from ptztrack.cli.scenario import command_scenario
from ptztrack.config import LiveView, PoseError, ScenarioError
from ptztrack.evaluate.executors import Progress
from ptztrack.evaluate.registration import summarise_registration
from ptztrack.experiments.cells import Execution, run_experiment_cells
from ptztrack.experiments.registration import (
    closed_loop_cells,
    live_view_settings,
    registration_views,
    run_closed_loop_cell,
)
from ptztrack.files import write_json
from ptztrack.names import POSE_SOURCES


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
    size = scenario.pose_feedback.image_size_px
    print(
        f"Registration of {summary['views']} live views at random reachable poses, {size[0]} x {size[1]} px, "
        f"against {len(index.poses)} reference views: {summary['registered']} registered"
    )
    print(f"  {_describe_live_views(settings)}")
    for name, key, unit in (
        ("focal length error", "focal_err", "pct"),
        ("ground error", "ground_err", "m"),
        ("  with true pose", "oracle_ground_err", "m"),
        ("  with lens", "lens_ground_err", "m"),
    ):
        median, p90 = (_unless_failed(summary[f"{key}_{which}_{unit}"]) for which in ("median", "p90"))
        symbol = "%" if unit == "pct" else unit
        print(f"  {name:<19} median {median} {symbol}   p90 {p90} {symbol}")
    print(f"  time per view       median {summary['register_ms_median']:.0f} ms")
    print(
        f"\nClosed loop: {args.policy}, {scenario.detector.kind} detector, {scenario.tracker.association} association, "
        f"camera off its commands by {args.pose_noise_deg:g} deg and {100 * args.zoom_noise:g} % zoom (1 sigma)"
    )
    width = max(len(name) for name in POSE_SOURCES)
    print(f"  {'pose source':<{width + 2}} MOTA     MOTP [m]  pose known  tracker pose error (pan, tilt, zoom)")
    for row in closed_loop:
        print(
            f"  {row['pose_source']:<{width + 2}} {row['mota']:6.1%}   {row['motp_m']:.3f}     {row['pose_known']:6.1%}"
            f"      {row['tracker_pan_err_deg']:.3f} deg, {row['tracker_tilt_err_deg']:.3f} deg, "
            f"{row['tracker_zoom_err_pct']:.2f} %"
        )
    if args.json is not None:
        document = {**summary, "live_view_model": settings, "closed_loop": closed_loop, "views_detail": views}
        write_json(args.json, document)
        print(f"wrote {args.json}")
    return 0


def _describe_live_views(settings: dict) -> str:
    """One line on the registration experiment's live views (see ``live_view_settings``)."""
    frames = (
        f"reference views of frames {settings['reference_frames'][0]}-{settings['reference_frames'][1]}, "
        f"live views of frames {settings['first_live_frame']} on"
    )
    if settings["exact"]:
        return f"exact pinhole live views; {frames}"
    k1 = f"k1 {settings['k1_wide']:g} at zoom 1 to {settings['k1_tele']:g} at zoom {settings['tele_zoom']:g}"
    return (
        f"live views rolled up to {settings['roll_max_deg']:g} deg, principal point up to "
        f"{settings['principal_offset_max_px']:g} px off, {k1}, gain {settings['gain'][0]:g}-{settings['gain'][1]:g}, "
        f"brightness +-{settings['brightness_max']:g}, JPEG quality {settings['jpeg_quality']}; {frames}"
    )


def _unless_failed(error: float | None) -> str:
    """An error statistic, or what it means when it fell on views that were not registered."""
    return "(unregistered views)" if error is None else f"{error:.3f}"
