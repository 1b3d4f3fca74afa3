"""The regression corpus of bad inputs (tests/bad_inputs.py) through the real command, and Ctrl-C.

Every case runs in-process through ``ptztrack.cli.main``: exit 2 with one line of at most 300 characters
on stderr (file descriptor 2; records logged and Python warnings count as lines too) and no traceback (or
exit 0 where the input is legitimate), the lines naming what the case says they must (``Case.says``: the
field, the file, the bound), in less than 1 GB of resident memory: what a fresh process holds
after importing the command, plus what the case's run adds to this process's peak (Linux's peak resident
memory, reset before each case). The memory bombs, a legitimate input and an argparse error also run in a
fresh process as a user runs the command: the exit status, the one line, under 1 GB of peak resident memory.
In-process, a refused case must also end within ``SECONDS_MAX`` (a bad input is checked before the
work; a case that hangs is stopped after ``HANG_S``) and leave its scratch folder as it was: nothing
written, not even a temporary.
"""

import contextlib
import json
import logging
import os
import signal
import socket
import stat
import subprocess
import sys
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import PIL.Image
import pytest
from scipy.optimize import minimize_scalar

from bad_input_files import Case
from bad_inputs import cases, run_case, write_case
from ptztrack.cli import main
from ptztrack.cli.interrupt import INTERRUPTED, _inside_compiler
from ptztrack.config import load_camera_calibration, write_camera_calibration
from ptztrack.occupancy.multiview import ImageFolder
from ptztrack.scene.pets import DatasetError

LINE_MAX_CHARACTERS = 300
MEMORY_MAX_MB = 1024.0
SECONDS_MAX = 10.0
HANG_S = 60.0
"""A case still running after this long is a hang (the fresh-process runner kills it then too)."""
IN_A_FRESH_PROCESS = [
    "YAML billion laughs",
    "XML entity bomb",
    "detections gzip bomb",
    "people.count 1e6",
    "image_size_px 1e8",
    "scenario a huge value",
    "--beta nan",
    "dataset: a good one",
]
"""Memory bombs, an argparse error (SystemExit in-process) and a legitimate input, run as a user runs
them."""


@pytest.fixture(scope="module")
def corpus(tmp_path_factory):
    return {case.name: case for case in cases(tmp_path_factory.mktemp("videos"))}


@pytest.fixture(scope="module")
def imported_mb() -> float:
    """The peak resident memory of a fresh process that has imported the command, in MB."""
    script = "import resource, ptztrack.cli; print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)"
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    return int(result.stdout) / 1024


def resident_mb() -> tuple[float, float]:
    """This process's resident memory and its peak since the last reset, in MB (Linux)."""
    status = dict(line.split(":", 1) for line in open("/proc/self/status").read().splitlines())
    return int(status["VmRSS"].split()[0]) / 1024, int(status["VmHWM"].split()[0]) / 1024


class Hung(BaseException):
    """Raised in the test's thread when a case runs past ``HANG_S`` (not an Exception, so that the
    command's own handlers do not turn it into an exit status)."""


@dataclass(frozen=True)
class InProcess:
    """What ``main`` did with a case: its exit status, the lines a user would see on stderr (written,
    logged, warned), all of stderr, how much it raised the peak resident memory above what it found
    (MB), how long it took (s), and the files it left in the case's folder beside the case's own."""

    status: int
    lines: list[str]
    stderr: str
    added_mb: float
    seconds: float
    written: set


def run_in_process(case: Case, directory: Path, capfd, caplog) -> InProcess:
    """``main`` on the case, its files written into ``directory``."""
    argv = write_case(case, directory)
    given = files_in(directory)
    capfd.readouterr()
    caplog.clear()

    def hung(signum, frame):
        raise Hung(f"{case.name}: still running after {HANG_S:g} s")

    previous = signal.signal(signal.SIGALRM, hung)
    signal.setitimer(signal.ITIMER_REAL, HANG_S)
    with open("/proc/self/clear_refs", "w") as clear_refs:
        clear_refs.write("5")  # the peak resident memory starts again from the current
    before_mb, _ = resident_mb()
    started = time.monotonic()
    try:
        with warnings.catch_warnings(record=True) as caught:
            # Python's default filters outside pytest: what a user would see printed.
            warnings.simplefilter("default")
            for category in (DeprecationWarning, PendingDeprecationWarning, ImportWarning, ResourceWarning):
                warnings.filterwarnings("ignore", category=category)
            try:
                status = main(argv)
            except SystemExit as exit:  # argparse's errors
                status = exit.code
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, previous)
    seconds = time.monotonic() - started
    added_mb = resident_mb()[1] - before_mb
    stderr = capfd.readouterr().err
    lines = stderr.strip().splitlines()
    lines += [f"ptztrack: {record.getMessage()}" for record in caplog.records if record.levelno >= logging.WARNING]
    lines += [f"{warning.category.__name__}: {warning.message}" for warning in caught]
    return InProcess(status, lines, stderr, added_mb, seconds, files_in(directory) - given)


