"""``ptztrack experiment occupancy``: the LPOM paper's people on the ground from several calibrated views,
against clustering."""

import argparse

from ptztrack.builders.occupancy_synthetic import PLAZA_LEAD_IN_FRAMES
from ptztrack.config import load_dataset, pets_dataset
from ptztrack.experiments.occupancy import dataset_runs, format_occupancy_table, plaza_runs, room_runs
from ptztrack.files import InputError, run_folder, write_json
from ptztrack.loop.executors import Progress
from ptztrack.names import PLAZA_FRAMES, ROOM_FRAMES
from ptztrack.occupancy.output import write_occupancy_outputs


def occupancy_experiment_command(args: argparse.Namespace) -> int:
    if args.lead_in is not None and args.dataset != "synthetic-plaza":
        raise InputError(f"experiment occupancy {args.dataset}: --lead-in is an option of synthetic-plaza only")
    with Progress("frame", args.quiet) as progress:
        if args.dataset == "synthetic-room":
            runs = room_runs(args.frames or ROOM_FRAMES, args.seed, progress, args.methods)
        elif args.dataset == "synthetic-plaza":
            lead_in = PLAZA_LEAD_IN_FRAMES if args.lead_in is None else args.lead_in
            runs = plaza_runs(args.frames or PLAZA_FRAMES, args.seed, progress, args.methods, lead_in)
        else:
            dataset = pets_dataset() if args.dataset == "pets" else load_dataset(args.dataset)
            runs = dataset_runs(dataset, args.frames, progress, args.methods)
    rows = [row for run in runs for row in run.rows]
    print(format_occupancy_table(args.dataset, rows))
    written = []
    if args.out is not None:
        with run_folder(args.out, args.overwrite) as folder:
            for run in runs:
                write_occupancy_outputs(folder / str(run.rows[0]["dataset"]), run, args.images_every)
        written.append(args.out)
    if args.json is not None:
        write_json(args.json, rows)
        written.append(args.json)
    if written:
        print(f"wrote {', '.join(str(path) for path in written)}")
    return 0
