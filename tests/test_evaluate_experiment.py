import importlib.util
import json
import os

import cv2
import numpy as np
import pytest

from ptztrack.builders.experiments import run_cell, scene_statistics, synthetic_cells
from ptztrack.cli import main
from ptztrack.config import scenario_from_dict
from ptztrack.evaluate.executors import run_cells
from ptztrack.evaluate.tables import format_table, paired_difference, summarise
from ptztrack.names import STRATEGIES

SMALL = scenario_from_dict({"frames": 8})


def test_serial_and_local_process_executors_give_identical_rows():
    cells = synthetic_cells(SMALL, sequences=2)
    progress = []
    local = run_cells(cells, run_cell, "local", workers=2, progress=lambda done, total: progress.append((done, total)))
    assert local == run_cells(cells, run_cell, "serial")
    assert [row["strategy"] for row in local] == [cell.strategy for cell in cells]
    assert progress[-1] == (len(cells), len(cells)) and len(progress) == len(cells)


def worker_and_threads(value: int) -> tuple[int, int, int, int]:
    """A cell's value, the process that ran it, OpenCV's threads there and a sum OpenCV computed there."""
    image = np.full((600, 800), value, np.uint8)
    return value, os.getpid(), cv2.getNumThreads(), int(cv2.resize(image, (400, 300)).sum())


def test_cells_run_together_in_one_worker_with_one_opencv_thread_and_come_back_in_order():
    threads = cv2.getNumThreads()
    # This process's OpenCV threads have worked before the pool forks (a worker that then set its own
    # threads would wait forever for them).
    cv2.resize(np.zeros((2000, 2000), np.uint8), (1000, 1000))
    progress = []
    rows = run_cells(
        list(range(7)),
        worker_and_threads,
        "local",
        workers=2,
        progress=lambda done, total: progress.append((done, total)),
        together=lambda value: value % 3 == 0,
    )
    assert [row[0] for row in rows] == list(range(7))
    assert [row[3] for row in rows] == [value * 400 * 300 for value in range(7)]
    assert {row[1] for row in rows if row[0] % 3 == 0} != {os.getpid()}
    assert len({row[1] for row in rows if row[0] % 3 == 0}) == 1 == len({row[1] for row in rows if row[0] % 3})
    assert {row[2] for row in rows} == {1}
    assert cv2.getNumThreads() == threads
    assert progress[-1] == (7, 7) and len(progress) == 2
    serial = run_cells(list(range(7)), worker_and_threads, "serial", together=lambda value: value % 3 == 0)
    assert [(row[0], row[3]) for row in serial] == [(row[0], row[3]) for row in rows]


@pytest.mark.slow
@pytest.mark.skipif(importlib.util.find_spec("ray") is None, reason="needs the ray extra")
def test_ray_executor_gives_the_same_rows():
    # Not imported here: the executor must import Ray itself, after setting
    # the environment that keeps a local cluster on the loopback interface.
    cells = synthetic_cells(SMALL, sequences=2, strategies=("rnd", "smpl"))
    environment = dict(os.environ)
    assert run_cells(cells, run_cell, "ray") == run_cells(cells, run_cell, "serial")
    # The loopback settings were for Ray's start only: the caller's environment is as it was.
    assert dict(os.environ) == environment


def row(strategy, seed, mota, motp_m, height_px, detections, zoom):
    return {
        "strategy": strategy,
        "label": strategy,
        "beta": None,
        "seed": seed,
        "objects": 350,
        "mota": mota,
        "motp_m": motp_m,
        "height_px": height_px,
        "detections": detections,
        "zoom": zoom,
    }


def test_summary_is_the_mean_over_sequences_in_the_papers_layout():
    rows = [
        row("fix", 1, 0.7, 0.4, 60.0, 20, 1.0),
        row("fix", 0, 0.5, 0.2, 50.0, 10, 1.0),
        row("smpl", 0, 0.9, 0.1, 90.0, 30, 2.5),
        row("smpl", 1, 0.8, 0.1, 90.0, 30, 2.5),
    ]
    summary = summarise(rows)
    assert [entry["strategy"] for entry in summary] == ["fix", "smpl"]
    assert summary[0] == {
        "strategy": "fix",
        "label": "fix",
        "beta": None,
        "sequences": 2,
        "mota": pytest.approx(0.6),
        "motp_m": pytest.approx(0.3),
        "height_px": pytest.approx(55.0),
        "detections": pytest.approx(15.0),
        "zoom": pytest.approx(1.0),
        # the sample standard deviation 0.1414, over sqrt(2)
        "mota_se": pytest.approx(0.1),
        "mota_sd": pytest.approx(0.1414, abs=1e-4),
        "seeds": 2,
        "instances": 350.0,
        "mota_per_sequence": [0.5, 0.7],
    }
    # smpl - fix, sequence by sequence: 0.4 and 0.1; mean 0.25, standard error 0.2121 / sqrt(2) = 0.15
    mean, error, count = paired_difference(summary, "smpl", "fix")
    assert (mean, error, count) == (pytest.approx(0.25), pytest.approx(0.15), 2)
    lines = format_table(summary).splitlines()
    assert lines[0].split() == ["fix", "smpl"]
    assert lines[1].split() == ["MOTA", "60.0%", "85.0%"]
    assert lines[2].split() == ["+-10.0", "+-5.0"]
    assert [line.split("  ")[0].strip() for line in lines[3:]] == ["MOTP [m]", "Height [px]", "# Dets", "Zoom [x]"]


