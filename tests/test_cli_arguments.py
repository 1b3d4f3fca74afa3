"""The command line's arguments: quick to parse, loading no subsystem."""

import subprocess
import sys

import pytest

# What parsing and printing help may load of ptztrack: the package, the command line's parser, the
# registry's names, the shared names and defaults, the file helpers' errors, and Ctrl-C's handler.
PARSING_MODULES = {
    "ptztrack",
    "ptztrack.cli",
    "ptztrack.cli.arguments",
    "ptztrack.cli.camera_arguments",
    "ptztrack.cli.follow_arguments",
    "ptztrack.cli.multicamera_arguments",
    "ptztrack.cli.options",
    "ptztrack.cli.score_arguments",
    "ptztrack.cli.interrupt",
    "ptztrack.registry",
    "ptztrack.names",
    "ptztrack.files",
}


@pytest.mark.parametrize(
    "command", [["--help"], ["run", "--help"], ["experiment", "pets", "--help"], ["score", "--help"], ["bogus"]]
)
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
