"""The ``ptztrack`` command line's parser: every command, its arguments and their checks.

It and its sibling modules below import argparse, the registry's names and :mod:`ptztrack.names` only,
so that ``ptztrack --help`` stays quick; each command names its body as ``"module:function"``, which
:func:`ptztrack.cli.main` imports when the command runs. The PTZ papers' commands are here; the cameras' are in
:mod:`ptztrack.cli.camera_arguments`, the follow camera's in :mod:`ptztrack.cli.follow_arguments`, those of
several cameras at once in :mod:`ptztrack.cli.multicamera_arguments`, ``score``'s in
:mod:`ptztrack.cli.score_arguments`, and the options they share and
every option's type in :mod:`ptztrack.cli.options`.
"""

import argparse
from pathlib import Path

from ptztrack import registry
from ptztrack.cli.camera_arguments import add_camera_commands
from ptztrack.cli.follow_arguments import add_follow_commands
from ptztrack.cli.multicamera_arguments import add_network_parser, add_occupancy_parser, add_render_parser
from ptztrack.cli.options import (
    POLICY_HELP,
    RUN_FOLDER_FILES,
    add_association_argument,
    add_detector_model_arguments,
    add_executor_arguments,
    add_quiet_argument,
    add_recording_arguments,
    add_tracker_arguments,
    add_view_argument,
    non_negative_float,
    non_negative_int,
    policy_name,
    port_number,
    positive_float,
    positive_int,
    protocol_field,
)
from ptztrack.cli.score_arguments import add_score_parser
from ptztrack.names import POSE_SOURCES, PROTOCOLS, VERSION, PetsProtocol, SyntheticProtocol


class DefaultsShown(argparse.HelpFormatter):
    """Every option's help ends in its default, as it is typed, unless the help already tells it or there
    is none (None, or an unset flag)."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text, default = action.help or "", action.default
        unset = default is None or default is False or default == argparse.SUPPRESS
        if not action.option_strings or unset or "default" in text:
            return text
        words = default if isinstance(default, list | tuple) else [default]
        shown = " ".join(f"{word:g}" if isinstance(word, float) else str(word) for word in words)
        return f"{text} (default {shown.replace('%', '%%')})"


class OneLineParser(argparse.ArgumentParser):
    """Command-line mistakes end in one line on stderr and exit status 2, like every other bad input, naming
    the help of the command they were made in."""

    def __init__(self, *args, **kwargs) -> None:
        kwargs.setdefault("formatter_class", DefaultsShown)
        super().__init__(*args, **kwargs)

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")

    def parse_args(self, args=None, namespace=None):
        """As argparse's, but words left over are an error of the innermost command given (its help tells
        what it takes), not of ``ptztrack`` itself."""
        parsed, extras = self.parse_known_args(args, namespace)
        if extras:
            command: argparse.ArgumentParser = self
            while (choose := _subcommands(command)) is not None:
                command = choose.choices[getattr(parsed, choose.dest)]
            command.error(f"unrecognized arguments: {' '.join(extras)}")
        return parsed


def _subcommands(command: argparse.ArgumentParser) -> argparse._SubParsersAction | None:
    """The action that picks ``command``'s subcommand, if it has subcommands."""
    return next((each for each in command._actions if isinstance(each, argparse._SubParsersAction)), None)


