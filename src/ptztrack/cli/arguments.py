"""The ``ptztrack`` command line's parser: every command, its arguments and their checks.

It imports argparse, the registry's names and :mod:`ptztrack.names` only, so that ``ptztrack --help``
stays quick; each command names its body as ``"module:function"``, which :func:`ptztrack.cli.main`
imports when the command runs.
"""

import argparse
import math
from pathlib import Path

from ptztrack import registry
from ptztrack.names import (
    EXECUTORS,
    FOLLOW_TRACKERS,
    MAX_FRAMES,
    OCCUPANCY_MAP_METHODS,
    OTB_TRACKS,
    PASSWORD_VARIABLE,
    PLAZA_FRAMES,
    POSE_SOURCES,
    PROTOCOLS,
    ROOM_FRAMES,
    RUN_FILES,
    STRATEGIES,
    VIEW_STATES_FILE,
)

RUN_FOLDER_FILES = (*RUN_FILES, VIEW_STATES_FILE)


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
    _add_detector_model_arguments(run, prior_shift=True)
    run.add_argument("--seed", type=_non_negative_int, default=0)
    run.add_argument("--frames", type=_positive_int, help="overrides the scenario's number of frames")
    _add_tracker_arguments(run)
    run.add_argument(
        "--out", type=Path, help=f"directory for {', '.join(RUN_FOLDER_FILES)}; written whole or not at all"
    )
    run.add_argument("--overwrite", action="store_true", help="replace a non-empty --out folder")
    _add_view_argument(run)
    _add_quiet_argument(run)
    _add_recording_arguments(run)
    run.set_defaults(handler="ptztrack.cli.run:run_command")

    view = commands.add_parser("view", help="replay a finished run's --out folder in the web view")
    view.add_argument("folder", type=Path, help="a folder written by ptztrack run, follow or live with --out")
    view.add_argument("--port", type=_port, default=0, help="serve on http://127.0.0.1:PORT/ (default: any free one)")
    view.add_argument("--steps-per-s", type=_positive_float, default=10.0, help="the replay's pace")
    view.set_defaults(handler="ptztrack.cli.run:view_command")

    experiment = commands.add_parser("experiment", help="run one of the papers' experiments and print its table")
    experiments = experiment.add_subparsers(
        dest="name", required=True, metavar="{synthetic,pets,msg,registration,follow,occupancy,network}"
    )

    synthetic = experiments.add_parser("synthetic", help="the PTZ paper's Tables 1-2 on the synthetic scene")
    synthetic.add_argument("--scenario", default="synthetic", help="'synthetic' (built in) or a scenario YAML file")
    synthetic.add_argument("--detector", choices=detectors, default="realistic")
    _add_detector_model_arguments(synthetic, prior_shift=True)
    synthetic.add_argument("--sequences", type=_positive_int, default=12)
    synthetic.add_argument("--frames", type=_positive_int, help="overrides the scenario's number of frames")
    synthetic.add_argument("--strategies", nargs="+", choices=_strategies(policies), default=list(STRATEGIES))
    _add_association_argument(synthetic)
    _add_executor_arguments(synthetic, "one row per strategy")
    synthetic.set_defaults(handler="ptztrack.cli.ptz_paper:synthetic_experiment_command")

    pets = experiments.add_parser(
        "pets", help="the PTZ paper's Tables 3-4 on a recording (default PETS 2009 S2.L1; --dataset for another)"
    )
    pets.add_argument(
        "--detector",
        default="ideal",
        help="ideal (the annotations), hog, detections (the dataset view's own boxes) or a registered one",
    )
    _add_detector_model_arguments(pets)
    pets.add_argument(
        "--beta",
        type=_non_negative_float,
        action="append",
        help="a weight of the patrolling term (repeatable; default 9 and 1)",
    )
    pets.add_argument("--strategies", nargs="+", choices=_strategies(policies), default=list(STRATEGIES))
    pets.add_argument("--frames", type=_positive_int, help="overrides the scenario's number of steps")
    pets.add_argument(
        "--protocol",
        choices=PROTOCOLS,
        default="a-priori",
        help="a-priori: every parameter fixed before looking at the recording; two-fold: the detector's model "
        "fitted on one half of the frames, the table scored on the other, both ways",
    )
    pets.add_argument("--seeds", type=_positive_int, default=5, help="runs of a strategy whose run depends on its seed")
    _add_tracker_arguments(pets)
    _add_executor_arguments(pets, "one row per strategy and beta")
    _add_recording_arguments(pets)
    pets.set_defaults(handler="ptztrack.cli.ptz_paper:pets_experiment_command")

    msg = experiments.add_parser("msg", help="the face-capture paper's Figure 7")
    msg.add_argument("--runs", type=_positive_int, default=414, help="simulations")
    msg.add_argument("--plot", type=Path, help="M against N_j/s per scheduler (PNG)")
    msg.add_argument("--trails", type=Path, help="one simulation's trails in (x, y, t) (PNG)")
    _add_executor_arguments(msg, "one row per run and scheduler")
    msg.set_defaults(handler="ptztrack.cli.msg:msg_experiment_command")

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
    registration.add_argument(
        "--exact-views",
        action="store_true",
        help="exact pinhole views instead of the scenario's camera.live_view (default: the realistic model)",
    )
    registration.add_argument("--detector", choices=detectors, default="hog", help="closed-loop detector")
    _add_detector_model_arguments(registration)
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
    registration.set_defaults(handler="ptztrack.cli.registration:registration_experiment_command")
    _add_follow_commands(commands, experiments)
    _add_occupancy_parser(experiments)
    _add_network_parser(experiments, detectors)
    _add_camera_commands(commands, policies)
    _add_render_parser(commands)
    return root


