"""The live loop's rates against the virtual ONVIF camera on 127.0.0.1, and its score beside the offline run.

``ptztrack live``'s loop (:func:`ptztrack.builders.live.run_live_episode`)
drives the virtual camera of ``ptztrack serve-camera`` (PETS S2.L1, moving at
90 deg/s and 3 zoom per second) over ONVIF, in this process, for ``--steps``
steps of the PETS scenario at ``--time-scale`` of its 5 Hz, with ``--policy``
and the HOG detector. It prints the steps per second, the decisions sent
(a decision is not sent while the camera moves), the images captured, the
time of a decision, of a capture (waiting for the camera to stand still,
GetStatus and the snapshot: ``image_after_ms`` from the step's start), and the MOTA of the live run
scored against the recording's truth beside the offline virtual-PTZ run of
the same steps.

    python benchmarks/live_loop.py [--steps 110] [--time-scale 0.25] [--policy smpl] [--json PATH]
"""

import argparse
from pathlib import Path

import numpy as np

from ptztrack.builders.episode import run_episode
from ptztrack.builders.live import (
    live_as_episode,
    offline_counterpart,
    run_live_episode,
    virtual_calibration,
    virtual_camera,
)
from ptztrack.camera.onvif_client import CameraAddress
from ptztrack.config import pets_scenario
from ptztrack.evaluate.metrics import episode_metrics
from ptztrack.files import write_json


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=110)
    parser.add_argument("--time-scale", type=float, default=0.25)
    parser.add_argument("--policy", default="smpl")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    scenario = pets_scenario("hog", frames=args.steps)
    camera, feed = virtual_camera(scenario, args.time_scale, 0, "bench", "bench-pass")
    with camera:
        address = CameraAddress("127.0.0.1", camera.onvif_port, "bench", "bench-pass")
        world, live = run_live_episode(
            scenario, virtual_calibration(), address, args.policy, args.steps, args.time_scale, seed=0
        )
    live_metrics = episode_metrics(live_as_episode(world, live, feed.rows()))
    offline = offline_counterpart(scenario, world, live, feed.rows())
    offline_metrics = episode_metrics(run_episode(offline, args.policy, 0))
    captured = np.isfinite(live.capture_time_s)
    step_s = np.diff(live.step_time_s)
    row = {
        "policy": args.policy,
        "steps": len(live.commanded),
        "time_scale": args.time_scale,
        "first_video_frame": offline.required_recording("").frame_range[0],
        "steps_per_s": float(1 / np.mean(step_s)),
        "decisions_sent": int(live.sent.sum()),
        "images": int(captured.sum()),
        "decision_ms": float(1e3 * np.mean(live.decision_s)),
        "image_after_ms": float(1e3 * np.nanmean(live.capture_time_s - live.step_time_s)),
        "live_mota": live_metrics["mota"],
        "offline_mota": offline_metrics["mota"],
        "live_motp_m": live_metrics["motp_m"],
        "offline_motp_m": offline_metrics["motp_m"],
    }
    width = max(map(len, row))
    for key, value in row.items():
        print(f"{key:>{width}}  {value:.4g}" if isinstance(value, float) else f"{key:>{width}}  {value}")
    if args.json is not None:
        write_json(args.json, row)


if __name__ == "__main__":
    main()
