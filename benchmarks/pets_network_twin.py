"""A synthetic twin of the PETS camera network: its cameras over synthetic walkers, with exact truth.

`ptztrack experiment network pets` is the only data with a camera network,
so a form of its fixed cameras chosen on it would be chosen on the table it
is scored by. This twin is the data to choose on instead. S2.L1's seven
calibrated cameras watch ``--people`` walkers on the plaza's area (the
occupancy experiment's layout), 398 steps at 5 Hz, seeds from 1000 (the
PETS run's are 0-4). The PTZ camera is View_001's virtual one, as in the
PETS run, with the simulated detector of a HOG-like curve (r0 16 px, HOG's
96 px person over its 6x upsampling; Kd 0.1 per px; 0.1 false positives a
view) and the PETS run's detector-model prior. Each other view is a fixed
camera of boxes made from the walkers through the view's true calibration
(found with probability 0.9 times the share not hidden by nearer walkers,
3 px of noise on feet and head, 0.1 ghost boxes a frame at a random point
of the area), which its tracker reads through a calibration turned by
N(0, sigma) about each axis: the views' disagreement of the real one.
The fixed cameras' tracker is the PETS network's
(:func:`ptztrack.builders.pets_network.published_network_parts`);
``--report-single-view-tracks`` also reports the tracks one fixed view
alone has detected (``SharedBelief.needs_a_second_camera`` empty).

It prints MOTA (scored inside View_001's walkable area, as the PETS table
is) per configuration and calibration error, and per seed.

    python benchmarks/pets_network_twin.py [--seeds 8] [--sigmas-deg 0 0.25 0.5] [--people 8]
                                           [--configs ptz 6fixed ptz+6fixed] [--report-single-view-tracks]
                                           [--workers 2] [--json PATH]
"""

import argparse
from dataclasses import dataclass, replace
from pathlib import Path

import cv2
import numpy as np

from ptztrack.builders.occupancy_synthetic import plaza_layout
from ptztrack.builders.pets_network import published_camera_world, published_network_parts, published_views
from ptztrack.builders.recording import pets_scenario
from ptztrack.builders.world import BuiltScene, build_scene, camera_world, detector_model
from ptztrack.evaluate.metrics import tracking_metrics, tracks_within
from ptztrack.files import write_json
from ptztrack.geometry.calibration import PinholeCalibration, camera_centre_m, project_pinhole
from ptztrack.geometry.occlusion import occluded_fraction
from ptztrack.loop.executors import execute_cells
from ptztrack.loop.simulated import NetworkWorld, run_network_loop
from ptztrack.loop.streams import episode_streams
from ptztrack.occupancy.multiview import CameraView
from ptztrack.occupancy.plaza import plaza_truth
from ptztrack.types import GroundTruth

FIRST_SEED = 1000
PTZ_RECALL_KD_PER_PX, PTZ_RECALL_R0_PX, PTZ_FALSE_POSITIVES = 0.1, 16.0, 0.1
FIXED_RECALL, BOX_NOISE_PX, GHOSTS_PER_FRAME, GHOST_HEIGHT_M = 0.9, 3.0, 0.1, 1.75
BOX_WIDTH_PER_HEIGHT = 0.41
MM_PER_M = 1000.0


@dataclass(frozen=True)
class TwinCell:
    """One episode: configuration ``config`` ('ptz', '6fixed' or 'ptz+6fixed') on the walkers of ``seed``,
    the fixed views' calibrations turned by N(0, ``sigma_deg``)."""

    config: str
    seed: int
    sigma_deg: float
    people: int
    report_single_view_tracks: bool


def turned_calibration(calibration: PinholeCalibration, sigma_deg: float, rng: np.random.Generator):
    """``calibration`` turned about its optical centre by N(0, sigma_deg) about each axis."""
    error = cv2.Rodrigues(np.deg2rad(rng.normal(0.0, sigma_deg, 3)))[0]
    centre_mm = camera_centre_m(calibration) * MM_PER_M
    rotation = error @ calibration.R
    return replace(calibration, R=rotation, t=-rotation @ centre_mm)


def walker_boxes(truth: GroundTruth, calibration: PinholeCalibration, size_px, rng: np.random.Generator):
    """Per step, the boxes (K, 5) ``(left, top, width, height, score)`` px a detector finds of the walkers
    in the calibrated view of ``size_px`` (width, height), and its ghosts (see the module's docstring)."""
    (x0, y0), (x1, y1) = plaza_layout().area_m
    width_px, height_px = size_px
    centre_mm = camera_centre_m(calibration) * MM_PER_M
    boxes = []
    for positions_m in truth.positions_m:
        present = np.all(np.isfinite(positions_m), axis=1)
        ground_mm = np.c_[positions_m[present] * MM_PER_M, np.zeros(int(present.sum()))]
        heads_mm = ground_mm + np.c_[np.zeros((len(ground_mm), 2)), truth.heights_m[present] * MM_PER_M]
        ghosts = rng.poisson(GHOSTS_PER_FRAME)
        ghost_mm = np.c_[rng.uniform(x0, x1, ghosts), rng.uniform(y0, y1, ghosts), np.zeros(ghosts)] * MM_PER_M
        ghost_heads_mm = ghost_mm + [0.0, 0.0, GHOST_HEIGHT_M * MM_PER_M]
        feet = project_pinhole(calibration, np.concatenate([ground_mm, ghost_mm]))
        heads = project_pinhole(calibration, np.concatenate([heads_mm, ghost_heads_mm]))
        tall_px = feet[:, 1] - heads[:, 1]
        inside = (heads[:, 1] >= 0) & (feet[:, 1] <= height_px) & (feet[:, 0] >= 0) & (feet[:, 0] <= width_px)
        inside &= tall_px > 0
        half_px = BOX_WIDTH_PER_HEIGHT * tall_px / 2
        outline = np.stack([feet[:, 0] - half_px, heads[:, 1], feet[:, 0] + half_px, feet[:, 1]], axis=-1)
        walkers = len(ground_mm)
        hidden = np.zeros(len(feet))
        hidden[:walkers] = occluded_fraction(
            outline[:walkers], np.linalg.norm(ground_mm - centre_mm, axis=1), inside[:walkers]
        )
        recall = np.where(np.arange(len(feet)) < walkers, FIXED_RECALL, 1.0)
        found = inside & (rng.random(len(feet)) < recall * (1 - hidden))
        feet_px = feet[found] + rng.normal(0.0, BOX_NOISE_PX, (int(found.sum()), 2))
        top_px = heads[found, 1] + rng.normal(0.0, BOX_NOISE_PX, int(found.sum()))
        tall_px = feet_px[:, 1] - top_px
        kept = tall_px > 0
        feet_px, top_px, tall_px = feet_px[kept], top_px[kept], tall_px[kept]
        width = BOX_WIDTH_PER_HEIGHT * tall_px
        boxes.append(np.stack([feet_px[:, 0] - width / 2, top_px, width, tall_px, np.ones(len(tall_px))], axis=-1))
    return boxes


