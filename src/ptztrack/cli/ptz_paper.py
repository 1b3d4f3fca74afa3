"""``ptztrack experiment synthetic`` and ``pets``: the PTZ paper's Tables 1-4."""

import argparse
import sys

from ptztrack.cli.scenario import build_scenario, command_scenario
from ptztrack.experiments.cells import Execution
from ptztrack.experiments.ptz_tables import (
    format_report,
    protocol_folds,
    recording_cells,
    recording_title,
    run_table,
    shared_views_key,
    synthetic_cells,
    synthetic_title,
)
from ptztrack.files import write_json
from ptztrack.names import PetsProtocol


def synthetic_experiment_command(args: argparse.Namespace) -> int:
    scenario = build_scenario(
        args.scenario,
        args.detector,
        args.frames,
        association=args.association,
        measurement_source=None,
        detector_model=args.detector_model,
        prior_shift_px=args.prior_shift_px,
    )
    cells = synthetic_cells(scenario, args.sequences, args.strategies)
    title = synthetic_title(args.scenario, scenario, args.sequences)
    model = {"detector_model": scenario.detector.model, "prior_shift_px": scenario.detector.prior_shift_px}
    return _print_table(args, cells, title, extra=model)


def pets_experiment_command(args: argparse.Namespace) -> int:
    scenario = command_scenario(args, "pets")
    folds = protocol_folds(scenario, args.protocol)
    for fold in folds:
        if fold.fitted:
            fitted = ", ".join(f"{name} {value:.4g}" for name, value in fold.fitted.items())
            print(f"fold {fold.index}: fitted on the other half's frames: {fitted}", file=sys.stderr)
    betas = args.beta or list(PetsProtocol.betas)
    cells = [
        cell
        for fold in folds
        for cell in recording_cells(fold.scenario, betas, args.strategies, args.seeds, fold.index)
    ]
    title = recording_title(scenario, args.protocol, args.seeds)
    extra = {
        "protocol": args.protocol,
        "fitted": [fold.fitted for fold in folds],
        "detector_model": scenario.detector.model,
    }
    return _print_table(args, cells, title, "mota_sd", extra, together=shared_views_key)


def _print_table(
    args: argparse.Namespace,
    cells: list,
    title: str,
    spread: str = "mota_se",
    extra: dict | None = None,
    together=None,
) -> int:
    """The table of the cells (:func:`ptztrack.experiments.ptz_tables.run_table`) printed with ``spread`` after
    +- (:func:`~ptztrack.experiments.ptz_tables.format_report`); ``extra`` is added to every row (``--json``)."""
    print(f"{len(cells)} episodes, {args.executor} executor", file=sys.stderr)
    execution = Execution(args.executor, args.workers, args.quiet)
    summary = run_table(cells, args.strategies, execution, together)
    summary = [{**row, **(extra or {})} for row in summary]
    print(format_report(summary, title, spread))
    if args.json is not None:
        write_json(args.json, summary)
        print(f"wrote {args.json}")
    return 0
