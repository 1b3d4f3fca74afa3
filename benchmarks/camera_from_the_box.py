"""A camera from the box: ``camera calibrate --geometry`` against a virtual camera whose geometry it is not
told, and (``--live N``) ``live --pose registered`` with the file it wrote against the same live run told.

The camera is ``serve-camera``'s over the built-in PETS recording, in a process of its own, with a
geometry drawn by ``--geometry-seed`` (:func:`ptztrack.builders.live.virtual_geometry`; its truth log
tells where it looked), no positions in GetStatus and relative moves only. The command line is run as a
user runs it:

1. ``camera calibrate --geometry --snapshot``: the camera's ground view;
2. ``--points`` ground points, spread over that picture (the farthest-point order of a grid of the
   ground it shows), their pixels the true camera's projections plus ``--noise-px`` of Gaussian noise;
3. ``camera calibrate --geometry --ground-points``;
4. the file it wrote against the truth: ``focal_err_max_pct`` (the focal length at every zoom step the
   file lists against the camera's own), ``pan_tilt_err_max_deg`` (the file's pan and tilt at every
   normalised position the camera reaches, against the truth), ``position_err_m`` and
   ``bearing_err_deg`` (the ground view's pan, whose error is the pan zero's bearing's), each the
   largest over the ``--geometry-seed`` cameras; ``pan_tilt_err_scene_max_deg`` is the mapping's over
   the positions that look where the scenario's action grid does;
5. with ``--live N``: N runs of ``live --policy smpl --detector hog --pose registered`` with that file on
   the blind camera, and N with the true calibration (``virtual_geometry``'s) and GetStatus's positions
   on the same camera with positions and AbsoluteMove: ``mota_blind`` and ``mota_told``, their means.

Run: ``python benchmarks/camera_from_the_box.py [--geometry-seed 1] [--live 5] [--json PATH]``.
"""

import argparse
import contextlib
import json
import re
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

from ptztrack.builders.camera_calibration import camera_spaces
from ptztrack.builders.episode import episode_world
from ptztrack.builders.live import live_as_episode, run_live_episode
from ptztrack.builders.virtual_camera import VIRTUAL_SUPERSAMPLE, virtual_geometry
from ptztrack.camera.onvif_client import camera_address
from ptztrack.cli import main
from ptztrack.cli.camera import read_truth_log
from ptztrack.cli.scenario import build_scenario
from ptztrack.config import load_camera_calibration
from ptztrack.evaluate.metrics import episode_metrics
from ptztrack.files import write_atomically
from ptztrack.geometry.ptz import projection_matrix

# Ground points a user would pick: none farther than this from the camera (a far point's pixel is a
# wide stretch of ground).
MAX_RANGE_M = 40.0