def _add_render_parser(commands) -> None:
    """``ptztrack render``: a scenario's people and cameras rendered into a multi-view dataset folder."""
    from ptztrack.names import PEOPLE_LOOKS

    render = commands.add_parser(
        "render", help="render a scenario's people and cameras into a dataset: videos, calibration, ground truth"
    )
    render.add_argument(
        "--scenario",
        required=True,
        help="a scenario YAML file without a recording (its cameras, or its one camera, aimed at the area's "
        "centre; its area, frames, frame rate and people), or 'synthetic' (built in)",
    )
    render.add_argument(
        "--out",
        type=Path,
        required=True,
        help="the dataset folder: dataset.yaml, calibration.json, a video and a gt_*.txt per view; written whole or "
        "not at all",
    )
    render.add_argument(
        "--seed", type=_non_negative_int, default=0, help="draws the people's walks, textures and clothes (default 0)"
    )
    render.add_argument("--overwrite", action="store_true", help="replace a non-empty --out folder")
    render.add_argument(
        "--people-look",
        choices=PEOPLE_LOOKS,
        default=PEOPLE_LOOKS[0],
        help="the people drawn as textured cone bodies, or as pedestrians cut out of PETS 2009 View_001 "
        f"(default {PEOPLE_LOOKS[0]}: to HOG, the closer to real people)",
    )
    _add_quiet_argument(render)
    render.set_defaults(handler="ptztrack.cli.render:render_command")