def twin_episode(cell: TwinCell) -> dict:
    """One episode of the twin: the metrics of its tracks inside View_001's walkable area."""
    pets = pets_scenario("hog")
    scenario = pets.model_copy(
        update={
            "detector": pets.detector.model_copy(update={"kind": "realistic"}),
            "control": pets.control.model_copy(update={"beta": 9.0}),
        }
    )
    simulated = scenario.model_copy(
        update={
            "detector": scenario.detector.model_copy(
                update={
                    "recall_kd": PTZ_RECALL_KD_PER_PX,
                    "recall_r0_px": PTZ_RECALL_R0_PX,
                    "false_positives_per_frame": PTZ_FALSE_POSITIVES,
                }
            )
        }
    )
    streams = episode_streams(cell.seed)
    recorded = build_scene(pets, np.random.default_rng(streams.scene))
    at_step_rate = replace(plaza_layout(), frame_rate_hz=scenario.frame_rate_hz)
    truth = plaza_truth(at_step_rate, cell.people, scenario.frames, cell.seed)
    scene = BuiltScene(recorded.camera, recorded.grid, truth, recorded.area_polygon_m)
    ptz = cell.config != "6fixed"
    worlds = []
    if ptz:
        world = camera_world(simulated, scene, "simulated", "realistic", streams.tracker, streams.detector_model)
        worlds.append(replace(world, detector_model=detector_model(scenario, scene.camera, streams.detector_model)))
    if cell.config != "ptz":
        rng = np.random.default_rng([cell.seed, 1])
        views = published_views(pets)
        for view, model_seed in zip(views, streams.detector_model.spawn(len(views)), strict=True):
            boxes = walker_boxes(truth, view.calibration, view.image_size_px, rng)
            turned = turned_calibration(view.calibration, cell.sigma_deg, rng)
            believed = CameraView(view.name, turned, view.image_size_px, None, boxes)
            worlds.append(published_camera_world(scenario, scene, believed, np.arange(scenario.frames), model_seed))
    network = NetworkWorld(tuple(worlds))
    policy, tracker = published_network_parts(scenario, network, ptz)
    if cell.report_single_view_tracks:
        tracker.needs_a_second_camera = frozenset()
    episode = run_network_loop(network, policy, tracker, cell.seed)
    return tracking_metrics(episode.truth, tracks_within(episode.tracks, episode.area_polygon_m))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=8)
    parser.add_argument("--sigmas-deg", type=float, nargs="+", default=[0.0, 0.25, 0.5])
    parser.add_argument("--people", type=int, default=8)
    configs = ["ptz", "6fixed", "ptz+6fixed"]
    parser.add_argument("--configs", nargs="+", choices=configs, default=configs)
    parser.add_argument("--report-single-view-tracks", action="store_true")
    parser.add_argument("--workers", type=int)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    cells = [
        TwinCell(config, FIRST_SEED + index, sigma_deg, args.people, args.report_single_view_tracks)
        for sigma_deg in args.sigmas_deg
        for config in args.configs
        for index in range(args.seeds)
    ]
    metrics = execute_cells(cells, twin_episode, "local", args.workers)
    rows = []
    for sigma_deg in args.sigmas_deg:
        for config in args.configs:
            mine = [
                scored
                for cell, scored in zip(cells, metrics, strict=True)
                if (cell.config, cell.sigma_deg) == (config, sigma_deg)
            ]
            mota = [scored["mota"] for scored in mine]
            row = {
                "config": config,
                "sigma_deg": sigma_deg,
                "mota": float(np.mean(mota)),
                "mota_per_seed": mota,
                "false_positives": float(np.mean([scored["false_positives"] for scored in mine])),
                "misses": float(np.mean([scored["misses"] for scored in mine])),
            }
            rows.append(row)
            per_seed = " ".join(f"{100 * value:.1f}" for value in mota)
            print(
                f"sigma {sigma_deg:4.2f} deg  {config:<11} MOTA {100 * row['mota']:5.1f} %  "
                f"FP {row['false_positives']:6.1f}  misses {row['misses']:6.1f}  per seed {per_seed}"
            )
    if args.json is not None:
        write_json(args.json, {"seeds": [FIRST_SEED + index for index in range(args.seeds)], "rows": rows})


if __name__ == "__main__":
    main()
