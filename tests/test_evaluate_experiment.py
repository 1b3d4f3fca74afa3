import importlib.util
import json
import os

import numpy as np
import pytest

from ptztrack.builders.experiments import STRATEGIES, run_cell, synthetic_cells
from ptztrack.cli import main
from ptztrack.config import scenario_from_dict
from ptztrack.evaluate.executors import run_cells
from ptztrack.evaluate.tables import format_table, summarise

SMALL = scenario_from_dict({"frames": 8})


def test_serial_and_local_process_executors_give_identical_rows():
    cells = synthetic_cells(SMALL, sequences=2)
    progress = []
    local = run_cells(cells, run_cell, "local", workers=2, progress=lambda done, total: progress.append((done, total)))
    assert local == run_cells(cells, run_cell, "serial")
    assert [row["strategy"] for row in local] == [cell.strategy for cell in cells]
    assert progress[-1] == (len(cells), len(cells)) and len(progress) == len(cells)


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


def test_summary_is_the_mean_over_sequences_in_the_papers_layout():
    common = {"beta": None}
    rows = [
        {
            "strategy": "fix",
            "label": "fix",
            "mota": 0.5,
            "motp_m": 0.2,
            "height_px": 50.0,
            "detections": 10,
            "zoom": 1.0,
        },
        {
            "strategy": "fix",
            "label": "fix",
            "mota": 0.7,
            "motp_m": 0.4,
            "height_px": 60.0,
            "detections": 20,
            "zoom": 1.0,
        },
        {
            "strategy": "smpl",
            "label": "smpl",
            "mota": 0.9,
            "motp_m": 0.1,
            "height_px": 90.0,
            "detections": 30,
            "zoom": 2.5,
        },
    ]
    summary = summarise([{**row, **common} for row in rows])
    assert [row["strategy"] for row in summary] == ["fix", "smpl"]
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
    }
    lines = format_table(summary).splitlines()
    assert lines[0].split() == ["fix", "smpl"]
    assert lines[1].split() == ["MOTA", "60.0%", "90.0%"]
    assert [line.split("  ")[0].strip() for line in lines[1:]] == [
        "MOTA",
        "MOTP [m]",
        "Height [px]",
        "# Dets",
        "Zoom [x]",
    ]


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
    assert "10/10 episodes" in out.err
    rows = json.loads(path.read_text())
    assert [row["strategy"] for row in rows] == list(STRATEGIES)
    assert all({"strategy", "mota", "motp_m", "height_px", "detections", "zoom"} <= set(row) for row in rows)


def table(detector):
    scenario = scenario_from_dict({"detector": {"kind": detector}})
    return {row["label"]: row for row in summarise(run_cells(synthetic_cells(scenario, 12), run_cell, "local"))}


@pytest.mark.slow
def test_the_papers_synthetic_tables_qualitatively():
    """Tables 1 and 2: the information-gain strategies zoom in and track better than
    patrol and random with either detector, and better than fix with the realistic one."""
    realistic, ideal = table("realistic"), table("ideal")
    for strategy in ("intg", "smpl"):
        for other in ("fix", "patrol", "rnd"):
            assert realistic[strategy]["mota"] > realistic[other]["mota"], (strategy, other)
        for other in ("patrol", "rnd"):
            assert ideal[strategy]["mota"] > ideal[other]["mota"], (strategy, other)
        assert realistic[strategy]["zoom"] > realistic["fix"]["zoom"] + 1.0
        assert realistic[strategy]["height_px"] > realistic["fix"]["height_px"]
        assert realistic[strategy]["motp_m"] < realistic["fix"]["motp_m"]
    assert realistic["fix"]["mota"] < ideal["fix"]["mota"] - 0.2
    assert np.isclose(realistic["fix"]["zoom"], 1.0)


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