def _add_camera_commands(commands, policies: list[str]) -> None:
    """``ptztrack live`` and ``ptztrack serve-camera``: real ONVIF cameras, and a virtual one to test with."""
    live = commands.add_parser("live", help="drive an ONVIF PTZ camera in real time: capture, detect, track, decide")
    live.add_argument(
        "--camera",
        required=True,
        action="append",
        help="onvif://[user[:password]@]host[:port]; repeated: a network of cameras with one ground belief",
    )
    live.add_argument("--credentials", type=Path, help="a YAML file with username and password")
    live.add_argument(
        "--calibration",
        required=True,
        action="append",
        help="the camera's calibration YAML, or 'virtual' for ptztrack serve-camera; one for every camera, "
        "or one per --camera in their order",
    )
    live.add_argument(
        "--coordination",
        choices=("joint", "independent"),
        default="joint",
        help="a network's decisions: joint (greedy, each camera on the views before it) or each camera alone",
    )
    live.add_argument("--policy", choices=policies, default="smpl")
    live.add_argument("--scenario", default="pets", help="'pets' (built in) or a scenario YAML file")
    _add_recording_arguments(live, files=False)
    live.add_argument("--detector", default="hog", help="the scenario's detector (default hog)")
    _add_detector_model_arguments(live)
    live.add_argument(
        "--steps", type=_positive_int, help="use at most this many pictures (default: the scenario's frames)"
    )
    live.add_argument(
        "--time-scale", type=_positive_float, default=1.0, help="the scenario's seconds per second (serve-camera's)"
    )
    live.add_argument("--transport", choices=("tcp", "udp"), default="tcp", help="RTSP's transport (default tcp)")
    live.add_argument("--timeout-s", type=_positive_float, default=5.0, help="the longest wait for any camera call")
    live.add_argument(
        "--truth", type=Path, help="score against a virtual camera's truth log (serve-camera --truth-log)"
    )
    live.add_argument("--seed", type=_non_negative_int, default=0)
    live.add_argument(
        "--out", type=Path, help=f"directory for {', '.join(RUN_FOLDER_FILES)}; written whole, Ctrl-C too"
    )
    live.add_argument("--overwrite", action="store_true", help="replace a non-empty --out folder")
    _add_view_argument(live)
    live.set_defaults(handler="ptztrack.cli.camera:live_command")

    camera = commands.add_parser("camera", help="tools for a real camera").add_subparsers(dest="tool", required=True)
    calibrate = camera.add_parser("calibrate", help="time the camera's moves and write them into its calibration")
    calibrate.add_argument("--camera", required=True, help="onvif://[user[:password]@]host[:port]")
    calibrate.add_argument("--credentials", type=Path, help="a YAML file with username and password")
    calibrate.add_argument("--calibration", type=Path, required=True, help="the camera's calibration YAML (updated)")
    calibrate.add_argument(
        "--timeout-s", type=_positive_float, default=5.0, help="the longest wait for any camera call"
    )
    calibrate.set_defaults(handler="ptztrack.cli.camera:calibrate_camera_command")

    serve = commands.add_parser(
        "serve-camera", help="serve a recording's virtual PTZ camera over ONVIF on 127.0.0.1 (default PETS 2009 S2.L1)"
    )
    serve.add_argument("--port", type=_port, default=8080, help="the first camera's port (0: any free port each)")
    serve.add_argument(
        "--cameras", type=_positive_int, default=1, help="serve this many cameras, on --port and the ports after it"
    )
    serve.add_argument("--scenario", default="pets", help="'pets' (built in) or a recording scenario YAML file")
    _add_recording_arguments(serve, files=False)
    serve.add_argument("--time-scale", type=_positive_float, default=1.0, help="the recording's speed")
    serve.add_argument("--user", help=f"require this user (password: --credentials or ${PASSWORD_VARIABLE})")
    serve.add_argument("--credentials", type=Path, help="a YAML file with username and password to require")
    serve.add_argument(
        "--truth-log", type=Path, help="append every picture's time, step and pose here (CSV; the first camera's)"
    )
    serve.set_defaults(handler="ptztrack.cli.camera:serve_camera_command")


def _add_follow_commands(commands, experiments) -> None:
    """``ptztrack follow`` and ``ptztrack experiment follow``: the robot-cameraman paper's follow camera."""
    follow = commands.add_parser("follow", help="follow one annotated PETS person with the virtual PTZ camera")
    follow.add_argument("--target", type=_non_negative_int, required=True, help="the annotated person's id")
    follow.add_argument("--tracker", choices=FOLLOW_TRACKERS, default="particle")
    follow.add_argument("--seed", type=_non_negative_int, default=0)
    follow.add_argument("--frames", type=_positive_int, help="at most this many steps")
    follow.add_argument(
        "--target-point-px",
        type=_non_negative_float,
        nargs=2,
        metavar=("X", "Y"),
        help="(x*, y*); default: the image centre",
    )
    follow.add_argument(
        "--out",
        type=Path,
        help=f"directory for {', '.join(RUN_FOLDER_FILES)} (default follow-TARGET); written whole or not at all",
    )
    follow.add_argument("--overwrite", action="store_true", help="replace a non-empty --out folder")
    _add_view_argument(follow)
    _add_quiet_argument(follow)
    _add_follow_scenario_arguments(follow)
    follow.set_defaults(handler="ptztrack.cli.follow:follow_command")

    experiment = experiments.add_parser(
        "follow", help="the robot-cameraman paper: every PETS person followed, and the one-pass benchmark"
    )
    experiment.add_argument("--trackers", nargs="+", choices=FOLLOW_TRACKERS, default=list(FOLLOW_TRACKERS))
    experiment.add_argument("--targets", type=_non_negative_int, nargs="+", help="people to follow (default: all)")
    experiment.add_argument(
        "--otb-tracks", type=_non_negative_int, default=OTB_TRACKS, help="longest tracks of the one-pass benchmark"
    )
    experiment.add_argument("--seed", type=_non_negative_int, default=0)
    _add_follow_scenario_arguments(experiment)
    _add_executor_arguments(experiment, '{"closed_loop": [...], "otb": [...]} and the rows per person')
    experiment.set_defaults(handler="ptztrack.cli.follow:follow_experiment_command")


