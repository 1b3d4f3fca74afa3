"""The regression corpus of bad inputs (tests/bad_inputs.py) through the real command, and Ctrl-C.

Each case runs in a fresh process: exit 2 with one line of at most 300 characters and no traceback
(or exit 0 where the input is legitimate), within 10 s and 1 GB of resident memory.
"""

import json
import os
import signal
import subprocess
import sys
import time

import pytest

from bad_inputs import cases, run_case
from ptztrack.cli import main

LINE_MAX_CHARACTERS = 300
SECONDS_MAX = 10.0
MEMORY_MAX_MB = 1024.0


@pytest.fixture(scope="module")
def corpus(tmp_path_factory):
    return {case.name: case for case in cases(tmp_path_factory.mktemp("videos"))}


@pytest.mark.slow
@pytest.mark.parametrize("name", [case.name for case in cases(None)])
def test_every_bad_input_gets_one_clear_line_quickly_and_in_little_memory(corpus, name, tmp_path):
    case = corpus[name]
    outcome = run_case(case, tmp_path)
    assert outcome.exit_status == case.exit_status, outcome.stderr
    if case.exit_status == 2:
        lines = outcome.stderr.strip().splitlines()
        assert len(lines) == 1 and len(lines[0]) <= LINE_MAX_CHARACTERS, outcome.stderr
        assert lines[0].startswith("ptztrack") and "Traceback" not in outcome.stderr
    assert outcome.seconds < SECONDS_MAX
    assert outcome.peak_memory_mb < MEMORY_MAX_MB


@pytest.mark.slow
def test_ctrl_c_stops_a_run_in_one_line_and_leaves_no_folder(tmp_path):
    out = tmp_path / "run"
    process = subprocess.Popen(
        [sys.executable, "-m", "ptztrack.cli", "run", "--frames", "2000", "--out", str(out)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        # A test run in the background of a non-interactive shell inherits SIGINT ignored, which would
        # keep Python from installing its handler: give the command the disposition a terminal gives.
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    time.sleep(8.0)
    assert process.poll() is None, "the run ended before it could be interrupted"
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130
    assert stderr.strip().splitlines() == ["ptztrack: interrupted; nothing was left half-written"]
    assert not out.exists()
    assert os.listdir(tmp_path) == []


def test_a_failed_run_leaves_an_old_folder_as_it_was(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["run", "--frames", "2", "--policy", "fix", "--out", str(out)]) == 0
    before = {path.name: path.read_bytes() for path in out.iterdir()}
    assert main(["run", "--frames", "2", "--policy", "fix", "--out", str(out)]) == 2
    assert "not empty (add --overwrite" in capsys.readouterr().err
    assert main(["run", "--frames", "3", "--policy", "fix", "--out", str(out), "--overwrite"]) == 0
    after = {path.name: path.read_bytes() for path in out.iterdir()}
    assert after.keys() == before.keys() and after["steps.csv"] != before["steps.csv"]
    assert sorted(os.listdir(tmp_path)) == ["run"]


def test_metrics_of_a_run_without_people_are_strict_json_saying_why(tmp_path):
    scenario = tmp_path / "empty.yaml"
    scenario.write_text("people: {count: 0}\n")
    out = tmp_path / "run"
    assert main(["run", "--scenario", str(scenario), "--frames", "3", "--policy", "fix", "--out", str(out)]) == 0

    def refuse(constant):
        raise ValueError(f"{constant} in strict JSON")

    metrics = json.loads((out / "metrics.json").read_text(), parse_constant=refuse)
    assert metrics["motp_m"] is None and "MOTP is a mean over matches" in metrics["undefined"]["motp_m"]
    assert metrics["height_px"] is None and set(metrics["undefined"]) >= {"motp_m", "height_px"}
    assert metrics["objects"] == 0
