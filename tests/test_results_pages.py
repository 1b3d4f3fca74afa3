"""The results pages are what docs/build_results.py writes from the stored JSON, and a figure on them
moves with its JSON."""

import importlib.util
import json
import shutil
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"


def load_builder(name: str = "build_results"):
    spec = importlib.util.spec_from_file_location(name, DOCS / "build_results.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_committed_results_pages_are_what_the_build_writes_from_the_stored_json(capsys):
    assert load_builder().main(["--check"]) == 0, capsys.readouterr().err


@pytest.fixture
def builder_on_a_copy(tmp_path):
    """The builder reading and writing a copy of docs/results."""
    results = tmp_path / "results"
    shutil.copytree(DOCS / "results", results)
    builder = load_builder("build_results_on_a_copy")
    builder.RESULTS, builder.TEMPLATES, builder.DATA = results, results / "templates", results / "data"
    return builder


def test_a_changed_json_value_changes_its_page_and_the_check_names_the_page(builder_on_a_copy, capsys):
    data = builder_on_a_copy.DATA / "synthetic-ideal.json"
    rows = json.loads(data.read_text())
    fix = next(row for row in rows if row["label"] == "fix")
    before = builder_on_a_copy.render("information-gain")
    assert builder_on_a_copy.formatting.pct_pm(fix["mota"], fix["mota_se"]) in before
    fix["mota"] = 0.123
    data.write_text(json.dumps(rows))

    after = builder_on_a_copy.render("information-gain")

    assert after != before
    assert builder_on_a_copy.formatting.pct_pm(0.123, fix["mota_se"]) in after
    assert builder_on_a_copy.main(["--check"]) == 1
    assert "information-gain.md" in capsys.readouterr().err
    assert builder_on_a_copy.main([]) == 0
    assert builder_on_a_copy.main(["--check"]) == 0


def test_a_template_naming_a_figure_no_json_gives_is_refused(builder_on_a_copy):
    template = builder_on_a_copy.TEMPLATES / "face-capture.md.in"
    template.write_text(template.read_text() + "\n{{ msg_typed_by_hand }}\n")
    with pytest.raises(KeyError, match="msg_typed_by_hand"):
        builder_on_a_copy.render("face-capture")
