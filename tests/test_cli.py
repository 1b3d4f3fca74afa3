import csv
import fcntl
import json
import os
import pty
import re
import struct
import sys
import termios
import threading
from pathlib import Path

import pytest

from ptztrack.cli import main
from ptztrack.cli.scenario import build_scenario


def test_run_writes_metrics_tracks_and_picture(tmp_path, capsys):
    assert main(["run", "--policy", "fix", "--detector", "ideal", "--frames", "20", "--out", str(tmp_path)]) == 0
    printed = capsys.readouterr()
    assert "MOTA" in printed.out and "MOTP [m]" in printed.out
    assert printed.err == ""  # no progress bar where stderr is not a terminal
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    assert {"mota", "motp_m", "idf1", "height_px", "detections", "zoom"} <= set(metrics)
    with open(tmp_path / "tracks.csv", newline="") as file:
        rows = list(csv.DictReader(file))
    assert {"frame", "id", "x_m", "y_m", "var_x_m2", "cov_xy_m2", "var_y_m2"} <= set(rows[0])
    assert {int(row["frame"]) for row in rows} == set(range(20))
    assert (tmp_path / "episode.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not list(tmp_path.glob(".*tmp"))


def test_same_seed_gives_byte_identical_outputs_and_another_seed_does_not(tmp_path):
    common = ["run", "--policy", "fix", "--detector", "ideal", "--frames", "15"]
    for name, seed in (("a", "0"), ("b", "0"), ("c", "1")):
        assert main(common + ["--seed", seed, "--out", str(tmp_path / name)]) == 0
    for name in ("metrics.json", "tracks.csv", "episode.png"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()
    assert (tmp_path / "a" / "tracks.csv").read_bytes() != (tmp_path / "c" / "tracks.csv").read_bytes()


def test_a_scenario_file_runs(tmp_path, capsys):
    path = tmp_path / "small.yaml"
    path.write_text("area_m: [10, 10]\nframes: 8\npeople: {count: 3}\ncamera: {position_m: [5, -3, 6]}\n")
    assert main(["run", "--scenario", str(path)]) == 0
    assert "3 people" in capsys.readouterr().out


@pytest.mark.parametrize("text, field", [("area_m: [-15, 15]\n", "area_m.0"), ("speed: 3\n", "speed: unknown key")])
def test_bad_scenario_file_exits_2_with_one_line_and_no_traceback(tmp_path, capfd, text, field):
    """In-process (stderr at file descriptor 2); tests/test_bad_inputs.py runs such cases in a fresh process too."""
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    assert main(["run", "--scenario", str(path)]) == 2
    stderr = capfd.readouterr().err
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, stderr
    assert field in lines[0] and str(path) in lines[0]
    assert "Traceback" not in stderr


def test_an_output_path_that_cannot_be_a_directory_exits_2_naming_it(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("keep me")
    assert main(["run", "--frames", "3", "--out", str(blocker / "out")]) == 2
    assert f"{blocker / 'out'}: {blocker} is a file, not a folder" in capsys.readouterr().err
    assert blocker.read_text() == "keep me"


EXCERPT = Path(__file__).parent / "data" / "pets_s2l1_excerpt"


def test_pets_runs_on_recording_files_given_on_the_command_line_either_calibration_format(tmp_path, capsys):
    files = ["--video", str(EXCERPT / "View_001.avi"), "--gt", str(EXCERPT / "gt_mot15.txt")]
    results = {}
    for calibration in ("pinhole.json", "View_001.xml"):
        out = tmp_path / calibration
        arguments = ["run", "--scenario", "pets", "--policy", "fix", "--frames", "10", "--out", str(out)]
        assert main(arguments + files + ["--calibration", str(EXCERPT / calibration)]) == 0
        results[calibration] = json.loads((out / "metrics.json").read_text())
    # The two calibrations of the same camera track the same people equally well.
    assert results["pinhole.json"]["detections"] == results["View_001.xml"]["detections"] > 0
    assert abs(results["pinhole.json"]["mota"] - results["View_001.xml"]["mota"]) < 0.05


@pytest.mark.parametrize(
    "option, name, problem",
    [
        ("--gt", "missing.txt", "no such ground-truth file"),
        ("--calibration", "calibration.json", "not valid JSON"),
        ("--video", "short.avi", "30 frames, the run needs"),
    ],
)
def test_a_bad_recording_file_exits_2_naming_the_file_and_the_problem(tmp_path, capsys, option, name, problem):
    path = tmp_path / name
    if name == "calibration.json":
        path.write_text("{not json")
    if name == "short.avi":
        path.write_bytes((EXCERPT / "View_001.avi").read_bytes())
    arguments = ["run", "--scenario", "pets", "--policy", "fix", "--detector", "hog", "--frames", "40"]
    assert main(arguments + [option, str(path)]) == 2
    error = capsys.readouterr().err
    assert str(path) in error and problem in error


def test_msg_experiment_prints_the_table_and_writes_rows_plot_and_trails(tmp_path, capsys):
    paths = {name: tmp_path / name for name in ("rows.json", "figure7.png", "trails.png")}
    arguments = ["experiment", "msg", "--runs", "3", "--executor", "serial"]
    arguments += [
        "--json",
        str(paths["rows.json"]),
        "--plot",
        str(paths["figure7.png"]),
        "--trails",
        str(paths["trails.png"]),
    ]
    assert main(arguments) == 0
    out = capsys.readouterr().out
    assert "N_j/s" in out and "msg - leave-first" in out and "msg - msg-no-join" in out
    rows = json.loads(paths["rows.json"].read_text())
    schedulers = {"msg", "msg-no-untangling", "naive", "msg-no-join", "leave-first"}
    assert len(rows) == 15 and {row["scheduler"] for row in rows} == schedulers
    assert all({"scheduler", "nj_s", "m"} <= set(row) and 0 <= row["m"] <= 1 for row in rows)
    for name in ("figure7.png", "trails.png"):
        assert paths[name].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_bad_registration_index_exits_2_naming_the_file(tmp_path, capsys):
    bad = tmp_path / "index.npz"
    bad.write_bytes(b"not an index")
    assert main(["experiment", "registration", "--index", str(bad), "--views", "1"]) == 2
    error = capsys.readouterr().err
    assert f"{bad}: not a registration index" in error
    assert "Traceback" not in error


@pytest.mark.slow
def test_the_registration_experiment_uses_realistic_live_views_and_says_which(tmp_path, capsys):
    document_path = tmp_path / "registration.json"
    arguments = ["experiment", "registration", "--views", "3", "--pose-sources", "oracle", "--frames", "3"]
    assert main([*arguments, "--detector", "ideal", "--executor", "serial", "--json", str(document_path)]) == 0
    assert "live views rolled up to 2 deg, principal point up to 10 px off" in capsys.readouterr().out
    document = json.loads(document_path.read_text())
    model = document["live_view_model"]
    assert model["exact"] is False and model["roll_max_deg"] == 2.0 and model["jpeg_quality"] == 75
    assert model["reference_frames"] == [1, 89] and model["first_live_frame"] == 389
    assert document["registered"] == 3 and document["focal_err_median_pct"] < 1.0
    assert document["ground_err_median_m"] is not None and [row["pose_source"] for row in document["closed_loop"]] == [
        "oracle"
    ]


def _stderr(argv: list[str], monkeypatch) -> str:
    """What ``ptztrack argv`` writes on stderr into a pseudo-terminal, as a user sees it: run in-process
    with sys.stderr the terminal's end (tqdm asks it whether it is a terminal, and its size)."""
    controller, terminal_end = pty.openpty()
    fcntl.ioctl(terminal_end, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 120, 0, 0))  # 24 rows, 120 columns
    chunks = []

    def read() -> None:
        while True:
            try:
                chunk = os.read(controller, 4096)
            except OSError:  # EIO: the terminal's end is closed and all it had is read
                break
            if not chunk:
                break
            chunks.append(chunk)

    reader = threading.Thread(target=read)
    reader.start()
    with monkeypatch.context() as patch, open(terminal_end, "w", buffering=1) as terminal:
        patch.setattr(sys, "stderr", terminal)
        status = main(argv)
    reader.join()
    os.close(controller)
    assert status == 0
    return b"".join(chunks).decode()


def test_a_progress_bar_in_a_terminal_and_none_with_quiet(monkeypatch):
    """tqdm's bar: what is counted, the share done, done / all, elapsed < left, the rate. Off a terminal
    there is none either (the in-process tests, whose stderr is captured, check it)."""
    experiment = ["experiment", "synthetic", "--sequences", "2"]
    experiment += ["--frames", "4", "--strategies", "fix", "rnd", "--executor", "serial"]
    shown = _stderr(experiment, monkeypatch)
    assert re.search(r"episodes: 100%\|.*\| 4/4 \[\d\d:\d\d<00:00, +[\d.]+episode/s\]", shown), shown
    quiet = _stderr([*experiment, "--quiet"], monkeypatch)
    assert "episodes:" not in quiet and "%|" not in quiet and "4 episodes, serial executor" in quiet
    run = _stderr(["run", "--frames", "6", "--policy", "fix"], monkeypatch)
    assert re.search(r"steps: 100%\|.*\| 6/6 \[\d\d:\d\d<00:00, +[\d.]+step/s\]", run), run


def test_the_command_line_selects_the_cjpdaf_association(capsys):
    assert build_scenario("pets", "hog", association="cjpdaf").tracker.association == "cjpdaf"
    assert build_scenario("synthetic", association="cjpdaf").tracker.association == "cjpdaf"
    assert main(["run", "--scenario", "pets", "--policy", "fix", "--association", "cjpdaf", "--frames", "5"]) == 0
    assert "MOTA" in capsys.readouterr().out
    with pytest.raises(SystemExit) as error:
        main(["run", "--association", "greedy"])
    assert error.value.code == 2
