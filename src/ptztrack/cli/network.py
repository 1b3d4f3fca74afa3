"""``ptztrack experiment network synthetic``: a camera network's table."""

import argparse
import sys

from ptztrack.cli.scenario import build_scenario
from ptztrack.experiments.cells import Execution
from ptztrack.experiments.network import format_network_table, network_cells, network_title, run_network_table
from ptztrack.files import write_json


def network_experiment_command(args: argparse.Namespace) -> int:
    scenario = build_scenario(
        "synthetic", args.detector, args.frames, detector_model=args.detector_model, prior_shift_px=None
    )
    cells = network_cells(scenario, args.sequences, args.max_ptz, args.method)
    print(f"{len(cells)} episodes, {args.executor} executor", file=sys.stderr)
    summary = run_network_table(cells, Execution(args.executor, args.workers, args.quiet))
    print(format_network_table(summary, network_title(scenario, args.sequences, args.method)))
    if args.json is not None:
        write_json(args.json, summary)
        print(f"wrote {args.json}")
    return 0