def spread_ground_points(
    camera, pose, count: int, noise_px: float, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """``count`` ground points (x, y) m seen at ``pose``, spread over the picture (farthest-point order of
    the grid points whose pixels lie 8 px inside it), and their pixels with ``noise_px`` of noise."""
    H = projection_matrix(camera, pose)[:, [0, 1, 3]]
    width_px, height_px = camera.image_width_px, camera.image_height_px
    u, v = np.meshgrid(np.linspace(8, width_px - 8, 15), np.linspace(8, height_px - 8, 12))
    pixels = np.c_[u.ravel(), v.ravel()]
    ground = np.c_[pixels, np.ones(len(pixels))] @ np.linalg.inv(H).T
    ground = ground[:, :2] / ground[:, 2:]
    # Pixels below the horizon (their rays meet the ground in front of the camera), within MAX_RANGE_M.
    depth = (np.c_[ground, np.ones(len(ground))] @ H.T)[:, 2]
    kept = np.flatnonzero((depth > 0) & (np.linalg.norm(ground - camera.position_m[:2], axis=1) < MAX_RANGE_M))
    chosen = [kept[np.argmax(pixels[kept, 1])]]
    while len(chosen) < count:
        distance = np.min(np.linalg.norm(pixels[kept, None] - pixels[chosen][None], axis=-1), axis=1)
        chosen.append(kept[np.argmax(distance)])
    return ground[chosen], pixels[chosen] + rng.normal(0.0, noise_px, (count, 2))


def geometry_errors(calibration, truth, true_f_min_px: float, ground_view_true, scene_poses, steps: int = 201) -> dict:
    """The file's errors against the true geometry (see the module); ``pan_tilt_err_scene_max_deg`` is
    the pan and tilt mapping's over the normalised positions whose true pan and tilt lie within those of
    ``scene_poses`` (N, 3), the action grid's."""
    true_spaces, found_spaces = camera_spaces(truth), camera_spaces(calibration)
    curve = np.asarray(calibration.zoom_curve, dtype=float)
    true_curve = np.asarray(truth.zoom_curve, dtype=float)
    true_focal = true_f_min_px * np.interp(curve[:, 0], true_curve[:, 0], true_curve[:, 1])
    found_focal = calibration.f_min_px * curve[:, 1]
    preset = true_spaces.normalised(ground_view_true)
    x = np.linspace(-1.0, 1.0, steps)
    positions = np.c_[x, x, np.zeros(steps)]
    # A camera without positions counts its normalised position from the ground preset.
    found_positions = positions if calibration.positions else positions - [preset[0], preset[1], 0.0]
    true_pose, found_pose = true_spaces.pose(positions), found_spaces.pose(found_positions)
    pan_error = np.abs((found_pose[:, 0] - true_pose[:, 0] + 180.0) % 360.0 - 180.0)
    tilt_error = np.abs(found_pose[:, 1] - true_pose[:, 1])
    # Only where the head reaches: a position beyond its ends on the preset's side is not one.
    reachable = np.abs(found_positions[:, 0]) <= 1.0
    reachable_tilt = np.abs(found_positions[:, 1]) <= 1.0
    low, high = np.min(scene_poses, axis=0), np.max(scene_poses, axis=0)
    in_pan = reachable & (true_pose[:, 0] >= low[0]) & (true_pose[:, 0] <= high[0])
    in_tilt = reachable_tilt & (true_pose[:, 1] >= low[1]) & (true_pose[:, 1] <= high[1])
    view = calibration.ground_view
    return {
        "pan_tilt_err_scene_max_deg": float(max(pan_error[in_pan].max(), tilt_error[in_tilt].max())),
        "focal_err_max_pct": float(100 * np.max(np.abs(found_focal / true_focal - 1))),
        "focal_err_pct": (100 * (found_focal / true_focal - 1)).round(3).tolist(),
        "pan_tilt_err_max_deg": float(max(pan_error[reachable].max(), tilt_error[reachable_tilt].max())),
        "position_err_m": float(np.linalg.norm(np.asarray(calibration.position_m) - np.asarray(truth.position_m))),
        "bearing_err_deg": float(abs((view.pan_deg - ground_view_true[0] + 180.0) % 360.0 - 180.0)),
        "tilt_err_deg": float(abs(view.tilt_deg - ground_view_true[1])),
    }


@contextlib.contextmanager
def served(seed: int, blind: bool, truth_log: Path):
    """``ptztrack serve-camera`` in a process of its own (a camera is a machine of its own) with the
    geometry of ``seed``, without positions and AbsoluteMove where ``blind``; its onvif:// URL."""
    command = [sys.executable, "-m", "ptztrack.cli", "serve-camera", "--port", "0", "--geometry-seed", str(seed)]
    command += ["--truth-log", str(truth_log), "--supersample", str(VIRTUAL_SUPERSAMPLE)]
    command += ["--no-positions", "--relative-only"] if blind else []
    server = subprocess.Popen(command, stdout=subprocess.PIPE, text=True)
    try:
        line = server.stdout.readline() if server.stdout is not None else ""
        found = re.search(r"onvif://127\.0\.0\.1:\d+", line)
        if found is None:
            raise RuntimeError(f"serve-camera did not start: {line!r}")
        yield found.group(0)
    finally:
        server.send_signal(signal.SIGINT)
        server.communicate(timeout=30)


def last_pose(truth_log: Path) -> np.ndarray:
    """The pose (3,) of the newest picture in a truth log."""
    time.sleep(0.5)
    return read_truth_log(truth_log)[-1, 2:]


def calibrate_blind(
    url: str, truth_log: Path, seed: int, points: int, noise_px: float, folder: Path
) -> tuple[Path, np.ndarray]:
    """``camera calibrate --geometry`` as a user runs it (see the module) on the camera at ``url``; the
    file it wrote and the ground view's true pose."""
    scenario = build_scenario("pets", "hog")
    world = episode_world(scenario, 0)
    calibration = folder / f"camera-{seed}.yaml"
    command = ["camera", "calibrate", "--geometry", "--camera", url, "--calibration", str(calibration)]
    if main([*command, "--snapshot", str(folder / "ground.png")]) != 0:
        raise RuntimeError("the snapshot failed")
    ground_view = last_pose(truth_log)
    rng = np.random.default_rng(seed)
    ground_m, pixels_px = spread_ground_points(world.camera, ground_view, points, noise_px, rng)
    rows = [[*map(float, pixel), *map(float, ground)] for pixel, ground in zip(pixels_px, ground_m, strict=True)]
    points_file = folder / "points.yaml"
    write_atomically(points_file, yaml.safe_dump({"snapshot": "ground.png", "points": rows}).encode())
    if main([*command, "--ground-points", str(points_file)]) != 0:
        raise RuntimeError("the calibration failed")
    return calibration, ground_view


def live_motas(url: str, truth_log: Path, calibration, pose_source: str, runs: int, steps: int | None) -> list[float]:
    """MOTA of ``runs`` live runs (seeds 0, 1, ...) of ``live --policy smpl --detector hog`` on the camera."""
    scenario = build_scenario("pets", "hog")
    address = camera_address(url)
    motas = []
    for seed in range(runs):
        (world,), (live,) = run_live_episode(
            scenario, [calibration], [address], "smpl", steps or scenario.frames, 1.0, seed, pose_source=pose_source
        )
        metrics = episode_metrics(live_as_episode(world, live, read_truth_log(truth_log)))
        motas.append(float(metrics["mota"]))
        print(f"  live {pose_source} run {seed}: MOTA {metrics['mota']:.1%}", flush=True)
    return motas


def main_benchmark() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--geometry-seed", type=int, nargs="+", default=[1])
    parser.add_argument("--points", type=int, default=6)
    parser.add_argument("--noise-px", type=float, default=1.0)
    parser.add_argument("--live", type=int, default=0, help="live runs each, blind and told (0: none)")
    parser.add_argument("--steps", type=int, help="pictures each live run uses (default: the scenario's frames)")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    runs = []
    scenario = build_scenario("pets", "hog")
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        for seed in args.geometry_seed:
            truth_log = folder / f"truth-{seed}.csv"
            with served(seed, True, truth_log) as url:
                started_s = time.monotonic()
                calibration, ground_view = calibrate_blind(url, truth_log, seed, args.points, args.noise_px, folder)
                run = {"geometry_seed": seed, "calibrate_s": round(time.monotonic() - started_s, 1)}
                found = load_camera_calibration(calibration)
                world = episode_world(scenario, 0)
                truth = virtual_geometry(scenario, seed=seed)
                run |= geometry_errors(found, truth, world.camera.f_min_px, ground_view, world.grid.poses)
                print(
                    f"geometry seed {seed}: focal {run['focal_err_max_pct']:.2f} %, pan/tilt at most "
                    f"{run['pan_tilt_err_max_deg']:.2f} deg ({run['pan_tilt_err_scene_max_deg']:.2f} in the scene), "
                    f"position {run['position_err_m']:.3f} m, "
                    f"bearing {run['bearing_err_deg']:.3f} deg ({run['calibrate_s']:.0f} s)",
                    flush=True,
                )
                if args.live:
                    run["mota_blind_runs"] = live_motas(url, truth_log, found, "registered", args.live, args.steps)
            if args.live:
                with served(seed, False, truth_log) as url:
                    run["mota_told_runs"] = live_motas(url, truth_log, truth, "status", args.live, args.steps)
            runs.append(run)
    keys = (
        "focal_err_max_pct",
        "pan_tilt_err_max_deg",
        "pan_tilt_err_scene_max_deg",
        "position_err_m",
        "bearing_err_deg",
    )
    result = {key: max(run[key] for run in runs) for key in keys} | {"runs": runs}
    if args.live:
        result["mota_blind"] = float(np.mean([mota for run in runs for mota in run["mota_blind_runs"]]))
        result["mota_told"] = float(np.mean([mota for run in runs for mota in run["mota_told_runs"]]))
        print(f"MOTA blind {result['mota_blind']:.1%}, told {result['mota_told']:.1%} (means of {args.live} runs)")
    if args.json is not None:
        write_atomically(args.json, json.dumps(result, indent=1).encode())
    return 0


if __name__ == "__main__":
    sys.exit(main_benchmark())
