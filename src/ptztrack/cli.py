"""The ``ptztrack`` command: a thin layer over the Python API."""

import argparse
import json
import os
import sys
import tempfile
from functools import partial
from pathlib import Path

import numpy as np

from ptztrack import registry
from ptztrack.builders.episode import episode_world, run_episode
from ptztrack.builders.experiments import (
    POSE_SOURCES,
    STRATEGIES,
    closed_loop_cells,
    recording_cells,
    registration_views,
    run_cell,
    run_closed_loop_cell,
    synthetic_cells,
)
from ptztrack.builders.occupancy import ROOM_FRAMES, dataset_runs, room_runs
from ptztrack.builders.registration import reference_index
from ptztrack.config import (
    PoseError,
    Scenario,
    ScenarioError,
    load_dataset,
    load_scenario,
    pets_dataset,
    pets_scenario,
    scenario_from_dict,
)
from ptztrack.control.msg_scheduler import CHOOSERS
from ptztrack.evaluate.executors import EXECUTORS, print_progress, run_cells
from ptztrack.evaluate.metrics import DISPLAY, episode_metrics
from ptztrack.evaluate.msg import (
    ambiguity_figure,
    format_ambiguity_table,
    msg_cells,
    run_msg,
    run_msg_cell,
    summarise_by_ambiguity,
    trails_figure,
)
from ptztrack.evaluate.occupancy_output import write_occupancy_outputs
from ptztrack.evaluate.registration import summarise_registration
from ptztrack.evaluate.report import RUN_FILES, write_atomically, write_figure, write_outputs
from ptztrack.evaluate.tables import format_table, summarise
from ptztrack.evaluate.video import view_renderer
from ptztrack.geometry.calibration import CalibrationError
from ptztrack.geometry.registration import RegistrationIndexError
from ptztrack.scene.pets import DatasetError
from ptztrack.scene.roads import walk_roads

RUN_FIGURES = ("mota", "motp_m", "idf1", "height_px", "detections", "zoom", "switches")


def build_scenario(
    name_or_path: str,
    detector: str | None = None,
    frames: int | None = None,
    recording_paths: dict | None = None,
    association: str | None = None,
    measurement_source: str | None = None,
) -> Scenario:
    """The built-in synthetic or PETS scene or a YAML file, with command-line overrides applied.

    recording_paths : {'video' | 'calibration' | 'ground_truth': path} replacing the recording's files.
    association : 'hungarian' or 'cjpdaf', replacing ``tracker.association``.
    measurement_source : 'detector' or 'spatiogram', replacing ``tracker.measurement_source``.
    """
    overrides: dict[str, object] = {
        f"recording.{key}": str(path) for key, path in (recording_paths or {}).items() if path is not None
    }
    if association is not None:
        overrides["tracker.association"] = association
    if measurement_source is not None:
        overrides["tracker.measurement_source"] = measurement_source
    if detector is not None:
        overrides["detector.kind"] = detector
    if frames is not None:
        overrides["frames"] = frames
    if name_or_path == "synthetic":
        return scenario_from_dict({}, "synthetic", **overrides)
    if name_or_path == "pets":
        return pets_scenario(str(overrides.pop("detector.kind", "ideal")), **overrides)
    return load_scenario(name_or_path, **overrides)


def recording_paths(args: argparse.Namespace) -> dict:
    return {"video": args.video, "calibration": args.calibration, "ground_truth": args.gt}


def format_metrics(metrics: dict) -> str:
    width = max(len(DISPLAY[key][0]) for key in RUN_FIGURES)
    return "\n".join(f"{DISPLAY[key][0]:<{width}}  {DISPLAY[key][1].format(metrics[key])}" for key in RUN_FIGURES)