def _add_follow_scenario_arguments(command: argparse.ArgumentParser) -> None:
    command.add_argument(
        "--scenario", default="pets", help="'pets' (built in) or a recording scenario YAML file with a follow section"
    )
    command.add_argument(
        "--achromatic-bins",
        action="store_true",
        help="the particle filter bins greys by value (Perez et al.) besides the paper's hue-saturation bins",
    )
    _add_recording_arguments(command)


def _add_occupancy_parser(experiments) -> None:
    occupancy = experiments.add_parser(
        "occupancy", help="the LPOM paper: people on the ground from several calibrated views, against clustering"
    )
    occupancy.add_argument(
        "dataset",
        help="'synthetic-room' (near, steep cameras), 'synthetic-plaza' (PETS S2.L1's far, shallow cameras, "
        "rendered) or 'pets' (built in), or a multi-view dataset YAML file",
    )
    occupancy.add_argument(
        "--frames",
        type=_occupancy_frames,
        help=f"frames to use (synthetic-room: {ROOM_FRAMES}, synthetic-plaza: {PLAZA_FRAMES} per sequence; else all)",
    )
    occupancy.add_argument(
        "--seed", type=_non_negative_int, default=0, help="synthetic-room, synthetic-plaza: draws people and textures"
    )
    occupancy.add_argument(
        "--lead-in",
        type=_occupancy_lead_in,
        metavar="FRAMES",
        help="synthetic-plaza: frames rendered before the first, which only the background models learn "
        "(default: half the background model's history, after which it learns at its steady rate)",
    )
    occupancy.add_argument(
        "--methods",
        nargs="*",
        choices=OCCUPANCY_MAP_METHODS,
        default=list(OCCUPANCY_MAP_METHODS),
        help="the methods to run beside LPOM and the clustering baseline (default: both; none: neither; "
        "lpom-foreground needs a view with video, pom every view's image size)",
    )
    occupancy.add_argument(
        "--out", type=Path, help="directory for maps, video, detections and tracks per recording; written whole"
    )
    occupancy.add_argument("--overwrite", action="store_true", help="replace a non-empty --out folder")
    occupancy.add_argument("--images-every", type=_positive_int, default=10, help="a map picture every N frames")
    occupancy.add_argument("--json", type=Path, help="write one row per method (and people count) here")
    _add_quiet_argument(occupancy)
    occupancy.set_defaults(handler="ptztrack.cli.occupancy:occupancy_experiment_command")


def _add_network_parser(experiments, detectors: list[str]) -> None:
    network = experiments.add_parser(
        "network",
        help="a camera network: PTZ cameras deciding jointly, each alone or fixed, with a wide fixed one; or the "
        "PETS PTZ camera with six views' published detections",
    )
    network.add_argument(
        "setting",
        choices=("synthetic", "pets"),
        help="synthetic: 1 to --max-ptz cameras around the area; pets: the virtual PTZ camera over a dataset's "
        "view (--dataset, --view; default PETS 2009 S2.L1's View_001) and its other views' detections as fixed cameras",
    )
    network.add_argument(
        "--detector",
        choices=detectors,
        help="the cameras' detector (synthetic: default realistic; pets, the PTZ camera's: hog or ideal, default hog)",
    )
    _add_detector_model_arguments(network)
    network.add_argument("--sequences", type=_positive_int, help="synthetic: sequences (default 12)")
    network.add_argument(
        "--first-sequence",
        type=_non_negative_int,
        help="synthetic: the first sequence's seed (default 0, the table's; from 1000: development sequences)",
    )
    network.add_argument("--frames", type=_positive_int, help="overrides the scenario's number of frames")
    network.add_argument("--max-ptz", type=_positive_int, help="synthetic: the most PTZ cameras (default 4)")
    network.add_argument("--seeds", type=_positive_int, help="pets: seeds of the runs with the PTZ camera (default 5)")
    network.add_argument(
        "--beta", type=_non_negative_float, help="pets: the PTZ camera's weight of the patrolling term (default 9)"
    )
    network.add_argument(
        "--method", choices=("intg", "smpl"), default="intg", help="the PTZ cameras' expected information"
    )
    _add_recording_arguments(network, files=False)
    _add_executor_arguments(network, "one row per configuration")
    network.set_defaults(handler="ptztrack.cli.network:network_experiment_command")