def parser() -> argparse.ArgumentParser:
    root = OneLineParser(prog="ptztrack", description="Multi-person tracking with a PTZ camera.")
    root.add_argument("--version", action="version", version=f"ptztrack {VERSION}")
    commands = root.add_subparsers(dest="command", required=True)
    policies, detectors = registry.names("policies"), registry.names("detectors")
    run = commands.add_parser("run", help="run one closed-loop episode and print its metrics")
    run.add_argument(
        "--scenario", default="synthetic", help="'synthetic' or 'pets' (built in), or a scenario YAML file"
    )
    run.add_argument("--policy", type=policy_name, choices=policies, default="smpl", help=POLICY_HELP)
    run.add_argument("--detector", choices=detectors, help="overrides the scenario's detector")
    add_detector_model_arguments(run, prior_shift=True)
    run.add_argument(
        "--seed", type=non_negative_int, default=0, help="fixes the run's random draws: the same seed, the same run"
    )
    run.add_argument("--frames", type=positive_int, help="overrides the scenario's number of frames")
    add_tracker_arguments(run)
    run.add_argument(
        "--out", type=Path, help=f"directory for {', '.join(RUN_FOLDER_FILES)}; written whole or not at all"
    )
    run.add_argument("--overwrite", action="store_true", help="replace a non-empty --out folder")
    add_view_argument(run, wait=True)
    add_quiet_argument(run)
    add_recording_arguments(run)
    run.set_defaults(handler="ptztrack.cli.run:run_command")

    view = commands.add_parser("view", help="replay a finished run's --out folder in the web view")
    view.add_argument("folder", type=Path, help="a folder written by ptztrack run, follow or live with --out")
    view.add_argument(
        "--port", type=port_number, default=0, help="serve on http://127.0.0.1:PORT/ (default: any free one)"
    )
    view.add_argument("--steps-per-s", type=positive_float, default=10.0, help="the replay's pace")
    view.set_defaults(handler="ptztrack.cli.run:view_command")

    experiment = commands.add_parser("experiment", help="run one of the papers' experiments and print its table")
    experiments = experiment.add_subparsers(
        dest="name", required=True, metavar="{synthetic,pets,msg,registration,follow,occupancy,network}"
    )

    synthetic = experiments.add_parser("synthetic", help="the PTZ paper's Tables 1-2 on the synthetic scene")
    synthetic.add_argument("--scenario", default="synthetic", help="'synthetic' (built in) or a scenario YAML file")
    synthetic.add_argument("--detector", choices=detectors, **protocol_field(SyntheticProtocol, "detector"))
    add_detector_model_arguments(synthetic, prior_shift=True)
    synthetic.add_argument("--sequences", type=positive_int, **protocol_field(SyntheticProtocol, "sequences"))
    synthetic.add_argument("--frames", type=positive_int, help="overrides the scenario's number of frames")
    synthetic.add_argument(
        "--strategies",
        nargs="+",
        type=policy_name,
        choices=policies,
        **protocol_field(SyntheticProtocol, "strategies"),
    )
    add_association_argument(synthetic)
    add_executor_arguments(synthetic, "one row per strategy")
    synthetic.set_defaults(handler="ptztrack.cli.ptz_paper:synthetic_experiment_command")

    pets = experiments.add_parser(
        "pets", help="the PTZ paper's Tables 3-4 on a recording (default PETS 2009 S2.L1; --dataset for another)"
    )
    pets.add_argument("--detector", **protocol_field(PetsProtocol, "detector"))
    add_detector_model_arguments(pets)
    pets.add_argument(
        "--beta", type=non_negative_float, action="append", **protocol_field(PetsProtocol, "betas", repeatable=True)
    )
    pets.add_argument(
        "--strategies", nargs="+", type=policy_name, choices=policies, **protocol_field(PetsProtocol, "strategies")
    )
    pets.add_argument("--frames", type=positive_int, help="overrides the scenario's number of steps")
    pets.add_argument("--protocol", choices=PROTOCOLS, **protocol_field(PetsProtocol, "protocol"))
    pets.add_argument("--seeds", type=positive_int, **protocol_field(PetsProtocol, "seeds"))
    add_tracker_arguments(pets)
    add_executor_arguments(pets, "one row per strategy and beta")
    add_recording_arguments(pets)
    pets.set_defaults(handler="ptztrack.cli.ptz_paper:pets_experiment_command")

    msg = experiments.add_parser("msg", help="the face-capture paper's Figure 7")
    msg.add_argument("--runs", type=positive_int, default=414, help="simulations")
    msg.add_argument("--plot", type=Path, help="M against N_j/s per scheduler (PNG)")
    msg.add_argument("--trails", type=Path, help="one simulation's trails in (x, y, t) (PNG)")
    add_executor_arguments(msg, "one row per run and scheduler")
    msg.set_defaults(handler="ptztrack.cli.msg:msg_experiment_command")

    registration = experiments.add_parser(
        "registration", help="the scale-invariant paper: registered PTZ views, and the closed loop on their poses"
    )
    registration.add_argument("--scenario", default="pets", help="'pets' (built in) or a recording scenario YAML file")
    registration.add_argument("--views", type=positive_int, default=100, help="random live views to register")
    registration.add_argument("--seed", type=non_negative_int, default=0, help="draws the live views' poses and frames")
    registration.add_argument(
        "--index", type=Path, help="reference index file: read if it exists, else built and written (default: built)"
    )
    registration.add_argument(
        "--exact-views",
        action="store_true",
        help="exact pinhole views instead of the scenario's camera.live_view (default: the realistic model)",
    )
    registration.add_argument("--detector", choices=detectors, default="hog", help="closed-loop detector")
    add_detector_model_arguments(registration)
    registration.add_argument(
        "--policy", type=policy_name, choices=policies, default="smpl", help="the closed loop's policy"
    )
    registration.add_argument(
        "--pose-sources", nargs="+", choices=POSE_SOURCES, default=list(POSE_SOURCES), help="closed-loop pose sources"
    )
    registration.add_argument(
        "--pose-noise-deg",
        type=non_negative_float,
        default=2.0,
        help="closed loop: pan and tilt landing error, 1 sigma",
    )
    registration.add_argument(
        "--zoom-noise", type=non_negative_float, default=0.02, help="closed loop: relative zoom landing error, 1 sigma"
    )
    registration.add_argument(
        "--frames", type=positive_int, help="closed loop: overrides the scenario's number of steps"
    )
    add_tracker_arguments(registration)
    add_executor_arguments(registration, "the registration errors and the closed-loop rows")
    add_recording_arguments(registration)
    registration.set_defaults(handler="ptztrack.cli.registration:registration_experiment_command")
    add_follow_commands(commands, experiments)
    add_occupancy_parser(experiments)
    add_network_parser(experiments, detectors)
    add_camera_commands(commands, policies)
    add_render_parser(commands)
    add_score_parser(commands)
    return root
