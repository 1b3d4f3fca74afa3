"""The command line's arguments: quick to parse (no subsystem), and their choices those of the subsystems."""

import subprocess
import sys

import pytest

from ptztrack.builders.experiments import POSE_SOURCES, STRATEGIES
from ptztrack.builders.follow import FOLLOW_TRACKERS
from ptztrack.builders.follow_experiment import OTB_TRACKS
from ptztrack.builders.occupancy import ROOM_FRAMES
from ptztrack.builders.pets import PROTOCOLS
from ptztrack.camera.onvif_client import PASSWORD_VARIABLE
from ptztrack.cli import arguments
from ptztrack.evaluate.executors import EXECUTORS
from ptztrack.evaluate.report import RUN_FILES
from ptztrack.evaluate.view_state import VIEW_STATES_FILE

# What parsing and printing help may load of ptztrack: the package, the command line's parser, the
# registry's names and the file helpers' errors.
PARSING_MODULES = {"ptztrack", "ptztrack.cli", "ptztrack.cli.arguments", "ptztrack.registry", "ptztrack.files"}


def test_the_command_lines_copies_of_choices_and_defaults_are_the_subsystems():
    assert arguments.RUN_FOLDER_FILES == (*RUN_FILES, VIEW_STATES_FILE)
    assert arguments.STRATEGIES == STRATEGIES
    assert arguments.POSE_SOURCES == POSE_SOURCES
    assert arguments.PROTOCOLS == PROTOCOLS
    assert arguments.FOLLOW_TRACKERS == FOLLOW_TRACKERS
    assert arguments.OTB_TRACKS == OTB_TRACKS
    assert arguments.ROOM_FRAMES == ROOM_FRAMES
    assert arguments.EXECUTORS == EXECUTORS
    assert arguments.PASSWORD_VARIABLE == PASSWORD_VARIABLE


@pytest.mark.parametrize("command", [["--help"], ["run", "--help"], ["experiment", "pets", "--help"], ["bogus"]])
def test_help_and_bad_commands_load_no_subsystem(command):
    script = (
        "import contextlib, io, sys\n"
        "from ptztrack.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):\n"
        "    try:\n"
        f"        main({command!r})\n"
        "    except SystemExit:\n"
        "        pass\n"
        "print(' '.join(sorted(name for name in sys.modules if name.startswith(('ptztrack', 'numpy')))))\n"
    )
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert set(result.stdout.split()) <= PARSING_MODULES
