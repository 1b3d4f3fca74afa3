"""A camera from the box: ``camera calibrate --geometry`` against a virtual camera whose geometry it is not
told, and (``--live``) ``live --pose registered`` with the file it wrote against the same live run told.

The camera is ``serve-camera``'s over the built-in PETS recording, in process (so that its truth can be
read), with a geometry drawn by ``--geometry-seed`` (:func:`ptztrack.builders.live.virtual_geometry`),
no positions in GetStatus and relative moves only. The command line is run as a user runs it:

1. ``camera calibrate --geometry --snapshot``: the camera's ground view;
2. ``--points`` ground points, spread over that picture (the farthest-point order of a grid of the
   ground it shows), their pixels the true camera's projections plus ``--noise-px`` of Gaussian noise;
3. ``camera calibrate --geometry --ground-points``;
4. the file it wrote against the truth: ``focal_err_max_pct`` (the focal length at every zoom step the
   file lists against the camera's own), ``pan_tilt_err_max_deg`` (the file's pan and tilt at every
   normalised position the camera reaches, against the truth), ``position_err_m`` and
   ``bearing_err_deg`` (the ground view's pan, whose error is the pan zero's bearing's), each the
   largest over the ``--geometry-seed`` cameras; ``pan_tilt_err_scene_max_deg`` is the mapping's over
   the positions that look where the scenario's action grid does.

Run: ``python benchmarks/camera_from_the_box.py [--geometry-seed 1] [--json PATH]``.
"""

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

from ptztrack.builders.live import camera_spaces, virtual_geometry, virtual_onvif_camera
from ptztrack.cli import main
from ptztrack.cli.scenario import build_scenario
from ptztrack.config import load_camera_calibration
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


def calibrate_blind(seed: int, points: int, noise_px: float, folder: Path) -> dict:
    """One blind calibration of a camera drawn with ``seed`` (see the module); its errors and times."""
    scenario = build_scenario("pets", "hog")
    truth = virtual_geometry(scenario, seed=seed)
    camera, feed = virtual_onvif_camera(scenario, 1.0, 0, geometry=truth, positions=False, absolute_moves=False)
    camera.start()
    url = f"onvif://127.0.0.1:{camera.onvif_port}"
    calibration = folder / f"camera-{seed}.yaml"
    try:
        started_s = time.monotonic()
        command = ["camera", "calibrate", "--geometry", "--camera", url, "--calibration", str(calibration)]
        if main([*command, "--snapshot", str(folder / "ground.png")]) != 0:
            raise RuntimeError("the snapshot failed")
        time.sleep(0.5)
        ground_view = camera.truth()[1][-1]
        rng = np.random.default_rng(seed)
        ground_m, pixels_px = spread_ground_points(feed.world.camera, ground_view, points, noise_px, rng)
        rows = [[*map(float, pixel), *map(float, ground)] for pixel, ground in zip(pixels_px, ground_m, strict=True)]
        points_file = folder / "points.yaml"
        write_atomically(points_file, yaml.safe_dump({"snapshot": "ground.png", "points": rows}).encode())
        if main([*command, "--ground-points", str(points_file)]) != 0:
            raise RuntimeError("the calibration failed")
        calibrate_s = time.monotonic() - started_s
    finally:
        camera.stop()
    found = load_camera_calibration(calibration)
    errors = geometry_errors(found, truth, feed.world.camera.f_min_px, ground_view, feed.world.grid.poses)
    return {"geometry_seed": seed, "calibrate_s": round(calibrate_s, 1), **errors}


def main_benchmark() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--geometry-seed", type=int, nargs="+", default=[1])
    parser.add_argument("--points", type=int, default=6)
    parser.add_argument("--noise-px", type=float, default=1.0)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    runs = []
    with tempfile.TemporaryDirectory() as folder:
        for seed in args.geometry_seed:
            run = calibrate_blind(seed, args.points, args.noise_px, Path(folder))
            print(
                f"geometry seed {seed}: focal {run['focal_err_max_pct']:.2f} %, pan/tilt at most "
                f"{run['pan_tilt_err_max_deg']:.2f} deg ({run['pan_tilt_err_scene_max_deg']:.2f} in the scene), "
                f"position {run['position_err_m']:.3f} m, "
                f"bearing {run['bearing_err_deg']:.3f} deg ({run['calibrate_s']:.0f} s)",
                flush=True,
            )
            runs.append(run)
    keys = (
        "focal_err_max_pct",
        "pan_tilt_err_max_deg",
        "pan_tilt_err_scene_max_deg",
        "position_err_m",
        "bearing_err_deg",
    )
    result = {key: max(run[key] for run in runs) for key in keys} | {"runs": runs}
    if args.json is not None:
        write_atomically(args.json, json.dumps(result, indent=1).encode())
    return 0


if __name__ == "__main__":
    sys.exit(main_benchmark())
