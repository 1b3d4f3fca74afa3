"""``ptztrack experiment network synthetic`` and ``pets``: a camera network's table."""

import argparse
import sys

from ptztrack.cli.scenario import build_scenario
from ptztrack.config import ScenarioError
from ptztrack.experiments.cells import Execution
from ptztrack.experiments.network import format_network_table, network_cells, network_title, run_network_table
from ptztrack.files import write_json
from ptztrack.names import NetworkProtocol

# The options of one setting only, and their defaults.
SYNTHETIC_OPTIONS = {name: getattr(NetworkProtocol, name) for name in ("sequences", "first_sequence", "max_ptz")}
PETS_OPTIONS = {"seeds": NetworkProtocol.seeds, "beta": NetworkProtocol.beta, "dataset": None, "dataset_view": None}


def network_experiment_command(args: argparse.Namespace) -> int:
    mine, theirs = (PETS_OPTIONS, SYNTHETIC_OPTIONS) if args.setting == "pets" else (SYNTHETIC_OPTIONS, PETS_OPTIONS)
    for name in theirs:
        if getattr(args, name) is not None:
            option = "--" + name.replace("_", "-")
            raise ScenarioError(f"experiment network {args.setting}: {option} is an option of the other setting")
    for name, default in mine.items():
        if getattr(args, name) is None:
            setattr(args, name, default)
    if args.setting == "pets":
        return _pets_command(args)
    scenario = build_scenario(
        "synthetic", args.detector or "realistic", args.frames, detector_model=args.detector_model, prior_shift_px=None
    )
    cells = network_cells(scenario, args.sequences, args.max_ptz, args.method, args.first_sequence)
    print(f"{len(cells)} episodes, {args.executor} executor", file=sys.stderr)
    summary = run_network_table(cells, Execution(args.executor, args.workers, args.quiet))
    print(format_network_table(summary, network_title(scenario, args.sequences, args.method, args.first_sequence)))
    return _write(args, summary)


def _pets_command(args: argparse.Namespace) -> int:
    from ptztrack.builders.pets_network import PUBLISHED_RECALL, published_views
    from ptztrack.experiments.pets_network import (
        format_pets_network_table,
        pets_network_cells,
        pets_network_title,
        run_pets_network_table,
    )

    scenario = build_scenario(
        "pets",
        args.detector or "hog",
        args.frames,
        detector_model=args.detector_model,
        dataset=args.dataset,
        view=args.dataset_view,
    )
    scenario = scenario.model_copy(update={"control": scenario.control.model_copy(update={"beta": args.beta})})
    cells = pets_network_cells(scenario, published_views(scenario), args.seeds, args.method)
    print(f"{len(cells)} episodes, {args.executor} executor", file=sys.stderr)
    summary = run_pets_network_table(cells, Execution(args.executor, args.workers, args.quiet))
    print(format_pets_network_table(summary, pets_network_title(scenario, args.seeds, args.method, PUBLISHED_RECALL)))
    return _write(args, [{**row, "fixed_recall": PUBLISHED_RECALL} for row in summary])


def _write(args: argparse.Namespace, summary: list[dict]) -> int:
    if args.json is not None:
        write_json(args.json, summary)
        print(f"wrote {args.json}")
    return 0
