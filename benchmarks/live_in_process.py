"""The live loop against a camera in its own process: no stream, no ONVIF, every picture dated exactly.

``ptztrack live``'s loop (:func:`ptztrack.loop.live.run_live`, with the policy,
tracker and planning :func:`ptztrack.builders.live.run_live_episode` gives
it) drives the virtual camera's head (:mod:`ptztrack.virtual_onvif.head`, 90
deg/s and 3 zoom per second, times ``--speedup``), whose pictures are the
PETS S2.L1 view at its pose, the recording playing in real time: 25 a
second, each handed to the loop ``--delay-s`` after its capture with its
exact capture time, its pose sampled as the live camera polls GetStatus.
It prints the live run's MOTA beside the offline run of the recording
steps its pictures showed, as ``benchmarks/live_loop.py`` scores them: what
the loop costs without the stream, the H.264 and a camera's process on the
same cores.

    python benchmarks/live_in_process.py [--steps 700] [--delay-s 0] [--speedup 1] [--offline-seeds 1]
                                         [--json PATH]
"""

import argparse
import threading
import time
from pathlib import Path

import numpy as np

from ptztrack.builders.camera_calibration import camera_spaces, pose_timeline
from ptztrack.builders.episode import episode_world, make_policy, make_tracker, run_episode
from ptztrack.builders.live import live_as_episode, live_world, offline_counterpart, plan_ahead_of
from ptztrack.builders.recording import pets_scenario
from ptztrack.builders.virtual_camera import VIRTUAL_FRAME_RATE_HZ, VIRTUAL_SPEEDS, RecordingFeed, virtual_calibration
from ptztrack.camera.live_camera import POLL_S
from ptztrack.camera.stream import LatestFrame
from ptztrack.evaluate.metrics import episode_metrics
from ptztrack.files import write_json
from ptztrack.loop.live import run_live, warm_up
from ptztrack.virtual_onvif.head import Head, head_axes


class InProcessCamera:
    """A :class:`ptztrack.loop.live.LiveCamera` in this process: ``feed``'s picture at the head's pose, every
    frame interval, handed over ``delay_s`` after its capture."""

    def __init__(self, feed: RecordingFeed, head: Head, timeline, delay_s: float):
        self.frames, self.latest, self.timeline = self, LatestFrame(), timeline
        self._feed, self._head, self._delay_s, self._target = feed, head, delay_s, None
        # The head keeps monotonic time; pictures and samples are dated in epoch seconds.
        self._epoch_offset_s = time.time() - time.monotonic()
        self._stopping = threading.Event()
        self._threads = [threading.Thread(target=run, daemon=True) for run in (self._pictures, self._samples)]

    def send(self, pose) -> bool:
        pose = np.asarray(pose, dtype=float)
        if self._target is not None and np.array_equal(pose, self._target):
            return False
        self._target = pose
        self.timeline.sent(time.time(), pose)
        self._head.move_to(pose.tolist(), [1.0, 1.0, 1.0])
        return True

    def _pictures(self) -> None:
        period_s, next_s = 1.0 / VIRTUAL_FRAME_RATE_HZ, time.monotonic()
        while not self._stopping.wait(max(0.0, next_s - time.monotonic())):
            next_s += period_s
            monotonic_s, pose, _ = self._head.now()
            image, captured_s = self._feed.render(pose, 0.0), monotonic_s + self._epoch_offset_s
            handed_s = captured_s + self._delay_s - time.time()
            if handed_s > 0:
                threading.Timer(handed_s, self.latest.put, (image, captured_s)).start()
            else:
                self.latest.put(image, captured_s)

    def _samples(self) -> None:
        while not self._stopping.wait(POLL_S):
            monotonic_s, pose, moving = self._head.now()
            self.timeline.sample(monotonic_s + self._epoch_offset_s, pose, any(moving))

    def __enter__(self) -> "InProcessCamera":
        for thread in self._threads:
            thread.start()
        return self

    def __exit__(self, *exc_info) -> None:
        self._stopping.set()
        for thread in self._threads:
            thread.join()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=700, help="pictures the live run uses")
    parser.add_argument("--delay-s", type=float, default=0.0, help="seconds from a picture's capture to the loop")
    parser.add_argument("--speedup", type=float, default=1.0, help="the head's speeds times this")
    parser.add_argument("--offline-seeds", type=int, default=1)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    scenario = pets_scenario("hog")
    calibration = virtual_calibration()
    move_times = {axis: (offset_s, seconds / args.speedup) for axis, (offset_s, seconds) in calibration.move_times}
    calibration = calibration.model_copy(
        update={"move_times": calibration.move_times.model_copy(update=move_times), "capture_time_sd_s": 0.001}
    )
    world = live_world(scenario, calibration, 0)
    policy, tracker = make_policy("smpl", scenario, world), make_tracker(None, scenario, world)
    plan_ahead = plan_ahead_of(scenario)
    warm_up(world, policy, tracker)
    feed = RecordingFeed(episode_world(scenario, 0), 1.0 / scenario.frame_rate_hz)
    limits, rates_per_s = head_axes(camera_spaces(calibration), VIRTUAL_SPEEDS)
    head = Head(world.grid.poses[world.start_action], limits, args.speedup * rates_per_s)
    with InProcessCamera(feed, head, pose_timeline(calibration), args.delay_s) as camera:
        live = run_live(world, policy, tracker, camera, args.steps, 1.0, 0, plan_ahead=plan_ahead)
    truth_log = feed.rows()
    offline = offline_counterpart(scenario, world, live, truth_log)
    offline_mota = [episode_metrics(run_episode(offline, "smpl", seed))["mota"] for seed in range(args.offline_seeds)]
    rates = live.rates()
    row = {
        "delay_s": args.delay_s,
        "speedup": args.speedup,
        "pictures_used": len(live.capture_time_s),
        "recording_steps": offline.frames,
        "frames_used_per_s": rates["frames_used_per_s"],
        "frame_age_s_p95": rates["frame_age_s_p95"],
        "mota_live": episode_metrics(live_as_episode(world, live, truth_log))["mota"],
        "mota_offline": offline_mota[0],
        "mota_offline_seeds_mean": float(np.mean(offline_mota)),
        "pictures_moving": float(np.mean(np.any(live.pose_sd > 0, axis=1))),
        "zoom_live": float(np.mean(live.poses[:, 2])),
    }
    width = max(map(len, row))
    for key, value in row.items():
        print(f"{key:>{width}}  {value:.4g}" if isinstance(value, float) else f"{key:>{width}}  {value}")
    if args.json is not None:
        write_json(args.json, {**row, "mota_offline_per_seed": offline_mota})


if __name__ == "__main__":
    main()
