"""The live loop's pace against the virtual ONVIF camera on 127.0.0.1, its score beside the offline
run of the same recording steps, and where the two differ.

``ptztrack live``'s loop (:func:`ptztrack.builders.live.run_live_episode`) drives the virtual camera
of ``ptztrack serve-camera`` (PETS S2.L1 played at ``--time-scale``, 25 fps over RTSP, moving at 90
deg/s and 3 zoom per second), served by a process of its own on this machine's cores, with
``--policy`` and the HOG detector, for ``--steps`` pictures used. It prints the rates (decisions,
pictures used and pictures detected per second, the age of the picture each decision was made on, the choices and the
new targets sent per second), the policy's time (the first decision with tracks and the median, both
among the decisions with a choice: a camera that moves, or has not yet taken a picture at rest where
it went, is given its target alone), and the MOTA of the live run scored against the recording's
truth beside the offline virtual-PTZ run of the same recording steps. Each picture used is then
found among the pictures the camera rendered (by its thumbnail), which gives what the live run paid:
the stream's true delay, the pose error at capture (the pose the tracker used against the pose
rendered, still and moving), the recording step it took the picture for against the one shown, and
the detections per picture against the offline run's; and the stages a decision's picture went
through (medians), with the detection's cost by the picture's zoom beside the people it found there and
the detector model's recall at their height. The gap is then taken apart by replays through
a fresh tracker, each changing one thing: the live run's pictures rendered exactly (the recording's
view at the step and pose each showed, at its render time: no stream, no pose error; detected where
the live run could place them), then one detected picture per recording step (the offline run's rate, at
the live camera's poses). What is left between the last and the offline run is where the camera
looked. The offline run is also repeated
over ``--offline-seeds`` seeds (its policy samples), for the spread of the figure the live run is
held against.

    python benchmarks/live_loop.py [--steps 700] [--time-scale 1] [--policy smpl] [--transport tcp]
                                   [--offline-seeds 5] [--busy-cores N] [--json PATH]

``--busy-cores N`` starts N processes that spin on this machine's cores for the live run (a camera's
small computer running other work); the JSON then holds the run's keys under ``busy``. The machine (its
CPU model and cores) and the virtual camera's own CPU use (its share of one core: a real camera does not
share the loop's cores) are reported beside the figures.
"""

import argparse
import contextlib
import multiprocessing
import os
import time
from functools import partial
from pathlib import Path

import cv2
import numpy as np

from ptztrack.builders.camera_calibration import camera_spaces
from ptztrack.builders.episode import episode_world, make_tracker, run_episode
from ptztrack.builders.live import live_as_episode, live_world, offline_counterpart, run_live_episode, shown_steps
from ptztrack.builders.recording import pets_scenario
from ptztrack.builders.virtual_camera import RecordingFeed, virtual_calibration, virtual_onvif_camera
from ptztrack.camera.move_timing import measure_image_delay
from ptztrack.camera.onvif_client import CameraAddress, ONVIFClient
from ptztrack.camera.onvif_spaces import MoveTimes
from ptztrack.camera.stream import FrameStream, rtsp_pictures, thumbnail
from ptztrack.evaluate.metrics import clear_metrics, episode_metrics
from ptztrack.files import write_json
from ptztrack.loop.steps import track

# A picture is matched among the renders of the second before its estimated capture time and after it.
MATCH_WINDOW_S = (1.0, 0.5)
# Thumbnails within this mean grey level of the best match are indistinguishable from it.
SAME_GREY = 0.5
# The zoom bands the detection's cost and recall are reported in.
ZOOM_BANDS = ((1.0, 1.5), (1.5, 3.0), (3.0, np.inf))