def run_command(args: argparse.Namespace) -> int:
    scenario = build_scenario(
        args.scenario, args.detector, args.frames, recording_paths(args), args.association, args.measurement_source
    )
    world = episode_world(scenario, args.seed)
    episode = run_episode(scenario, args.policy, args.seed, world)
    metrics = episode_metrics(episode)
    print(
        f"scenario {args.scenario}, policy {args.policy}, detector {scenario.detector.kind}, "
        f"seed {args.seed}, {len(episode.actions)} steps, {episode.truth.positions_m.shape[1]} people"
    )
    print(format_metrics(metrics))
    if args.out is not None:
        title = f"{args.policy}, {scenario.detector.kind} detector, seed {args.seed}: MOTA {metrics['mota']:.1%}"
        write_outputs(args.out, episode, metrics, title, view_renderer(world))
        print(f"wrote {', '.join(RUN_FILES)} into {args.out}")
    return 0


def msg_experiment_command(args: argparse.Namespace) -> int:
    cells = msg_cells(args.runs)
    print(f"{len(cells)} simulations x {len(CHOOSERS)} schedulers, {args.executor} executor", file=sys.stderr)
    rows = [row for rows in run_cells(cells, run_msg_cell, args.executor, args.workers, print_progress) for row in rows]
    print("Face capture on the MSG: M by N_j/s bin, mean +- standard deviation (runs)")
    print(format_ambiguity_table(summarise_by_ambiguity(rows)))
    written = []
    if args.json is not None:
        write_atomically(args.json, (json.dumps(rows, indent=2) + "\n").encode())
        written.append(args.json)
    if args.plot is not None:
        write_figure(args.plot, ambiguity_figure(rows))
        written.append(args.plot)
    if args.trails is not None:
        cell = cells[0]
        scene = walk_roads(cell.scene, np.random.default_rng(cell.seed))
        run = run_msg(scene, "msg", cell.tracklets, cell.zoom_out_score)
        title = f"simulation {cell.seed}: {cell.scene.people} walkers, N_j/s {run.nj_s}, msg scheduler, M {run.m:.2f}"
        write_figure(args.trails, trails_figure(scene, run, title))
        written.append(args.trails)
    if written:
        print(f"wrote {', '.join(str(path) for path in written)}")
    return 0


def registration_experiment_command(args: argparse.Namespace) -> int:
    scenario = build_scenario(
        args.scenario,
        args.detector,
        args.frames,
        recording_paths(args),
        args.association,
        args.measurement_source,
    )
    if scenario.recording is None or scenario.recording.video is None:
        raise ScenarioError(f"{args.scenario}: the registration experiment needs a recording with a video")
    with tempfile.TemporaryDirectory() as scratch:
        index_path = args.index or Path(scratch) / "index.npz"
        feedback = scenario.pose_feedback.model_copy(update={"index": str(index_path)})
        scenario = scenario.model_copy(update={"pose_feedback": feedback})
        built = not Path(index_path).exists()
        print(f"{'building' if built else 'reading'} the reference index {index_path}", file=sys.stderr)
        index = reference_index(scenario)
        print(f"{len(index.poses)} reference views; registering {args.views} live views", file=sys.stderr)
        views = registration_views(scenario, index, args.views, args.seed, partial(print_progress, noun="views"))
        summary = summarise_registration(views)
        pose_error = PoseError(pan_tilt_sigma_deg=args.pose_noise_deg, zoom_sigma=args.zoom_noise)
        cells = closed_loop_cells(scenario, pose_error, args.policy, args.pose_sources)
        print(f"{len(cells)} closed-loop runs, {args.executor} executor", file=sys.stderr)
        closed_loop = run_cells(cells, run_closed_loop_cell, args.executor, args.workers, print_progress)
    size = scenario.pose_feedback.image_size_px
    print(
        f"Registration of {summary['views']} live views at random reachable poses, {size[0]} x {size[1]} px, "
        f"against {len(index.poses)} reference views: {summary['registered']} registered"
    )
    for name, key, unit in (("focal length error", "focal_err", "pct"), ("ground error", "ground_err", "m")):
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
        document = {**summary, "closed_loop": closed_loop, "views_detail": views}
        write_atomically(args.json, (json.dumps(document, indent=2) + "\n").encode())
        print(f"wrote {args.json}")
    return 0


