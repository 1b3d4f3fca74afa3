"""Registration of one PTZ view, on one core: milliseconds per view and where they go.

Builds (or reads, with --index) the PETS reference index at the view size asked for, renders
random reachable live views of frames 300 after the reference sweep, as a real camera takes them
(camera.live_view's realistic model; --exact-views for exact pinhole views), and times `register`
on each, single-threaded.
As a reference measured in the same run: OpenCV's SIFT alone on the full-size view at its
default settings, which is what registration would cost before any matching without the
halved, low-contrast detection.

    python benchmarks/registration_speed.py [--views 50] [--size 640 480] [--index PATH] [--exact-views] [--json PATH]
"""

import argparse
import time
from pathlib import Path

import cv2
import numpy as np

from ptztrack.builders.recording import pets_scenario
from ptztrack.builders.registration import live_view_model, reference_index, registration_camera
from ptztrack.builders.world import action_grid
from ptztrack.camera.live_view import render_view
from ptztrack.experiments.registration import first_live_frame
from ptztrack.files import write_json
from ptztrack.geometry.registration import LIVE_FEATURES, register, sift_features, within_view_ratio_matches
from ptztrack.scene.pets import RecordedVideo


def main() -> None:
    arguments = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    arguments.add_argument("--views", type=int, default=50)
    arguments.add_argument("--size", type=int, nargs=2, default=(640, 480), metavar=("WIDTH", "HEIGHT"))
    arguments.add_argument("--index", help="reference index file: read if it exists, else built and written")
    arguments.add_argument("--exact-views", action="store_true", help="exact pinhole live views")
    arguments.add_argument("--json", type=Path, help="write the figures here")
    args = arguments.parse_args()
    cv2.setNumThreads(1)

    scenario = pets_scenario(
        "ideal",
        pose_feedback={"image_size_px": tuple(args.size), "index": args.index},
        camera={"image_size_px": (160, 120), "live_view": None if args.exact_views else {}},
    )
    start = time.perf_counter()
    index = reference_index(scenario)
    seconds = time.perf_counter() - start
    print(f"reference index: {len(index.poses)} views, {len(index.descriptors)} features, {seconds:.1f} s")
    virtual, whole_frame_pose = registration_camera(scenario)
    grid = action_grid(scenario)
    rng = np.random.default_rng(0)
    video = RecordedVideo(scenario.recording.video, scenario.recording.recorded_size_px)
    frames = np.sort(rng.integers(first_live_frame(scenario, whole_frame_pose), 795, args.views))
    live = live_view_model(scenario)
    images = []
    for frame in frames:
        pose = [
            whole_frame_pose[0] + rng.uniform(grid.pan_deg.min(), grid.pan_deg.max()),
            whole_frame_pose[1] + rng.uniform(grid.tilt_deg.min(), grid.tilt_deg.max()),
            rng.uniform(1.0, grid.zoom.max()),
        ]
        images.append(render_view(virtual, video.frame(int(frame)), np.array(pose), live))

    timings = []
    for image in images:
        start = time.perf_counter()
        _, descriptors = sift_features(image, LIVE_FEATURES)
        features = time.perf_counter()
        within_view_ratio_matches(index, descriptors)
        matched = time.perf_counter()
        register(virtual.camera, index, image)
        registered = time.perf_counter()
        cv2.SIFT.create().detectAndCompute(cv2.cvtColor(image, cv2.COLOR_BGR2GRAY), None)
        reference = time.perf_counter()
        timings.append((registered - matched, features - start, matched - features, reference - registered))
    total, sift, matching, full_size_sift = np.median(timings, axis=0) * 1e3
    p90 = np.percentile([row[0] for row in timings], 90) * 1e3
    kind = "exact pinhole" if live is None else "realistic"
    print(f"register one {args.size[0]} x {args.size[1]} {kind} view, one thread, {args.views} views:")
    print(
        f"  median {total:.1f} ms (p90 {p90:.1f} ms): SIFT {sift:.1f} ms, FLANN and ratio test {matching:.1f} ms, "
        f"RANSAC and pose {total - sift - matching:.1f} ms"
    )
    print(
        f"  reference, OpenCV SIFT alone at full size and default settings: {full_size_sift:.1f} ms "
        f"({full_size_sift / total:.2f}x the whole registration)"
    )
    if args.json is not None:
        figures = {
            "views": args.views,
            "size_px": list(args.size),
            "live_views": kind,
            "register_ms_median": total,
            "register_ms_p90": p90,
            "sift_ms_median": sift,
            "matching_ms_median": matching,
            "full_size_sift_ms_median": full_size_sift,
        }
        write_json(args.json, figures)


if __name__ == "__main__":
    main()
