"""``ptztrack experiment msg``: the face-capture paper's Figure 7."""

import argparse
import sys

import numpy as np

from ptztrack.evaluate.report import write_figure
from ptztrack.experiments.cells import Execution, run_experiment_cells
from ptztrack.facecapture.experiment import (
    ambiguity_figure,
    format_ambiguity_table,
    format_paired_differences,
    msg_cells,
    run_msg,
    run_msg_cell,
    summarise_by_ambiguity,
    trails_figure,
)
from ptztrack.facecapture.roads import walk_roads
from ptztrack.facecapture.scheduler import SCHEDULERS
from ptztrack.files import write_json


def msg_experiment_command(args: argparse.Namespace) -> int:
    cells = msg_cells(args.runs)
    print(f"{len(cells)} simulations x {len(SCHEDULERS)} schedulers, {args.executor} executor", file=sys.stderr)
    execution = Execution(args.executor, args.workers, args.quiet)
    rows = [row for rows in run_experiment_cells(cells, run_msg_cell, execution, "simulation") for row in rows]
    print("Face capture on the MSG: M by N_j/s bin, mean +- standard deviation (runs)")
    print(format_ambiguity_table(summarise_by_ambiguity(rows)))
    print(format_paired_differences(rows))
    written = []
    if args.json is not None:
        write_json(args.json, rows)
        written.append(args.json)
    if args.plot is not None:
        write_figure(args.plot, ambiguity_figure(rows))
        written.append(args.plot)
    if args.trails is not None:
        cell = cells[0]
        scene = walk_roads(cell.scene, np.random.default_rng(cell.seed))
        run = run_msg(scene, "msg", cell.tracker, cell.zoom_out_score, cell.seed, cell.zoomed_half_width_m)
        title = f"simulation {cell.seed}: {cell.scene.people} walkers, N_j/s {scene.nj_s}, msg scheduler, M {run.m:.2f}"
        write_figure(args.trails, trails_figure(scene, run, title))
        written.append(args.trails)
    if written:
        print(f"wrote {', '.join(str(path) for path in written)}")
    return 0
