"""Writes the results pages from their templates and the JSON their commands wrote.

    python docs/build_results.py           # writes docs/results/<page>.md
    python docs/build_results.py --check   # exits 1, naming the pages that differ, unless they are up to date

A page ``docs/results/<page>.md`` is its template ``docs/results/templates/<page>.md.in`` with every
``{{ name }}`` replaced: ``{{ command:RUN }}`` by the command of run ``RUN`` in ``data/runs.json`` (a
``bash`` block marked not-run, with its measured wall time), any other name by the page's field of
that name, computed from ``docs/results/data/*.json`` as the commands wrote them by the page's module
in ``docs/results_build/`` (beside the site's pages, excluded from it by mkdocs.yml). A template
naming a field its page does not compute, or a page computing a field its template does not use,
is an error: every figure on a page comes from a stored JSON file.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

RESULTS = Path(__file__).resolve().parent / "results"
TEMPLATES = RESULTS / "templates"
DATA = RESULTS / "data"
PLACEHOLDER = re.compile(r"\{\{\s*([A-Za-z0-9_:.\-]+)\s*\}\}")
GENERATED_NOTE = "<!-- Written by docs/build_results.py from templates/{page}.md.in and data/: edit those. -->\n"

# The tests load this file by its path, so docs/ need not be on the import path already.
sys.path.insert(0, str(Path(__file__).resolve().parent))
from results_build import (  # noqa: E402
    Load,
    camera_network,
    face_capture,
    follow_camera,
    formatting,
    information_gain,
    live,
    long_runs,
    occupancy_map,
    registration,
    speed,
)


def load(name: str) -> Any:
    """The JSON file ``data/<name>.json``."""
    return json.loads((DATA / f"{name}.json").read_text())


# The index: a headline figure per system, each from its page's JSON.

HEADLINES = (
    information_gain,
    face_capture,
    registration,
    follow_camera,
    occupancy_map,
    camera_network,
    live,
    long_runs,
)


def index_fields(load: Load) -> dict[str, str]:
    return {"headline_table": formatting.table(["system", "headline"], [page.headline(load) for page in HEADLINES])}


PAGES: dict[str, Callable[[Load], dict[str, str]]] = {
    "index": index_fields,
    "information-gain": information_gain.fields,
    "face-capture": face_capture.fields,
    "long-runs": long_runs.fields,
    "camera-network": camera_network.fields,
    "occupancy-map": occupancy_map.fields,
    "follow-camera": follow_camera.fields,
    "registration": registration.fields,
    "live": live.fields,
    "speed": speed.fields,
}


def command_block(run: str, runs: dict) -> str:
    """The command of ``run`` as a ``bash`` block, marked not-run with its measured time."""
    entry = runs[run]
    seconds = entry["wall_s"]
    took = f"{round(seconds / 10) * 10:.0f} seconds" if seconds < 90 else f"{round(seconds / 60):.0f} minutes"
    return f"<!-- not-run: reproduces this table, about {took} on 2 cores -->\n```bash\n{entry['command']}\n```"


def render(page: str) -> str:
    """Page ``page`` as the build writes it."""
    template = (TEMPLATES / f"{page}.md.in").read_text()
    fields = PAGES[page](load)
    runs = load("runs")
    used = set()

    def replace(match: re.Match) -> str:
        name = match.group(1)
        if name.startswith("command:"):
            return command_block(name.removeprefix("command:"), runs)
        if name not in fields:
            raise KeyError(f"templates/{page}.md.in names {{{{ {name} }}}}, which the page does not compute")
        used.add(name)
        return fields[name]

    text = PLACEHOLDER.sub(replace, template)
    unused = sorted(set(fields) - used)
    if unused:
        raise KeyError(f"templates/{page}.md.in does not use the page's fields {', '.join(unused)}")
    return GENERATED_NOTE.format(page=page) + text


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true", help="write nothing; exit 1 if a page differs")
    args = parser.parse_args(argv)
    differing = []
    for page in PAGES:
        text = render(page)
        path = RESULTS / f"{page}.md"
        if args.check:
            if not path.exists() or path.read_text() != text:
                differing.append(path)
        elif not path.exists() or path.read_text() != text:
            path.write_text(text)
            print(f"wrote {path}")
    if differing:
        names = ", ".join(str(path.relative_to(RESULTS.parent.parent)) for path in differing)
        print(f"not what docs/build_results.py writes: {names}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