def files_in(directory: Path) -> set[Path]:
    return {path.relative_to(directory) for path in directory.rglob("*")}


@pytest.mark.parametrize("name", [case.name for case in cases(None)])
def test_every_bad_input_gets_one_clear_line_and_little_memory(corpus, imported_mb, name, tmp_path, capfd, caplog):
    case = corpus[name]
    run = run_in_process(case, tmp_path, capfd, caplog)
    assert run.status == case.exit_status, run.lines
    if case.exit_status == 2:
        assert len(run.lines) == 1 and len(run.lines[0]) <= LINE_MAX_CHARACTERS, run.lines
        assert run.lines[0].startswith("ptztrack") and "Traceback" not in run.stderr
        assert run.seconds < SECONDS_MAX and not run.written, (run.seconds, run.written)
    said = "\n".join(run.lines)
    assert all(part.replace("{dir}", str(tmp_path)) in said for part in case.says), (case.says, run.lines)
    assert imported_mb + run.added_mb < MEMORY_MAX_MB, (imported_mb, run.added_mb)


@pytest.mark.slow
@pytest.mark.parametrize("name", IN_A_FRESH_PROCESS)
def test_in_a_fresh_process_one_clear_line_and_little_resident_memory(corpus, name, tmp_path):
    case = corpus[name]
    outcome = run_case(case, tmp_path)
    assert outcome.exit_status == case.exit_status, outcome.stderr
    if case.exit_status == 2:
        lines = outcome.stderr.strip().splitlines()
        assert len(lines) == 1 and len(lines[0]) <= LINE_MAX_CHARACTERS, outcome.stderr
        assert lines[0].startswith("ptztrack") and "Traceback" not in outcome.stderr
    assert outcome.peak_memory_mb < MEMORY_MAX_MB


CTRL_C_DELAYS_S = (1.0, 3.0, 8.0)
"""When the Ctrl-C test interrupts a run: while its modules load, while its world is built, while Numba
compiles (on an empty cache, as on a new machine: its first functions take seconds to compile)."""
STOP_S = 2.0
"""How long after Ctrl-C a command may take to end."""


def start_command(argv: list[str], **options) -> subprocess.Popen:
    """The command in a fresh process, its stderr piped, with SIGINT's default disposition: a test run
    in the background of a non-interactive shell inherits SIGINT ignored, which would keep Python from
    installing its handler."""
    return subprocess.Popen(
        [sys.executable, "-m", "ptztrack.cli", *argv],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
        **options,
    )


def stopped_within(process: subprocess.Popen, seconds: float) -> str:
    """The stderr of ``process``, which must end within ``seconds``."""
    started = time.monotonic()
    try:
        _, stderr = process.communicate(timeout=seconds)
    except subprocess.TimeoutExpired:
        process.kill()
        process.communicate()
        raise AssertionError(f"still running {seconds:g} s after Ctrl-C") from None
    assert time.monotonic() - started < seconds
    return stderr


def test_ctrl_c_under_scipy_waits_for_it_to_return_as_inside_numbas_compiler():
    """A KeyboardInterrupt raised under SciPy's compiled code is printed as ignored, not raised (the
    tracker's quadrature is made there, in a run's first steps): the handler defers a Ctrl-C while any
    frame of the interrupted stack is SciPy's, and raises it at once elsewhere."""
    frames = []
    minimize_scalar(lambda x: frames.append(sys._getframe()) or (x - 1.0) ** 2)
    assert _inside_compiler(frames[0])
    assert not _inside_compiler(sys._getframe())


@pytest.mark.slow
def test_ctrl_c_stops_a_run_within_two_seconds_in_one_line_and_leaves_no_folder(tmp_path):
    # Started together and interrupted in turn: one run's wait is the next one's start.
    outputs = tmp_path / "outputs"
    outputs.mkdir()
    runs = {
        delay_s: start_command(
            ["run", "--frames", "20000", "--out", str(outputs / f"run-{delay_s:g}")],
            env={**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / f"numba-cache-{delay_s:g}")},
        )
        for delay_s in CTRL_C_DELAYS_S
    }
    started = time.monotonic()
    try:
        for delay_s, process in runs.items():
            time.sleep(max(0.0, started + delay_s - time.monotonic()))
            assert process.poll() is None, f"the run ended before {delay_s:g} s"
            process.send_signal(signal.SIGINT)
            stderr = stopped_within(process, STOP_S)
            assert process.returncode == 130, (delay_s, stderr)
            assert stderr.strip().splitlines() == [INTERRUPTED], delay_s
    finally:
        for process in runs.values():
            process.kill()
            process.communicate()
    assert os.listdir(outputs) == []


