import json

import numpy as np
import pytest

from ptztrack.cli import main
from ptztrack.config import scenario_from_dict
from ptztrack.experiments.network import (
    WIDE_CAMERA_POSITION_M,
    configurations,
    network_scenario,
    ring_positions_m,
    summarise_network,
)


def test_the_ring_starts_at_the_scenarios_camera_and_keeps_its_distance_and_height():
    scenario = scenario_from_dict({})
    centre_m = np.array([7.5, 7.5])
    one, two, four = (np.asarray(ring_positions_m(scenario, count)) for count in (1, 2, 4))
    np.testing.assert_allclose(one, [scenario.camera.position_m])
    np.testing.assert_allclose(two[1], [7.5, 21.0, 2.5], atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(four[:, :2] - centre_m, axis=1), 13.5)
    network = network_scenario(scenario, 2, fixed=True, wide=True)
    assert [camera.kind for camera in network.cameras] == ["fixed"] * 3
    assert network.cameras[-1].position_m == WIDE_CAMERA_POSITION_M
    mast = network_scenario(scenario, 3, fixed=False, wide=False, placement="mast")
    assert [camera.kind for camera in mast.cameras] == ["ptz"] * 3
    assert {camera.position_m for camera in mast.cameras} == {scenario.camera.position_m}


def test_every_configuration_pairs_with_the_joint_one_of_the_same_cameras():
    pairs = {row.label: row.pairs_with for row in configurations(2)}
    assert pairs == {
        "1ptz": None,
        "1fixed": "1ptz",
        "2ptz-joint": None,
        "2ptz-independent": "2ptz-joint",
        "2fixed": "2ptz-joint",
        "1ptz+wide": None,
        "1fixed+wide": "1ptz+wide",
        "2ptz-joint+wide": None,
        "2ptz-independent+wide": "2ptz-joint+wide",
        "2fixed+wide": "2ptz-joint+wide",
        "wide": None,
        "2ptz-joint-mast": None,
        "2ptz-independent-mast": "2ptz-joint-mast",
    }


def test_the_paired_difference_is_taken_sequence_by_sequence():
    figures = {"motp_m": 0.2, "idf1": 0.5, "detections": 10, "zoom": 2.0}
    motas = {"2ptz-joint": [0.5, 0.7, 0.6], "2fixed": [0.3, 0.6, 0.3]}
    pairs = {"2ptz-joint": None, "2fixed": "2ptz-joint"}
    rows = [
        {"config": label, "joint": pairs[label], "seed": seed, "mota": mota, **figures}
        for label, values in motas.items()
        for seed, mota in reversed(list(enumerate(values)))
    ]
    joint, fixed = summarise_network(rows)
    assert joint["mota_per_sequence"] == [0.5, 0.7, 0.6] and "mota_minus_joint" not in joint
    assert fixed["mota_minus_joint"] == pytest.approx(-0.2)
    assert fixed["mota_minus_joint_se"] == pytest.approx(np.std([-0.2, -0.1, -0.3], ddof=1) / np.sqrt(3))
    assert fixed["mota_se"] == pytest.approx(np.std([0.3, 0.6, 0.3], ddof=1) / np.sqrt(3))


def test_the_command_writes_one_row_per_configuration(tmp_path, capsys):
    path = tmp_path / "network.json"
    arguments = ["experiment", "network", "synthetic", "--sequences", "2", "--frames", "4", "--max-ptz", "1"]
    assert main([*arguments, "--executor", "serial", "--quiet", "--json", str(path)]) == 0
    rows = json.loads(path.read_text())
    assert [row["config"] for row in rows] == ["1ptz", "1fixed", "1ptz+wide", "1fixed+wide", "wide"]
    for row in rows:
        assert {"config", "mota", "mota_se", "mota_per_sequence", "motp_m", "idf1"} <= set(row)
        assert len(row["mota_per_sequence"]) == 2
    fixed, ptz = rows[1], rows[0]
    difference = np.subtract(fixed["mota_per_sequence"], ptz["mota_per_sequence"]).mean()
    assert fixed["joint"] == "1ptz" and fixed["mota_minus_joint"] == pytest.approx(difference)
    assert "1fixed+wide" in capsys.readouterr().out


def test_a_development_run_scores_the_sequences_it_names_as_the_table_would(tmp_path):
    arguments = ["experiment", "network", "synthetic", "--frames", "4", "--max-ptz", "1", "--executor", "serial"]
    table, development = tmp_path / "table.json", tmp_path / "development.json"
    assert main([*arguments, "--sequences", "2", "--quiet", "--json", str(table)]) == 0
    assert main([*arguments, "--sequences", "1", "--first-sequence", "1", "--quiet", "--json", str(development)]) == 0
    for whole, later in zip(json.loads(table.read_text()), json.loads(development.read_text()), strict=True):
        assert whole["seeds"] == [0, 1] and later["seeds"] == [1]
        assert later["mota_per_sequence"] == whole["mota_per_sequence"][1:]
