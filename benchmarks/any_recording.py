"""Any recording: render one of a geometry drawn at random and run the PTZ table on it.

The geometry is drawn from ranges a surveillance camera meets (``--seed`` fixes every draw): an image of
640 x 480 to 1280 x 720 px, 6 to 25 frames per second, an area of 10 to 30 m a side, one camera 3 to 10 m
up somewhere along one of its sides with a horizontal field of view of 60 to 100 degrees, aimed at the
area's centre, and 3 to 12 walkers. ``ptztrack render`` writes it as a dataset file, and the PTZ paper's
table (``fix``, ``intg``, ``smpl``, a priori) runs on it through ``dataset_scenario`` with no code that
knows which recording it is. It prints the table and, with ``--json``, writes ``rows`` (strategy,
mota, ...) and ``recording`` (size, fps, camera position, people, area).

    python benchmarks/any_recording.py [--seed 0] [--detector ideal|hog] [--seconds 12] [--json PATH]
"""

import argparse
import logging
import math
import sys
import tempfile
from pathlib import Path

import numpy as np

from ptztrack.builders.recording import TABLES_PROTOCOL, dataset_scenario
from ptztrack.builders.render import render_dataset
from ptztrack.config import load_dataset, scenario_from_dict
from ptztrack.experiments.cells import Execution
from ptztrack.experiments.ptz_tables import format_table, recording_cells, recording_title, run_table
from ptztrack.files import write_json

IMAGE_SIZES_PX = ((640, 480), (800, 600), (960, 540), (1024, 576), (1280, 720))
FRAME_RATES_HZ = (6.0, 7.5, 10.0, 12.5, 15.0, 25.0)
STRATEGIES = ("fix", "intg", "smpl")


def random_geometry(rng: np.random.Generator, seconds: float) -> dict:
    """A scenario mapping of a random recording (see the module's docstring)."""
    width_px, height_px = IMAGE_SIZES_PX[rng.integers(len(IMAGE_SIZES_PX))]
    frame_rate_hz = float(FRAME_RATES_HZ[rng.integers(len(FRAME_RATES_HZ))])
    area_m = rng.uniform(10.0, 30.0, 2).round(1)
    side = rng.integers(4)
    along = rng.uniform(0.2, 0.8)
    edge_points = (
        (along * area_m[0], 0.0),
        (area_m[0], along * area_m[1]),
        (along * area_m[0], area_m[1]),
        (0.0, along * area_m[1]),
    )
    x_m, y_m = edge_points[side]
    height_m = rng.uniform(3.0, 10.0)
    field_of_view_deg = rng.uniform(60.0, 100.0)
    f_px = width_px / 2 / math.tan(math.radians(field_of_view_deg) / 2)
    return {
        "area_m": [float(area_m[0]), float(area_m[1])],
        "frames": int(round(seconds * frame_rate_hz)),
        "frame_rate_hz": frame_rate_hz,
        "people": {"count": int(rng.integers(3, 13))},
        "camera": {
            "position_m": [round(float(x_m), 2), round(float(y_m), 2), round(float(height_m), 2)],
            "image_size_px": [int(width_px), int(height_px)],
            "f_min_px": round(float(f_px), 1),
        },
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0, help="draws the geometry, the walkers and the rendering")
    parser.add_argument("--detector", choices=("ideal", "hog"), default="ideal")
    parser.add_argument("--seconds", type=float, default=12.0, help="the recording's length")
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--keep", type=Path, help="keep the rendered dataset in this folder")
    parser.add_argument("--json", type=Path, help="write rows and recording here")
    args = parser.parse_args()
    logging.basicConfig(format="%(message)s", level=logging.WARNING)
    geometry = random_geometry(np.random.default_rng(args.seed), args.seconds)
    scene = scenario_from_dict(geometry, "any recording")
    with tempfile.TemporaryDirectory() as scratch:
        folder = args.keep or Path(scratch) / "recording"
        dataset_file = render_dataset(scene, folder, seed=args.seed, overwrite=args.keep is not None)
        scenario = dataset_scenario(
            load_dataset(dataset_file), None, TABLES_PROTOCOL, dataset_file, **{"detector.kind": args.detector}
        )
        cells = recording_cells(scenario, [scenario.control.beta], STRATEGIES)
        print(f"{len(cells)} episodes on {folder}", file=sys.stderr)
        summary = run_table(cells, STRATEGIES, Execution("local", args.workers, True))
    print(format_table(summary, recording_title(scenario, "a-priori", 1)))
    recording = {
        "image_size_px": geometry["camera"]["image_size_px"],
        "frame_rate_hz": geometry["frame_rate_hz"],
        "camera_position_m": geometry["camera"]["position_m"],
        "f_px": geometry["camera"]["f_min_px"],
        "area_m": geometry["area_m"],
        "people": geometry["people"]["count"],
        "frames": geometry["frames"],
        "steps": scenario.frames,
        "step_rate_hz": scenario.frame_rate_hz,
        "seed": args.seed,
        "detector": args.detector,
    }
    print(f"recording: {recording}")
    if args.json is not None:
        write_json(args.json, {"rows": summary, "recording": recording})
        print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
