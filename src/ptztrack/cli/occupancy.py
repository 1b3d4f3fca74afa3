"""``ptztrack experiment occupancy``: the LPOM paper's people on the ground from several calibrated views,
against clustering."""

import argparse

from ptztrack.builders.occupancy import dataset_runs, room_runs
from ptztrack.config import load_dataset, pets_dataset
from ptztrack.evaluate.executors import Progress
from ptztrack.files import run_folder, write_json
from ptztrack.names import ROOM_FRAMES
from ptztrack.occupancy.output import write_occupancy_outputs

OCCUPANCY_COLUMNS = (
    ("method", "{}"),
    ("people", "{}"),
    ("moda", "{:.1%}"),
    ("modp", "{:.1%}"),
    ("precision", "{:.1%}"),
    ("recall", "{:.1%}"),
    ("error_m", "{:.3f}"),
    ("mota", "{:.1%}"),
    ("motp_m", "{:.3f}"),
    ("idf1", "{:.1%}"),
)


def occupancy_experiment_command(args: argparse.Namespace) -> int:
    with Progress("frame", args.quiet) as progress:
        if args.dataset == "synthetic-room":
            runs = room_runs(args.frames or ROOM_FRAMES, args.seed, progress)
        else:
            dataset = pets_dataset() if args.dataset == "pets" else load_dataset(args.dataset)
            runs = dataset_runs(dataset, args.frames, progress)
    rows = [row for run in runs for row in run.rows]
    columns = [(key, form) for key, form in OCCUPANCY_COLUMNS if any(key in row for row in rows)]
    print(f"Occupancy-map detection on {args.dataset}: MODA, MODP, precision, recall within 0.5 m; tracker fed by LPOM")
    print("  ".join(f"{key:>10}" for key, _ in columns))
    for row in rows:
        print("  ".join(f"{form.format(row[key]) if key in row else '':>10}" for key, form in columns))
    for row in rows:
        fitted = {key: value for key, value in row.items() if key.startswith("fitted_")}
        print(f"{row['dataset']} {row['method']}: {fitted} (each half of the frames scored with the other's fit)")
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