def _unless_failed(error: float | None) -> str:
    """An error statistic, or what it means when it fell on views that were not registered."""
    return "(unregistered views)" if error is None else f"{error:.3f}"


def synthetic_experiment_command(args: argparse.Namespace) -> int:
    scenario = build_scenario(
        args.scenario, args.detector, args.frames, association=args.association, measurement_source=None
    )
    cells = synthetic_cells(scenario, args.sequences, args.strategies)
    title = (
        f"{args.scenario} scene, {scenario.detector.kind} detector, beta {scenario.control.beta:g}, "
        f"{args.sequences} sequences of {scenario.frames} frames (means over sequences)"
    )
    return _run_table(args, cells, title)


def pets_experiment_command(args: argparse.Namespace) -> int:
    scenario = build_scenario(
        "pets", args.detector, args.frames, recording_paths(args), args.association, args.measurement_source
    )
    cells = recording_cells(scenario, args.beta or [9.0, 1.0], args.strategies)
    title = f"PETS 2009 S2.L1 View_001, {scenario.detector.kind} detector, every 2nd frame"
    return _run_table(args, cells, title)


def _run_table(args: argparse.Namespace, cells: list, title: str) -> int:
    print(f"{len(cells)} episodes, {args.executor} executor", file=sys.stderr)
    summary = summarise(run_cells(cells, run_cell, args.executor, args.workers, print_progress))
    print(format_table(summary, title))
    if args.json is not None:
        write_atomically(args.json, (json.dumps(summary, indent=2) + "\n").encode())
        print(f"wrote {args.json}")
    return 0


OCCUPANCY_COLUMNS = (
    ("method", "{}"),
    ("people", "{}"),
    ("moda", "{:.1%}"),
    ("modp", "{:.1%}"),
    ("precision", "{:.1%}"),
    ("recall", "{:.1%}"),
    ("error_m", "{:.3f}"),
    ("mota", "{:.1%}"),
    ("motp_m", "{:.3f}"),
    ("idf1", "{:.1%}"),
)


def occupancy_experiment_command(args: argparse.Namespace) -> int:
    progress = partial(print_progress, noun="frames")
    if args.dataset == "synthetic-room":
        runs = room_runs(args.frames or ROOM_FRAMES, args.seed, progress)
    else:
        dataset = pets_dataset() if args.dataset == "pets" else load_dataset(args.dataset)
        runs = dataset_runs(dataset, args.frames, progress)
    rows = [row for run in runs for row in run.rows]
    columns = [(key, form) for key, form in OCCUPANCY_COLUMNS if any(key in row for row in rows)]
    print(f"Occupancy-map detection on {args.dataset}: MODA, MODP, precision, recall within 0.5 m; tracker fed by LPOM")
    print("  ".join(f"{key:>10}" for key, _ in columns))
    for row in rows:
        print("  ".join(f"{form.format(row[key]) if key in row else '':>10}" for key, form in columns))
    for row in rows:
        fitted = {key: value for key, value in row.items() if key.startswith("fitted_")}
        print(f"{row['dataset']} {row['method']}: {fitted} (each half of the frames scored with the other's fit)")
    written = []
    if args.out is not None:
        for run in runs:
            directory = args.out / str(run.rows[0]["dataset"])
            write_occupancy_outputs(directory, run, args.images_every)
            written.append(directory)
    if args.json is not None:
        write_atomically(args.json, (json.dumps(rows, indent=2) + "\n").encode())
        written.append(args.json)
    if written:
        print(f"wrote {', '.join(str(path) for path in written)}")
    return 0


