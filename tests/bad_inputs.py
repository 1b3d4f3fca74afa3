"""A regression corpus of bad and near-miss inputs to the ``ptztrack`` command.

Each case is the files it needs (written into a scratch directory), the command line
(``{dir}`` is the scratch directory, ``{data}`` the built-in PETS folder) and the exit status
expected: 2 for a clean one-line error, 0 where the input is legitimate.
The cases are gathered by subject: :mod:`bad_run_inputs` (``ptztrack run``'s files),
:mod:`bad_option_inputs` (the command line's options), :mod:`bad_dataset_inputs` (dataset files) and
:mod:`bad_command_inputs` (the command line's own mistakes), each made of :mod:`bad_input_files`.
Used by tests/test_bad_inputs.py: every case in-process (:func:`run_case_in_process`), a few also in a
fresh process (:func:`run_case`).
"""

import os
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path

from bad_command_inputs import command_cases
from bad_dataset_inputs import dataset_cases
from bad_input_files import Case
from bad_option_inputs import option_cases
from bad_run_inputs import run_cases


def cases(scratch: Path | None) -> list[Case]:
    """Every case; ``scratch`` is where video files are made (None: a temporary folder)."""
    return [*run_cases(scratch), *option_cases(), *dataset_cases(scratch), *command_cases()]


@dataclass(frozen=True)
class Outcome:
    exit_status: int
    stderr: str
    seconds: float
    peak_memory_mb: float


def write_case(case: Case, directory: Path) -> list[str]:
    """Write the case's files into ``directory``; its command line there."""
    for name, content in case.files.items():
        if content is None:
            continue
        path = directory / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)
    return [part.replace("{dir}", str(directory)) for part in case.argv]


def run_case(case: Case, directory: Path, timeout_s: float = 60.0) -> Outcome:
    """Write the case's files into ``directory`` and run the command in a fresh process, measuring its
    wall time and peak resident memory (killed after ``timeout_s``)."""
    argv = write_case(case, directory)
    with tempfile.TemporaryFile("w+") as stderr:
        start = time.perf_counter()
        process = subprocess.Popen(
            [sys.executable, "-m", "ptztrack.cli", *argv], stdout=subprocess.DEVNULL, stderr=stderr
        )
        timer = threading.Timer(timeout_s, process.kill)
        timer.start()
        _, status, usage = os.wait4(process.pid, 0)
        timer.cancel()
        seconds = time.perf_counter() - start
        process.returncode = os.waitstatus_to_exitcode(status)
        stderr.seek(0)
        return Outcome(process.returncode, stderr.read(), seconds, usage.ru_maxrss / 1024)