def _strategies(policies: list[str]) -> list[str]:
    """The tables' strategy names ('rnd' for the 'random' policy) and every other registered policy."""
    return list(dict.fromkeys([*STRATEGIES, *(name for name in policies if name != "random")]))


def _add_executor_arguments(command: argparse.ArgumentParser, rows: str) -> None:
    command.add_argument("--executor", choices=EXECUTORS, default="local")
    command.add_argument("--workers", type=_positive_int, help="processes of the local executor (default: all cores)")
    command.add_argument("--json", type=Path, help=f"write {rows} here")
    _add_quiet_argument(command)


def _add_quiet_argument(command: argparse.ArgumentParser) -> None:
    command.add_argument(
        "--quiet", action="store_true", help="no progress bar (there is none either where stderr is not a terminal)"
    )


def _add_view_argument(command: argparse.ArgumentParser) -> None:
    command.add_argument(
        "--view",
        type=_port,
        nargs="?",
        const=0,
        metavar="PORT",
        help="serve a live view of the run on http://127.0.0.1:PORT/ (no PORT or 0: any free one)",
    )


def _add_detector_model_arguments(command: argparse.ArgumentParser, prior_shift: bool = False) -> None:
    """``--detector-model``, after ``--prior-shift-px`` with ``prior_shift``."""
    if prior_shift:
        command.add_argument(
            "--prior-shift-px",
            type=float,
            help="shifts the prior recall curve's r0 by this many pixels from the detector's own "
            "(a test of the learning)",
        )
    command.add_argument(
        "--detector-model",
        help="what the policies and the tracker know of the detector: online (learned as the camera runs; the "
        "default), a-priori (the prior curve, kept), true (a simulation's own curve) or an earlier run's "
        "detector_model.json as the prior",
    )


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


def _add_recording_arguments(command: argparse.ArgumentParser, files: bool = True) -> None:
    """The recording: a dataset file's view (the built-in PETS 2009 S2.L1's View_001 by default), and with
    ``files`` the single files that replace the scenario's."""
    recording = command.add_argument_group("recording (default: the built-in PETS 2009 S2.L1, View_001)")
    recording.add_argument(
        "--dataset",
        help="a dataset YAML file (docs: dataset files; 'pets': the built-in one) whose view the camera runs on",
    )
    recording.add_argument(
        "--dataset-view", metavar="NAME", help="the dataset's view (default: its first view with a video)"
    )
    if not files:
        return
    recording.add_argument("--video", type=Path, help="the recorded video (replaces the scenario's)")
    recording.add_argument("--calibration", type=Path, help="pinhole JSON or Tsai XML calibration of the recording")
    recording.add_argument("--gt", type=Path, help="MOTChallenge ground truth with world positions in metres")


# The types of the options: an error names what was expected and what was typed (argparse would say
# "invalid _non_negative_int value" of a ValueError), after argparse's "argument --option: ".
def _non_negative_float(text: str) -> float:
    return _finite_number(text, 0.0, above=False)


def _occupancy_frames(text: str) -> int:
    value = _positive_int(text)
    if value > MAX_FRAMES:
        raise argparse.ArgumentTypeError(
            f"must be at most {MAX_FRAMES} (memory: every frame's map and modes are kept; got {value})"
        )
    return value


def _occupancy_lead_in(text: str) -> int:
    value = _non_negative_int(text)
    if value > MAX_FRAMES:
        raise argparse.ArgumentTypeError(f"must be at most {MAX_FRAMES} (frames rendered and learned; got {value})")
    return value


def _positive_float(text: str) -> float:
    return _finite_number(text, 0.0, above=True)


def _non_negative_int(text: str) -> int:
    return _whole_number(text, 0)


def _positive_int(text: str) -> int:
    return _whole_number(text, 1)


def _port(text: str) -> int:
    value = _integer(text)
    if value is None or not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"expected a port from 0 to 65535, got {text!r}")
    return value


def _finite_number(text: str, lowest: float, above: bool) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and (value > lowest if above else value >= lowest)):
        raise argparse.ArgumentTypeError(f"expected a finite number {'>' if above else '>='} {lowest:g}, got {text!r}")
    return value


def _whole_number(text: str, lowest: int) -> int:
    value = _integer(text)
    if value is None or value < lowest:
        raise argparse.ArgumentTypeError(f"expected a whole number >= {lowest}, got {text!r}")
    return value


def _integer(text: str) -> int | None:
    try:
        return int(text)
    except ValueError:
        return None