class OneLineParser(argparse.ArgumentParser):
    """Command-line mistakes end in one line on stderr and exit status 2, like every other bad input."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def parser() -> argparse.ArgumentParser:
    root = OneLineParser(prog="ptztrack", description="Multi-person tracking with a PTZ camera.")
    commands = root.add_subparsers(dest="command", required=True)
    policies, detectors = registry.names("policies"), registry.names("detectors")
    run = commands.add_parser("run", help="run one closed-loop episode and print its metrics")
    run.add_argument(
        "--scenario", default="synthetic", help="'synthetic' or 'pets' (built in), or a scenario YAML file"
    )
    run.add_argument("--policy", choices=policies, default="smpl")
    run.add_argument("--detector", choices=detectors, help="overrides the scenario's detector")
    run.add_argument("--seed", type=_non_negative_int, default=0)
    run.add_argument("--frames", type=_positive_int, help="overrides the scenario's number of frames")
    _add_tracker_arguments(run)
    run.add_argument("--out", type=Path, help=f"directory for {', '.join(RUN_FILES)}")
    _add_recording_arguments(run)
    run.set_defaults(handler=run_command)

    experiment = commands.add_parser("experiment", help="run one of the papers' experiments and print its table")
    experiments = experiment.add_subparsers(
        dest="name", required=True, metavar="{synthetic,pets,msg,registration,occupancy}"
    )

    synthetic = experiments.add_parser("synthetic", help="the PTZ paper's Tables 1-2 on the synthetic scene")
    synthetic.add_argument("--scenario", default="synthetic", help="'synthetic' (built in) or a scenario YAML file")
    synthetic.add_argument("--detector", choices=detectors, default="realistic")
    synthetic.add_argument("--sequences", type=_positive_int, default=12)
    synthetic.add_argument("--frames", type=_positive_int, help="overrides the scenario's number of frames")
    synthetic.add_argument("--strategies", nargs="+", choices=_strategies(policies), default=list(STRATEGIES))
    _add_association_argument(synthetic)
    _add_executor_arguments(synthetic, "one row per strategy")
    synthetic.set_defaults(handler=synthetic_experiment_command)

    pets = experiments.add_parser("pets", help="the PTZ paper's Tables 3-4 on PETS 2009 S2.L1")
    pets.add_argument("--detector", default="ideal", help="ideal (the annotations) or hog")
    pets.add_argument(
        "--beta",
        type=_non_negative_float,
        action="append",
        help="a weight of the patrolling term (repeatable; default 9 and 1)",
    )
    pets.add_argument("--strategies", nargs="+", choices=_strategies(policies), default=list(STRATEGIES))
    pets.add_argument("--frames", type=_positive_int, help="overrides the scenario's number of steps")
    _add_tracker_arguments(pets)
    _add_executor_arguments(pets, "one row per strategy and beta")
    _add_recording_arguments(pets)
    pets.set_defaults(handler=pets_experiment_command)

    msg = experiments.add_parser("msg", help="the face-capture paper's Figure 7")
    msg.add_argument("--runs", type=_positive_int, default=414, help="simulations")
    msg.add_argument("--plot", type=Path, help="M against N_j/s per scheduler (PNG)")
    msg.add_argument("--trails", type=Path, help="one simulation's trails in (x, y, t) (PNG)")
    _add_executor_arguments(msg, "one row per run and scheduler")
    msg.set_defaults(handler=msg_experiment_command)

    registration = experiments.add_parser(
        "registration", help="the scale-invariant paper: registered PTZ views, and the closed loop on their poses"
    )
    registration.add_argument("--scenario", default="pets", help="'pets' (built in) or a recording scenario YAML file")
    registration.add_argument("--views", type=_positive_int, default=100, help="random live views to register")
    registration.add_argument(
        "--seed", type=_non_negative_int, default=0, help="draws the live views' poses and frames"
    )
    registration.add_argument(
        "--index", type=Path, help="reference index file: read if it exists, else built and written (default: built)"
    )
    registration.add_argument("--detector", choices=detectors, default="hog", help="closed-loop detector")
    registration.add_argument("--policy", choices=policies, default="smpl", help="closed-loop policy")
    registration.add_argument(
        "--pose-sources", nargs="+", choices=POSE_SOURCES, default=list(POSE_SOURCES), help="closed-loop pose sources"
    )
    registration.add_argument(
        "--pose-noise-deg",
        type=_non_negative_float,
        default=2.0,
        help="closed loop: pan and tilt landing error, 1 sigma",
    )
    registration.add_argument(
        "--zoom-noise", type=_non_negative_float, default=0.02, help="closed loop: relative zoom landing error, 1 sigma"
    )
    registration.add_argument(
        "--frames", type=_positive_int, help="closed loop: overrides the scenario's number of steps"
    )
    _add_tracker_arguments(registration)
    _add_executor_arguments(registration, "the registration errors and the closed-loop rows")
    _add_recording_arguments(registration)
    registration.set_defaults(handler=registration_experiment_command)
    _add_occupancy_parser(experiments)
    return root


def _add_occupancy_parser(experiments) -> None:
    occupancy = experiments.add_parser(
        "occupancy", help="the LPOM paper: people on the ground from several calibrated views, against clustering"
    )
    occupancy.add_argument("dataset", help="'synthetic-room' or 'pets' (built in), or a multi-view dataset YAML file")
    occupancy.add_argument(
        "--frames", type=_positive_int, help=f"frames to use (synthetic-room: {ROOM_FRAMES} per sequence; else all)"
    )
    occupancy.add_argument(
        "--seed", type=_non_negative_int, default=0, help="synthetic-room: draws people and textures"
    )
    occupancy.add_argument("--out", type=Path, help="directory for maps, video, detections and tracks per recording")
    occupancy.add_argument("--images-every", type=_positive_int, default=10, help="a map picture every N frames")
    occupancy.add_argument("--json", type=Path, help="write one row per method (and people count) here")
    occupancy.set_defaults(handler=occupancy_experiment_command)


def _strategies(policies: list[str]) -> list[str]:
    """The tables' strategy names ('rnd' for the 'random' policy) and every other registered policy."""
    return list(dict.fromkeys([*STRATEGIES, *(name for name in policies if name != "random")]))


