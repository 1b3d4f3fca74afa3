"""``ptztrack experiment synthetic`` and ``pets``: the PTZ paper's Tables 1-4."""

import argparse
import os
import sys

from ptztrack.builders.budget import refuse_if_too_large
from ptztrack.builders.experiments import recording_cells, run_cell, shared_views_key, synthetic_cells
from ptztrack.builders.pets import protocol_folds
from ptztrack.cli.experiment import run_experiment_cells
from ptztrack.cli.scenario import build_scenario, command_scenario
from ptztrack.evaluate.tables import format_table, paired_difference, summarise
from ptztrack.files import write_json


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
    title = (
        f"{args.scenario} scene, {scenario.detector.kind} detector, beta {scenario.control.beta:g}, "
        f"detector model {scenario.detector.model} (prior shifted {scenario.detector.prior_shift_px:g} px), "
        f"{args.sequences} sequences of {scenario.frames} frames (means over sequences)"
    )
    model = {"detector_model": scenario.detector.model, "prior_shift_px": scenario.detector.prior_shift_px}
    return _run_table(args, cells, title, extra=model)


def pets_experiment_command(args: argparse.Namespace) -> int:
    scenario = command_scenario(args, "pets")
    folds = protocol_folds(scenario, args.protocol)
    for fold in folds:
        if fold.fitted:
            fitted = ", ".join(f"{name} {value:.4g}" for name, value in fold.fitted.items())
            print(f"fold {fold.index}: fitted on the other half's frames: {fitted}", file=sys.stderr)
    betas = args.beta or [9.0, 1.0]
    cells = [
        cell
        for fold in folds
        for cell in recording_cells(fold.scenario, betas, args.strategies, args.seeds, fold.index)
    ]
    title = (
        f"PETS 2009 S2.L1 View_001, {scenario.detector.kind} detector ({scenario.detector.model} model), every 2nd "
        f"frame, protocol {args.protocol}, "
        f"{args.seeds} seeds where a run depends on its seed (MOTA +- standard deviation over seeds and folds)"
    )
    extra = {
        "protocol": args.protocol,
        "fitted": [fold.fitted for fold in folds],
        "detector_model": scenario.detector.model,
    }
    return _run_table(args, cells, title, "mota_sd", extra, together=shared_views_key)


def _run_table(
    args: argparse.Namespace,
    cells: list,
    title: str,
    spread: str = "mota_se",
    extra: dict | None = None,
    together=None,
) -> int:
    """The cells run and printed as a table of means over the runs (``spread``: the figure after +-), smpl
    against intg paired where both ran on several sequences; ``extra`` is added to every row (``--json``)."""
    print(f"{len(cells)} episodes, {args.executor} executor", file=sys.stderr)
    runs_at_once = 1 if args.executor == "serial" else min(len(cells), args.workers or os.cpu_count() or 1)
    refuse_if_too_large(cells[0].scenario, tuple(args.strategies), runs_at_once)
    summary = summarise(run_experiment_cells(args, cells, run_cell, together=together))
    summary = [{**row, **(extra or {})} for row in summary]
    print(format_table(summary, title, spread))
    labels = {row["label"] for row in summary}
    if {"smpl", "intg"} <= labels and summary[0]["sequences"] > 1:
        mean, error, count = paired_difference(summary, "smpl", "intg")
        paired = f"paired over {count} sequences, standard error"
        print(f"smpl - intg: {100 * mean:+.1f} +- {100 * error:.1f} MOTA points ({paired})")
    if args.json is not None:
        write_json(args.json, summary)
        print(f"wrote {args.json}")
    return 0
