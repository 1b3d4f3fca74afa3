"""The occupancy-map detectors' speed on one core: frames per second for 4 views of 1024 x 768.

Renders the synthetic room (3 people, the paper's lab: 4 corner cameras, 1024 x 768, 15 Hz) ahead
of time, then times LPOM on each frame, single-threaded: motion edges of the 4 views (Canny and the
frame difference), the summed loci through the precomputed locus tables, the normalised and
smoothed map, and its modes. Rendering is not timed (a camera delivers the frames). The tables'
one-off build time and memory are reported apart.

Then POM (Fleuret et al.) on the same frames with the foreground masks given (each frame against the
empty room, not timed): the masks reduced to the working resolution, the mean-field iterations and
the candidates (``pom_frames_per_s``); the rectangles' one-off computation is reported apart.

    python benchmarks/occupancy_speed.py [--frames 40] [--json PATH]
"""

import os

for variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[variable] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

from ptztrack.builders.occupancy_synthetic import ROOM, room_recording  # noqa: E402
from ptztrack.files import write_atomically  # noqa: E402
from ptztrack.occupancy.detectors import LpomDetector, lpom_parameters  # noqa: E402
from ptztrack.occupancy.lpom import map_modes, occupancy_map, table_map  # noqa: E402
from ptztrack.occupancy.motion_edges import motion_edges  # noqa: E402
from ptztrack.occupancy.multiview import CameraView  # noqa: E402
from ptztrack.occupancy.parameters import OccupancyParameters, PomParameters  # noqa: E402
from ptztrack.occupancy.pom import PomDetector  # noqa: E402
from ptztrack.occupancy.room import RoomRenderer  # noqa: E402

# Grey levels a pixel must differ from the empty room by to be foreground (the sensor noise's sigma is 2).
FOREGROUND_LEVELS = 25