@pytest.mark.slow
def test_ctrl_c_to_the_process_and_its_group_at_once_stops_an_experiment_in_one_line(tmp_path):
    """As a terminal's Ctrl-C (the group: the command and the local executor's workers) with a
    supervisor's (the command), twice more while it stops."""
    json = tmp_path / "follow.json"
    process = start_command(["experiment", "follow", "--json", str(json)], start_new_session=True)
    try:
        assert "closed-loop runs, local executor" in process.stderr.readline()
        time.sleep(0.5)  # the workers have started
        for gap_s in (0.0, 0.01, 0.05):
            time.sleep(gap_s)
            with contextlib.suppress(ProcessLookupError):
                os.kill(process.pid, signal.SIGINT)
                os.killpg(process.pid, signal.SIGINT)
        stderr = stopped_within(process, STOP_S)
    finally:
        process.kill()
        process.communicate()
    assert process.returncode == 130, stderr
    assert stderr.strip().splitlines() == [INTERRUPTED]
    assert not json.exists()


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


@pytest.mark.parametrize(
    "argv",
    [
        ["serve-camera", "--port", "{port}"],
        ["view", "{dir}", "--port", "{port}"],
        ["run", "--frames", "2", "--view", "{port}"],
    ],
    ids=["serve-camera", "view", "run --view"],
)
def test_a_port_another_program_listens_on_is_named_in_one_line(tmp_path, capfd, argv):
    with socket.create_server(("127.0.0.1", 0)) as busy:
        port = busy.getsockname()[1]
        assert main([part.format(port=port, dir=tmp_path) for part in argv]) == 2
    option = argv[-2]
    assert capfd.readouterr().err.splitlines() == [
        f"ptztrack: error: {option} {port}: cannot listen on 127.0.0.1:{port} (Address already in use)"
    ]


def test_an_image_folder_is_sized_as_opencv_decodes_it(tmp_path):
    """A JPEG turned by its EXIF orientation (a phone's) has the size of the plain image it decodes to."""
    exif = PIL.Image.Exif()
    exif[0x0112] = 6  # rotated 90 degrees
    PIL.Image.new("RGB", (64, 32)).save(tmp_path / "1.jpg", exif=exif.tobytes())
    PIL.Image.new("RGB", (32, 64)).save(tmp_path / "2.jpg")
    folder = ImageFolder(tmp_path)
    assert folder.frame(0).shape == folder.frame(1).shape == (64, 32, 3)
    PIL.Image.new("RGB", (64, 32)).save(tmp_path / "3.jpg")
    with pytest.raises(DatasetError, match=r"3.jpg: 64x32 px, but 1.jpg is 32x64 px"):
        ImageFolder(tmp_path)


@pytest.fixture(params=[0o022, 0o077], ids=["umask-022", "umask-077"])
def umask(request):
    previous = os.umask(request.param)
    yield request.param
    os.umask(previous)


def test_a_run_folder_and_its_files_get_the_users_umask(tmp_path, umask, capsys):
    out = tmp_path / "run"
    assert main(["run", "--frames", "2", "--policy", "fix", "--out", str(out)]) == 0
    assert stat.S_IMODE(out.stat().st_mode) == 0o777 & ~umask
    modes = {path.name: stat.S_IMODE(path.stat().st_mode) for path in out.iterdir()}
    assert "episode.mp4" in modes and set(modes.values()) == {0o666 & ~umask}, modes


def test_a_rewritten_file_keeps_its_mode_and_a_new_one_gets_the_umask(tmp_path, umask):
    """As ``camera calibrate`` rewrites a calibration file, and ``--json`` replaces an earlier one."""
    kept, new = tmp_path / "camera.yaml", tmp_path / "new.yaml"
    kept.write_text("pan_deg: [-90, 90]\ntilt_deg: [-45, 45]\nzoom_curve: [[0, 1], [1, 4]]\n")
    kept.chmod(0o640)
    calibration = load_camera_calibration(kept).model_copy(update={"image_delay_s": 0.1})
    write_camera_calibration(kept, calibration)
    write_camera_calibration(new, calibration)
    assert load_camera_calibration(kept).image_delay_s == 0.1
    assert stat.S_IMODE(kept.stat().st_mode) == 0o640
    assert stat.S_IMODE(new.stat().st_mode) == 0o666 & ~umask
    assert sorted(os.listdir(tmp_path)) == ["camera.yaml", "new.yaml"]


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
