"""What the documentation promises of its own pages: a short README, no dates or issue numbers outside the
changelog and the decision records, and reference pages generated from the code (docs/hooks/reference.py)
that cover every command, option and field."""

import argparse
import functools
import importlib.util
import re
from pathlib import Path

import pytest

from ptztrack.cli import parser
from ptztrack.config import CameraCalibrationFile, MultiViewDataset, Scenario
from ptztrack.service.config import ServiceConfig

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
README_MAX_LINES = 150
# History belongs to these: the changelog and the numbered decision records.
HISTORY_PAGES = ("changelog.md", "decisions/")
DATE = re.compile(r"\b\d{4}-\d{2}-\d{2}\b")
ISSUE = re.compile(r"\bissues?\s+#?\d+|(?<![\w&/#])#\d+\b", re.IGNORECASE)


def reader_pages() -> list[Path]:
    """README.md and every page of docs/ but the changelog and the decision records."""
    pages = sorted(DOCS.rglob("*.md"))
    kept = [page for page in pages if not page.relative_to(DOCS).as_posix().startswith(HISTORY_PAGES)]
    return [ROOT / "README.md", *kept]


@functools.cache
def load_reference_hook():
    spec = importlib.util.spec_from_file_location("docs_reference_hook", DOCS / "hooks" / "reference.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_readme_is_a_front_door_of_at_most_150_lines():
    lines = (ROOT / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) <= README_MAX_LINES, f"README.md has {len(lines)} lines, at most {README_MAX_LINES}"


@pytest.mark.parametrize("page", reader_pages(), ids=lambda page: page.relative_to(ROOT).as_posix())
def test_a_page_holds_no_date_and_no_issue_number(page):
    """Dates and issue numbers are history, which the changelog and the decision records keep."""
    found = [
        f"line {number}: {match.group(0)!r}"
        for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1)
        for match in (*DATE.finditer(line), *ISSUE.finditer(line))
    ]
    assert not found, f"{page.relative_to(ROOT)}: " + "; ".join(found[:10])


def commands(command: argparse.ArgumentParser, words: tuple[str, ...] = ("ptztrack",)):
    """Every command of the parser, as (words, parser), the root first."""
    yield words, command
    for action in command._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from commands(sub, (*words, name))


def test_the_command_line_reference_has_every_command_and_option_with_its_help():
    generated = load_reference_hook().command_line()
    for words, command in commands(parser()):
        if len(words) > 1:
            assert f"`{' '.join(words)}`" in generated, words
        for action in command._actions:
            for option in action.option_strings:
                assert f"`{option}" in generated or f", {option}" in generated, (words, option)


@pytest.mark.parametrize(
    ("name", "model"),
    [
        ("scenario", Scenario),
        ("dataset", MultiViewDataset),
        ("calibration", CameraCalibrationFile),
        ("service", ServiceConfig),
    ],
)
def test_a_file_reference_has_every_field_of_its_model_and_its_sections(name, model):
    generated = getattr(load_reference_hook(), name)()
    models = [model]
    while models:
        current = models.pop()
        for field, info in current.model_fields.items():
            assert f"| `{field}` |" in generated, (current.__name__, field)
            models.extend(load_reference_hook()._nested_models(info.annotation))


@pytest.mark.parametrize("model", [Scenario, MultiViewDataset, CameraCalibrationFile, ServiceConfig])
def test_every_field_of_a_file_reference_has_a_meaning(model):
    """Every field of the model and of its sections has a ``name : text`` entry in a docstring the
    reference reads, so no row of its table has an empty meaning."""
    hook = load_reference_hook()
    missing, seen, models = [], set(), [model]
    while models:
        current = models.pop()
        if current in seen:
            continue
        seen.add(current)
        meanings = hook._field_descriptions(current)
        for field, info in current.model_fields.items():
            if not meanings.get(field, "").strip():
                missing.append(f"{current.__name__}.{field}")
            models.extend(hook._nested_models(info.annotation))
    assert not missing, "fields without a meaning: " + ", ".join(missing)


def test_a_marker_of_a_page_is_replaced_by_its_generated_reference():
    hook = load_reference_hook()
    page = "# Scenario files\n\n<!-- generated: scenario -->\n"
    assert "| `frame_rate_hz` |" in hook.on_page_markdown(page)
    assert "<!-- generated:" not in hook.on_page_markdown(page)


def test_every_marker_in_the_docs_names_a_generator():
    names = set(load_reference_hook().GENERATORS)
    for page in DOCS.rglob("*.md"):
        for found in re.finditer(r"<!-- generated: ([a-z-]+) -->", page.read_text(encoding="utf-8")):
            assert found.group(1) in names, (page.relative_to(ROOT), found.group(1))