def main() -> None:
    arguments = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    arguments.add_argument("--frames", type=int, default=40, help="frames timed (one more is rendered first)")
    arguments.add_argument("--json", type=Path, help="write the figures here")
    args = arguments.parse_args()
    cv2.setNumThreads(1)

    recording = room_recording(people=3, frames=args.frames + 1, seed=0)
    images = [[view.frames(frame) for view in recording.views] for frame in range(recording.frames)]
    assert recording.truth is not None
    # The same room's renderer (same seed) for its empty backgrounds.
    backgrounds = RoomRenderer(ROOM, recording.truth, seed=0).backgrounds
    views = tuple(
        CameraView(view.name, view.calibration, view.image_size_px, images_of(images, index), None)
        for index, view in enumerate(recording.views)
    )
    recording = type(recording)(
        recording.name, views, recording.frames, recording.frame_rate_hz, recording.area_m, None
    )
    parameters = lpom_parameters(OccupancyParameters())
    start = time.perf_counter()
    detector = LpomDetector(recording, parameters)
    build_s = time.perf_counter() - start
    table_mb = sum(table.megabytes for table in detector.tables.values())
    detector.detect(0)

    per_frame_s = []
    for frame in range(1, recording.frames):
        start = time.perf_counter()
        detector.detect(frame)
        per_frame_s.append(time.perf_counter() - start)

    # The same work split into its stages, on the same frames.
    stages = {"edges": 0.0, "loci": 0.0, "map_and_modes": 0.0}
    motion_pixels = []
    for frame in range(1, recording.frames):
        start = time.perf_counter()
        masks = [motion_edges(images[frame - 1][v], images[frame][v], parameters.edges) for v in range(len(views))]
        edges = time.perf_counter()
        loci = [table_map(detector.tables[v], mask) for v, mask in enumerate(masks)]
        summed = time.perf_counter()
        pom = occupancy_map(loci, [1.0] * len(views), detector.grid, parameters.kernel_sigma_m)
        map_modes(pom, detector.grid, parameters.separation_m, parameters.window_m, parameters.candidate_strength)
        done = time.perf_counter()
        stages["edges"] += edges - start
        stages["loci"] += summed - edges
        stages["map_and_modes"] += done - summed
        motion_pixels.append([int(mask.sum()) for mask in masks])

    frames = len(per_frame_s)
    figures = {
        "frames_per_s": frames / sum(per_frame_s),
        "ms_per_frame_median": 1000 * float(np.median(per_frame_s)),
        "ms_per_frame_p90": 1000 * float(np.percentile(per_frame_s, 90)),
        "stages_ms_per_frame": {name: 1000 * seconds / frames for name, seconds in stages.items()},
        "motion_pixels_per_view_mean": float(np.mean(motion_pixels)),
        "views": len(views),
        "image_size_px": list(views[0].image_size_px),
        "grid_cells": list(detector.grid.shape),
        "table_build_s": build_s,
        "table_mb": table_mb,
        "frames": frames,
    }
    print(
        f"LPOM, {len(views)} views of {views[0].image_size_px[0]} x {views[0].image_size_px[1]}, one thread: "
        f"{figures['frames_per_s']:.1f} frames/s (median {figures['ms_per_frame_median']:.1f} ms, "
        f"p90 {figures['ms_per_frame_p90']:.1f} ms per frame over {frames} frames)"
    )
    print("  stages [ms/frame]: " + ", ".join(f"{k} {v:.1f}" for k, v in figures["stages_ms_per_frame"].items()))
    print(f"  motion pixels per view: {figures['motion_pixels_per_view_mean']:.0f} on average")
    print(f"  locus tables: {build_s:.1f} s to build once, {table_mb:.0f} MB for the {len(detector.tables)} views")
    figures.update(time_pom(recording, images, backgrounds))
    print(
        f"POM, the same views and frames, masks given, one thread: {figures['pom_frames_per_s']:.1f} frames/s "
        f"(median {figures['pom_ms_per_frame_median']:.1f} ms, p90 {figures['pom_ms_per_frame_p90']:.1f} ms per "
        f"frame; {figures['pom_iterations_mean']:.0f} iterations on average, {figures['pom_unconverged']} frames "
        f"stopped at the maximum)"
    )
    print(
        f"  {figures['pom_cells']} cells, working images {figures['pom_working_px'][0]} x "
        f"{figures['pom_working_px'][1]}; rectangles: {figures['pom_rectangles_s']:.1f} s to compute once"
    )
    if args.json is not None:
        write_atomically(args.json, (json.dumps(figures, indent=2) + "\n").encode())
        print(f"wrote {args.json}")


def time_pom(recording, images: list, backgrounds: list) -> dict:
    """POM's figures on frames 1 onwards (LPOM's frames): per frame, the masks' reduction to the working
    resolution, the mean-field iterations and the candidates, with the masks computed beforehand."""
    start = time.perf_counter()
    detector = PomDetector(recording, PomParameters())
    rectangles_s = time.perf_counter() - start
    per_frame_s, iterations, unconverged = [], [], 0
    for frame in range(1, recording.frames):
        masks = [
            cv2.absdiff(image, background).max(axis=2) > FOREGROUND_LEVELS
            for image, background in zip(images[frame], backgrounds, strict=True)
        ]
        start = time.perf_counter()
        detector.detect(frame, masks)
        per_frame_s.append(time.perf_counter() - start)
        assert detector.last is not None
        iterations.append(detector.last.iterations)
        unconverged += not detector.last.converged
    shape = detector.boxes.shapes[0]
    return {
        "pom_frames_per_s": len(per_frame_s) / sum(per_frame_s),
        "pom_ms_per_frame_median": 1000 * float(np.median(per_frame_s)),
        "pom_ms_per_frame_p90": 1000 * float(np.percentile(per_frame_s, 90)),
        "pom_iterations_mean": float(np.mean(iterations)),
        "pom_unconverged": unconverged,
        "pom_cells": detector.grid.cells,
        "pom_working_px": [shape[1], shape[0]],
        "pom_rectangles_s": rectangles_s,
    }


def images_of(images: list, view: int):
    return lambda frame: images[frame][view]


if __name__ == "__main__":
    main()
