"""The command line's options that several commands share, and the types that check every option's value.

Shared: the run folder's files (``RUN_FOLDER_FILES``), the executor, ``--quiet``, ``--view``, the detector's
model, the tracker's overrides and the recording (a dataset file's view, or single files). A type turns the
text of an option into its value or raises :class:`argparse.ArgumentTypeError`, whose message argparse puts
after "argument --option: ": finite numbers, whole numbers, ports (0 to 65535), frame counts (at most
``MAX_FRAMES``), policy names and ONVIF addresses.

It imports argparse, the registry's names and :mod:`ptztrack.names` only, so that ``ptztrack --help`` stays
quick.
"""

import argparse
import math
from dataclasses import fields
from pathlib import Path
from typing import Any

from ptztrack import registry
from ptztrack.names import EXECUTORS, MAX_FRAMES, RUN_FILES, VIEW_STATES_FILE

RUN_FOLDER_FILES = (*RUN_FILES, VIEW_STATES_FILE)
POLICY_HELP = (
    "how the camera picks its next view: the PTZ paper's fix, patrol, rnd (at random), intg or smpl, or a "
    "registered policy"
)


def protocol_field(protocol: type, name: str, repeatable: bool = False) -> dict[str, Any]:
    """``default=`` and ``help=`` of an option from the field ``name`` of the protocol dataclass ``protocol``
    (:mod:`ptztrack.names`): its default (a list for a tuple), and its help ending in that default (a tuple's
    numbers joined by 'and', its words by spaces, as they are typed). With
    ``repeatable`` (an ``append`` option, whose default would be appended to) the default is None and the
    help says the option repeats."""
    (found,) = (each for each in fields(protocol) if each.name == name)
    default = found.default
    if isinstance(default, tuple):
        words = [f"{value:g}" if isinstance(value, float) else str(value) for value in default]
        shown = (" and " if all(isinstance(value, float) for value in default) else " ").join(words)
        default = list(default)
    else:
        shown = f"{default:g}" if isinstance(default, float) else str(default)
    if repeatable:
        return {"default": None, "help": f"{found.metadata['help']} (repeatable; default {shown})"}
    return {"default": default, "help": f"{found.metadata['help']} (default {shown})"}


def add_executor_arguments(command: argparse.ArgumentParser, rows: str) -> None:
    command.add_argument(
        "--executor",
        choices=EXECUTORS,
        default="local",
        help="where the runs go: processes on this machine, a Ray cluster, or one after another in this process",
    )
    command.add_argument("--workers", type=positive_int, help="processes of the local executor (default: all cores)")
    command.add_argument("--json", type=Path, help=f"write {rows} here")
    add_quiet_argument(command)


def add_quiet_argument(command: argparse.ArgumentParser) -> None:
    command.add_argument(
        "--quiet", action="store_true", help="no progress bar (there is none either where stderr is not a terminal)"
    )


def add_view_argument(command: argparse.ArgumentParser, wait: bool = False) -> None:
    """``--view``, and with ``wait`` ``--view-wait`` (a simulated run, which can wait for its first page)."""
    command.add_argument(
        "--view",
        type=port_number,
        nargs="?",
        const=0,
        metavar="PORT",
        help="serve a live view of the run on http://127.0.0.1:PORT/ (no PORT or 0: any free one); the run does "
        f"not wait for a page: pages join and leave at any time{' (see --view-wait)' if wait else ''}",
    )
    if wait:
        command.add_argument(
            "--view-wait",
            action="store_true",
            help="with --view: the run waits after its first step until a page opens it (to watch it from its start)",
        )


def add_detector_model_arguments(command: argparse.ArgumentParser, prior_shift: bool = False) -> None:
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


def add_tracker_arguments(command: argparse.ArgumentParser) -> None:
    add_association_argument(command)
    command.add_argument(
        "--measurement-source",
        choices=("detector", "spatiogram"),
        help="overrides the scenario's tracker.measurement_source (spatiogram: templates between detector steps)",
    )


def add_association_argument(command: argparse.ArgumentParser) -> None:
    command.add_argument(
        "--association", choices=("hungarian", "cjpdaf"), help="overrides the scenario's tracker.association"
    )


def add_recording_arguments(command: argparse.ArgumentParser, files: bool = True) -> None:
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
# "invalid non_negative_int value" of a ValueError), after argparse's "argument --option: ".
def non_negative_float(text: str) -> float:
    return _finite_number(text, 0.0, above=False)


def occupancy_frames(text: str) -> int:
    value = positive_int(text)
    if value > MAX_FRAMES:
        raise argparse.ArgumentTypeError(
            f"must be at most {MAX_FRAMES} (memory: every frame's map and modes are kept; got {value})"
        )
    return value


def occupancy_lead_in(text: str) -> int:
    value = non_negative_int(text)
    if value > MAX_FRAMES:
        raise argparse.ArgumentTypeError(f"must be at most {MAX_FRAMES} (frames rendered and learned; got {value})")
    return value


def positive_float(text: str) -> float:
    return _finite_number(text, 0.0, above=True)


def non_negative_int(text: str) -> int:
    return _whole_number(text, 0)


def positive_int(text: str) -> int:
    return _whole_number(text, 1)


def policy_name(text: str) -> str:
    """A policy's name as typed; a former name is its current one, with a line on stderr saying so."""
    return registry.current_name("policies", text)


def onvif_url(text: str) -> str:
    """A camera's address ``onvif://[user[:password]@]host[:port]``, its scheme required; an error never
    shows the password."""
    scheme, separator, rest = text.partition("://")
    if separator and scheme == "onvif":
        return text
    if separator:
        raise argparse.ArgumentTypeError(f"expected onvif://[user[:password]@]host[:port], not {scheme}://")
    host = text.rpartition("@")[2]
    raise argparse.ArgumentTypeError(
        f"{host!r} has no scheme; expected onvif://[user[:password]@]host[:port], as onvif://{host}"
    )


def port_number(text: str) -> int:
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
