"""The command line's arguments of the robot-cameraman paper's follow camera: ``ptztrack follow`` and
``ptztrack experiment follow``.
"""

import argparse
from pathlib import Path

from ptztrack.cli.options import (
    RUN_FOLDER_FILES,
    add_executor_arguments,
    add_quiet_argument,
    add_recording_arguments,
    add_view_argument,
    non_negative_float,
    non_negative_int,
    positive_int,
)
from ptztrack.names import FOLLOW_TRACKERS, OTB_TRACKS

TRACKER_HELP = "what follows the person in the picture: the paper's particle filter, or OpenCV's CSRT or MIL"
SEED_HELP = "fixes the run's random draws (the particle filter's): the same seed, the same run"


def add_follow_commands(commands, experiments) -> None:
    """``ptztrack follow`` and ``ptztrack experiment follow``: the robot-cameraman paper's follow camera."""
    follow = commands.add_parser("follow", help="follow one annotated PETS person with the virtual PTZ camera")
    follow.add_argument("--target", type=non_negative_int, required=True, help="the annotated person's id")
    follow.add_argument("--tracker", choices=FOLLOW_TRACKERS, default="particle", help=TRACKER_HELP)
    follow.add_argument("--seed", type=non_negative_int, default=0, help=SEED_HELP)
    follow.add_argument("--frames", type=positive_int, help="at most this many steps")
    follow.add_argument(
        "--target-point-px",
        type=non_negative_float,
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
    add_view_argument(follow, wait=True)
    add_quiet_argument(follow)
    _add_follow_scenario_arguments(follow)
    follow.set_defaults(handler="ptztrack.cli.follow:follow_command")

    experiment = experiments.add_parser(
        "follow", help="the robot-cameraman paper: every PETS person followed, and the one-pass benchmark"
    )
    experiment.add_argument(
        "--trackers", nargs="+", choices=FOLLOW_TRACKERS, default=list(FOLLOW_TRACKERS), help=TRACKER_HELP
    )
    experiment.add_argument("--targets", type=non_negative_int, nargs="+", help="people to follow (default: all)")
    experiment.add_argument(
        "--otb-tracks", type=non_negative_int, default=OTB_TRACKS, help="longest tracks of the one-pass benchmark"
    )
    experiment.add_argument("--seed", type=non_negative_int, default=0, help=SEED_HELP)
    _add_follow_scenario_arguments(experiment)
    add_executor_arguments(experiment, '{"closed_loop": [...], "otb": [...]} and the rows per person')
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
    add_recording_arguments(command)
