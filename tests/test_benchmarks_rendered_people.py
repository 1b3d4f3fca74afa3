import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import rendered_people  # noqa: E402

pytestmark = pytest.mark.slow


def test_a_tiny_comparison_writes_the_bins_of_both_recordings(tmp_path, monkeypatch):
    path = tmp_path / "bins.json"
    argv = ["rendered_people.py", "--frames", "20", "--stride", "50", "--json", str(path)]
    monkeypatch.setattr(sys, "argv", argv)
    rendered_people.main()
    document = json.loads(path.read_text())
    assert document["people_look"] == "cones" and document["frames"] == 20
    assert sum(row["rendered_people"] for row in document["bins"]) > 0
    assert sum(row["pets_people"] for row in document["bins"]) > 0
    for row in document["bins"]:
        for recall in (row["rendered_recall"], row["pets_recall"]):
            assert recall is None or 0.0 <= recall <= 1.0