def test_unknown_strategies_and_executors_are_refused():
    with pytest.raises(ValueError, match="unknown strategies"):
        synthetic_cells(SMALL, 1, ("fix", "greedy"))
    with pytest.raises(ValueError, match="unknown executor"):
        run_cells(synthetic_cells(SMALL, 1, ("fix",)), run_cell, "cluster")


def test_experiment_command_prints_the_table_and_writes_one_row_per_strategy(tmp_path, capsys):
    path = tmp_path / "table.json"
    code = main(
        ["experiment", "synthetic", "--sequences", "2", "--frames", "6", "--executor", "serial", "--json", str(path)]
    )
    assert code == 0
    out = capsys.readouterr()
    assert "MOTA" in out.out and "Zoom [x]" in out.out
    assert out.err.splitlines() == ["10 episodes, serial executor"]  # no progress bar off a terminal
    rows = json.loads(path.read_text())
    assert [row["strategy"] for row in rows] == list(STRATEGIES)
    assert all({"strategy", "mota", "motp_m", "height_px", "detections", "zoom"} <= set(row) for row in rows)


def table(detector):
    # The paper's protocol: the policies know the simulated detector's curve.
    scenario = scenario_from_dict({"detector": {"kind": detector, "model": "true"}})
    return {row["label"]: row for row in summarise(run_cells(synthetic_cells(scenario, 12), run_cell, "local"))}


@pytest.mark.slow
def test_the_papers_synthetic_tables_qualitatively():
    """Tables 1 and 2 under the paper's protocol (no patrolling term, 12 sequences): with the realistic
    detector smpl > intg > every baseline, both zooming in, seeing people larger and localising them
    better than fix; with the ideal detector smpl has the highest MOTA; fix suffers most from the
    realistic detector. Every row has 350 person-instances per sequence, as in the paper."""
    realistic, ideal = table("realistic"), table("ideal")
    baselines = max(realistic[other]["mota"] for other in ("fix", "patrol", "rnd"))
    assert realistic["smpl"]["mota"] > realistic["intg"]["mota"] > baselines
    assert max(ideal, key=lambda label: ideal[label]["mota"]) == "smpl"
    for strategy in ("intg", "smpl"):
        assert realistic[strategy]["zoom"] > realistic["fix"]["zoom"] + 1.0
        assert realistic[strategy]["height_px"] > realistic["fix"]["height_px"]
        assert realistic[strategy]["motp_m"] < realistic["fix"]["motp_m"]
    assert realistic["fix"]["mota"] < ideal["fix"]["mota"] - 0.2
    assert np.isclose(realistic["fix"]["zoom"], 1.0)
    assert all(row["instances"] == 350 and len(row["mota_per_sequence"]) == 12 for row in realistic.values())


@pytest.mark.slow
def test_the_scene_has_the_papers_statistics():
    """With fix and the ideal detector the paper's camera detects 278.3 of the 350 person-instances
    of a sequence (79.5 %) at 49.1 px; the default scene 75-85 % at 45-55 px, losing most of the
    rest to occlusion."""
    figures = scene_statistics(scenario_from_dict({}), 12)
    assert figures["instances"] == 350
    assert 0.75 <= figures["detected_fraction"] <= 0.85
    assert 45 <= figures["height_px"] <= 55
    assert figures["hidden_fraction"] > figures["out_of_view_fraction"]


@pytest.mark.slow
def test_the_pets_experiment_has_a_column_per_strategy_and_beta(tmp_path, capsys):
    path = tmp_path / "pets.json"
    assert main(["experiment", "pets", "--frames", "20", "--beta", "3", "--beta", "1", "--json", str(path)]) == 0
    rows = json.loads(path.read_text())
    assert [row["label"] for row in rows] == ["fix", "patrol", "rnd", "intg b3", "smpl b3", "intg b1", "smpl b1"]
    assert [row["beta"] for row in rows] == [None, None, None, 3.0, 3.0, 1.0, 1.0]
    assert "intg b3" in capsys.readouterr().out


def test_the_pets_experiment_refuses_a_detector_it_does_not_have(capsys):
    assert main(["experiment", "pets", "--detector", "realistic"]) == 2
    assert "detector 'realistic' is not available" in capsys.readouterr().err
