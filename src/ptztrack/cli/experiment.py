"""What the experiments' commands share: their cells run on ``--executor`` with a progress bar."""

import argparse

from ptztrack.evaluate.executors import Progress, run_cells


def run_experiment_cells(args: argparse.Namespace, cells: list, run, noun: str = "episode", together=None) -> list:
    """An experiment's cells on ``--executor``, with a progress bar (none with ``--quiet`` or off a terminal);
    ``together`` as :func:`run_cells`'."""
    with Progress(noun, args.quiet) as progress:
        return run_cells(cells, run, args.executor, args.workers, progress, together)