def identify(live, log: np.ndarray, thumbnails: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each picture the live run used, the row of the camera's truth ``log`` (n, 5) it was rendered
    as (``thumbnails`` (n, 48, 64) of the renders), -1 where renders that differ in pose or step are
    indistinguishable from it; and whether that render is the only one like it (its time is then known:
    a camera standing still renders the same picture until the recording steps on)."""
    rows, only = np.full(len(live.capture_time_s), -1), np.zeros(len(live.capture_time_s), bool)
    for index, (jpeg, time_s) in enumerate(zip(live.images, live.capture_time_s, strict=True)):
        image = cv2.imdecode(np.frombuffer(jpeg, np.uint8), cv2.IMREAD_COLOR)
        window = np.flatnonzero((log[:, 0] > time_s - MATCH_WINDOW_S[0]) & (log[:, 0] < time_s + MATCH_WINDOW_S[1]))
        if image is None or not len(window):
            continue
        distance = np.mean(np.abs(thumbnails[window] - thumbnail(image)), axis=(1, 2))
        alike = window[distance <= distance.min() + SAME_GREY]
        if np.all(log[alike, 1:] == log[alike[0], 1:]):  # the same step at the same pose: any of them
            rows[index], only[index] = alike[0], len(alike) == 1
    return rows, only


def replay(scenario, calibration, steps, poses, times_s, detected) -> dict:
    """The CLEAR figures of a fresh tracker (the live run's) fed pictures rendered exactly: for each
    picture (T,), the recording's view at ``steps`` (T,) and ``poses`` (T, 3), predicted to ``times_s`` (T,)
    (wall seconds at time scale 1) and, where ``detected`` (T,) (where the live run's detector ran on it),
    detected as the live run detects; scored against ``steps``."""
    world = live_world(scenario, calibration, 0)
    view = world.backend
    tracker = make_tracker(None, scenario, world)
    rng = np.random.default_rng(0)
    reported = []
    for index, (step, pose) in enumerate(zip(steps, poses, strict=True)):
        tracker.predict(None if index == 0 else max(float(times_s[index] - times_s[index - 1]), 0.0))
        if detected[index]:
            detections = world.detector.detect(view, int(step), pose, rng)
            track(tracker, detections, pose, partial(view.image, int(step), pose))
        reported.append(tracker.reported())
    return clear_metrics(world.truth.positions_m[steps], [t.ids for t in reported], [t.mean[:, :2] for t in reported])


def detection_by_zoom(live, recall) -> dict:
    """For each of ZOOM_BANDS, over the pictures of ``live`` the detector ran on at a zoom in it: the median
    detection time (``ms``), the median height of the people it found (``people_height_px``), and
    ``recall``, the detector model's recall at that height (``recall(height_px)``, the run's online
    model as it ended; NaN without one, or without people found)."""
    detection_ms = 1e3 * (live.detected_s - live.picked_s)
    figures = {}
    for low, high in ZOOM_BANDS:
        band = np.flatnonzero(live.detected & (live.poses[:, 2] >= low) & (live.poses[:, 2] < high))
        heights_px = np.concatenate([np.zeros(0), *(live.detections[k].height_px for k in band)])
        height_px = float(np.median(heights_px)) if len(heights_px) else float("nan")
        figures[f"zoom {low:g}-{high:g}"] = {
            "ms": float(np.median(detection_ms[band])) if len(band) else float("nan"),
            "people_height_px": height_px,
            "recall": float(recall(height_px)) if recall is not None and np.isfinite(height_px) else float("nan"),
        }
    return figures


def serve(time_scale: float, ready, stop, results) -> None:
    """The virtual camera in a process of its own (as a camera is a machine of its own): its ONVIF port
    into ``ready``, then, once ``stop`` is set, its truth log, thumbnails and the CPU seconds it used (its
    rendering and encoding, which a real camera does on its own processor) into ``results``."""
    scenario = pets_scenario("hog")
    feed = RecordingFeed(episode_world(scenario, 0), 1.0 / scenario.frame_rate_hz, time_scale, thumbnails=[])
    camera, _ = virtual_onvif_camera(scenario, time_scale, 0, "bench", "bench-pass", feed=feed)
    with camera:
        ready.put(camera.onvif_port)
        started_cpu_s = time.process_time()
        stop.wait()
        cpu_s = time.process_time() - started_cpu_s
    results.put((feed.rows(), np.asarray(feed.thumbnails), cpu_s))


def spin(stop) -> None:
    """Keep a core busy until ``stop`` is set: other work on the machine the loop runs on."""
    while not stop.is_set():
        sum(range(100_000))


def machine() -> dict:
    """The machine's CPU model (``lscpu``'s model name, from /proc/cpuinfo) and how many cores it has."""
    model = "unknown"
    with contextlib.suppress(OSError), open("/proc/cpuinfo") as cpuinfo:
        model = next((line.split(":", 1)[1].strip() for line in cpuinfo if line.startswith("model name")), model)
    return {"cpu_model": model, "cores": os.cpu_count()}


def calibrated(address: CameraAddress):
    """The virtual calibration with the stream's delay and its capture times' uncertainty as ``camera
    calibrate`` measures them on the camera."""
    calibration = virtual_calibration()
    client = ONVIFClient(address)
    client.connect()
    stream = FrameStream(rtsp_pictures(client.stream_uri()), delay_s=0.0)
    stream.start()
    try:
        move_times = MoveTimes(calibration.move_times.pan, calibration.move_times.tilt, calibration.move_times.zoom)
        delay_s, capture_time_sd_s, _ = measure_image_delay(
            client, camera_spaces(calibration), move_times, stream.latest
        )
    finally:
        stream.stop()
        client.close()
    return calibration.model_copy(update={"image_delay_s": delay_s, "capture_time_sd_s": capture_time_sd_s})


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=700, help="pictures the live run uses")
    parser.add_argument("--time-scale", type=float, default=1.0)
    parser.add_argument("--policy", default="smpl")
    parser.add_argument("--transport", choices=("tcp", "udp"), default="tcp")
    parser.add_argument("--offline-seeds", type=int, default=5, help="seeds of the offline run (0 is the one compared)")
    parser.add_argument("--busy-cores", type=int, default=0, help="processes spinning on this machine during the run")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    if args.busy_cores < 0:
        parser.error(f"--busy-cores {args.busy_cores}: expected a whole number >= 0")
    scenario = pets_scenario("hog")
    decisions: list[tuple[float, int, int]] = []

    def observe(worlds, policy):
        return lambda step, context, record: decisions.append(
            (record["decision_s"], len(context.tracks), len(context.reachable))
        )

    processes = multiprocessing.get_context("spawn")
    ready, stop, results = processes.Queue(), processes.Event(), processes.Queue()
    server = processes.Process(target=serve, args=(args.time_scale, ready, stop, results), daemon=True)
    server.start()
    busy_stop = processes.Event()
    busy = [processes.Process(target=spin, args=(busy_stop,), daemon=True) for _ in range(args.busy_cores)]
    try:
        address = CameraAddress("127.0.0.1", ready.get(timeout=120), "bench", "bench-pass")
        calibration = calibrated(address)
        for process in busy:
            process.start()
        started = time.perf_counter()
        (world,), (live,) = run_live_episode(
            scenario, [calibration], [address], args.policy, args.steps, args.time_scale, 0,
            observe=observe, transport=args.transport, keep_images=True,
        )  # fmt: skip
        wall_s = time.perf_counter() - started
    finally:
        busy_stop.set()
        stop.set()
    for process in busy:
        process.join()
    truth_log, thumbnails, camera_cpu_s = results.get(timeout=60)
    server.join()
    live_metrics = episode_metrics(live_as_episode(world, live, truth_log))
    offline = offline_counterpart(scenario, world, live, truth_log)
    offline_episode = run_episode(offline, args.policy, 0)
    offline_metrics = episode_metrics(offline_episode)
    offline_seeds = [offline_metrics["mota"]] + [
        episode_metrics(run_episode(offline, args.policy, seed))["mota"] for seed in range(1, args.offline_seeds)
    ]

    rendered, timed = identify(live, truth_log, thumbnails)
    found = rendered >= 0
    true_pose = truth_log[rendered[found], 2:]
    pose_error = np.abs(live.poses[found] - true_pose)
    moving = np.any(live.pose_sd[found] > 0, axis=1)
    arrival_s = live.capture_time_s + calibration.image_delay_s
    decided = np.isfinite(live.decided_s)
    detected = decided & live.detected
    stages_s = {
        "stream (true delay)": float(np.median(arrival_s[timed] - truth_log[rendered[timed], 0])),
        "waiting for the detector": float(np.median((live.picked_s - arrival_s)[decided])),
        "pose sample and detection": float(np.median((live.detected_s - live.picked_s)[detected])),
        "waiting for the tracker, tracking": float(np.median((live.tracked_s - live.detected_s)[decided])),
        "decision and command": float(np.median((live.decided_s - live.tracked_s)[decided])),
    }
    by_zoom = detection_by_zoom(live, world.detector_model)
    # Each picture as rendered (unidentified ones: the step shown at its capture, the pose estimated).
    steps = np.where(found, truth_log[np.maximum(rendered, 0), 1], shown_steps(truth_log, live.capture_time_s))
    steps = np.clip(steps, 0, world.truth.positions_m.shape[0] - 1).astype(int)
    poses = np.where(found[:, None], truth_log[np.maximum(rendered, 0), 2:], live.poses)
    times_s = np.where(found, truth_log[np.maximum(rendered, 0), 0], live.capture_time_s)
    rendered_exactly = replay(scenario, calibration, steps, poses, times_s, live.detected)
    # The last detected picture of each recording step.
    detected_steps = steps[live.detected]
    last_of_step = np.flatnonzero(live.detected)[np.r_[detected_steps[1:] != detected_steps[:-1], True]]
    per_step = replay(
        scenario,
        calibration,
        steps[last_of_step],
        poses[last_of_step],
        times_s[last_of_step],
        np.ones(len(last_of_step), bool),
    )
    # A camera moving or not yet at rest where it went is given its target alone: no choice to time.
    choices = [(seconds, tracks) for seconds, tracks, reachable in decisions if reachable > 1]
    with_tracks = [seconds for seconds, tracks in choices if tracks > 0]
    rates, run_s = live.rates(), live.ended_s - live.started_s
    row = {
        **machine(),
        "busy_cores": args.busy_cores,
        "camera_cpu_share": camera_cpu_s / wall_s,
        "policy": args.policy,
        "time_scale": args.time_scale,
        "transport": args.transport,
        "image_delay_s_calibrated": calibration.image_delay_s,
        "capture_time_sd_s_calibrated": calibration.capture_time_sd_s,
        "pictures_used": len(live.capture_time_s),
        "recording_steps": offline.frames,
        "wall_s": wall_s,
        "decisions_per_s": rates["decisions_per_s"],
        "frames_used_per_s": rates["frames_used_per_s"],
        "frames_detected_per_s": rates["frames_detected_per_s"],
        "frames_received_per_s": rates["frames_received_per_s"],
        "frame_age_s_p95": rates["frame_age_s_p95"],
        "first_decision_s": with_tracks[0] if with_tracks else float("nan"),
        "median_decision_s": float(np.median([seconds for seconds, _ in choices])),
        "decisions_with_a_choice": len(choices) / max(len(decisions), 1),
        "choices_per_s": len(choices) / run_s,
        "new_targets_per_s": float(np.sum(live.sent)) / run_s,
        "mota_live": live_metrics["mota"],
        "mota_offline": offline_metrics["mota"],
        "mota_replay_rendered": rendered_exactly["mota"],
        "mota_replay_per_step": per_step["mota"],
        "mota_offline_seeds_mean": float(np.mean(offline_seeds)),
        "mota_offline_seeds_sd": float(np.std(offline_seeds, ddof=1)) if len(offline_seeds) > 1 else 0.0,
        "motp_live_m": live_metrics["motp_m"],
        "motp_offline_m": offline_metrics["motp_m"],
        "idf1_live": live_metrics["idf1"],
        "idf1_offline": offline_metrics["idf1"],
        "switches_live": live_metrics["switches"],
        "switches_offline": offline_metrics["switches"],
        "pictures_identified": int(found.sum()),
        "pictures_timed": int(timed.sum()),
        "stream_delay_s_median": stages_s["stream (true delay)"],
        "pictures_moving": float(np.mean(moving)),
        "pan_error_deg_still_p95": float(np.percentile(pose_error[~moving, 0], 95)) if (~moving).any() else 0.0,
        "pan_error_deg_moving_p95": float(np.percentile(pose_error[moving, 0], 95)) if moving.any() else 0.0,
        "zoom_error_moving_p95": float(np.percentile(pose_error[moving, 2], 95)) if moving.any() else 0.0,
        "wrong_step": float(
            np.mean(shown_steps(truth_log, live.capture_time_s[found]) != truth_log[rendered[found], 1])
        ),
        "detections_per_picture_live": float(np.mean([len(d) for d in live.detections])),
        "detections_per_step_offline": float(np.mean([len(d) for d in offline_episode.detections])),
        "zoom_live": float(np.mean(live.poses[:, 2])),
        "zoom_offline": float(np.mean(offline_episode.poses[:, 2])),
        "pose_changes_live": float(np.mean(np.any(np.diff(live.commanded, axis=0) != 0, axis=1))),
        "pose_changes_offline": float(np.mean(np.any(np.diff(offline_episode.commanded, axis=0) != 0, axis=1))),
    }
    width = max(map(len, row))
    for key, value in row.items():
        print(f"{key:>{width}}  {value:.4g}" if isinstance(value, float) else f"{key:>{width}}  {value}")
    print("\nwhere a decision's picture ages (medians over the decisions), ms:")
    for stage, seconds in stages_s.items():
        print(f"  {stage:<36} {1e3 * seconds:7.1f}")
    print("by the picture's zoom: the detection's time (ms), the people found (px tall), the model's recall there:")
    for band, figures in by_zoom.items():
        print(
            f"  {band:<12} {figures['ms']:7.1f} ms {figures['people_height_px']:6.1f} px recall {figures['recall']:.2f}"
        )
    if args.json is not None:
        document = {
            **row,
            "mota_offline_per_seed": offline_seeds,
            "stages_s": stages_s,
            "detection_by_zoom": by_zoom,
        }
        write_json(args.json, {"busy": document} if args.busy_cores else document)


if __name__ == "__main__":
    main()