def _add_executor_arguments(command: argparse.ArgumentParser, rows: str) -> None:
    command.add_argument("--executor", choices=EXECUTORS, default="local")
    command.add_argument("--workers", type=_positive_int, help="processes of the local executor (default: all cores)")
    command.add_argument("--json", type=Path, help=f"write {rows} here")


def _add_tracker_arguments(command: argparse.ArgumentParser) -> None:
    _add_association_argument(command)
    command.add_argument(
        "--measurement-source",
        choices=("detector", "spatiogram"),
        help="overrides the scenario's tracker.measurement_source (spatiogram: templates between detector steps)",
    )


def _add_association_argument(command: argparse.ArgumentParser) -> None:
    command.add_argument(
        "--association", choices=("hungarian", "cjpdaf"), help="overrides the scenario's tracker.association"
    )


def _add_recording_arguments(command: argparse.ArgumentParser) -> None:
    """Files of a recording that replace the scenario's (the built-in PETS ones with ``pets``)."""
    recording = command.add_argument_group("recording files (replace the scenario's)")
    recording.add_argument("--video", type=Path, help="the recorded video")
    recording.add_argument("--calibration", type=Path, help="pinhole JSON or Tsai XML calibration of the recording")
    recording.add_argument("--gt", type=Path, help="MOTChallenge ground truth with world positions in metres")


def _non_negative_float(text: str) -> float:
    value = float(text)
    if not value >= 0:
        raise argparse.ArgumentTypeError(f"must be at least 0 (got {text})")
    return value


def _non_negative_int(text: str) -> int:
    value = int(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be at least 0 (got {value})")
    return value


def _positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1 (got {value})")
    return value


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
    try:
        return args.handler(args)
    except (ScenarioError, CalibrationError, DatasetError, RegistrationIndexError, RuntimeError) as error:
        print(f"ptztrack: error: {error}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # The reader (say, `head`) has gone: stop quietly, and keep Python from
        # complaining again when it flushes stdout at exit.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except OSError as error:
        where = f"{error.filename}: " if error.filename else ""
        print(f"ptztrack: error: {where}{error.strerror or error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
