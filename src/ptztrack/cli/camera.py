"""Real and virtual cameras: ``ptztrack live`` drives an ONVIF PTZ camera, ``ptztrack camera calibrate``
times one's moves, ``ptztrack serve-camera`` serves the PETS virtual camera over ONVIF."""

import argparse
import contextlib
import logging
import os
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from urllib.parse import urlsplit

import numpy as np

from ptztrack.builders.camera_calibration import camera_spaces
from ptztrack.builders.live import live_as_episode, live_pictures, run_live_episode, shown_span
from ptztrack.builders.live_registered import check_pose_source
from ptztrack.builders.virtual_camera import (
    TRUTH_LOG_HEADER,
    camera_presets_path,
    virtual_calibration,
    virtual_geometry,
    virtual_onvif_cameras,
)
from ptztrack.camera.move_timing import measure_image_delay, measure_move_times, timed_move
from ptztrack.camera.onvif_client import ONVIFClient, camera_address
from ptztrack.camera.stream import FrameStream, rtsp_pictures
from ptztrack.cli.options import RUN_FOLDER_FILES
from ptztrack.cli.run import format_metrics
from ptztrack.cli.scenario import build_scenario
from ptztrack.cli.watch import Watch
from ptztrack.config import (
    CameraCalibrationFile,
    MoveTimesSection,
    ScenarioError,
    load_camera_calibration,
    load_credentials,
    write_camera_calibration,
)
from ptztrack.evaluate.metrics import episode_metrics, live_metrics
from ptztrack.evaluate.report import write_outputs
from ptztrack.files import check_output_file, read_text, run_folder
from ptztrack.loop.live import LiveEpisode
from ptztrack.loop.steps import Episode
from ptztrack.names import PASSWORD_VARIABLE, TRUTH_MOT_FILE, VIEW_STATES_FILE
from ptztrack.view.view_state import NetworkViewState, ViewState

log = logging.getLogger(__name__)
# How long a live run's end waits for serve-camera's truth log (written every half second) to hold its last picture.
TRUTH_LOG_WAIT_S = 5.0


def _credentials(args: argparse.Namespace) -> dict | None:
    """The ``--credentials`` file's {username, password}, if given, checked before any camera is called; its
    username may be left to ``--user`` or to every ``--camera`` URL's user."""
    if args.credentials is None:
        return None
    cameras = getattr(args, "camera", None) or []  # serve-camera has none
    urls = cameras if isinstance(cameras, list) else [cameras]
    users_in_urls = bool(urls) and all(urlsplit(url).username for url in urls)
    return load_credentials(args.credentials, getattr(args, "user", None) is not None or users_in_urls)


def live_command(args: argparse.Namespace) -> int:
    scenario = build_scenario(
        args.scenario, args.detector, detector_model=args.detector_model, dataset=args.dataset, view=args.dataset_view
    )
    calibrations = _calibrations(args)
    check_pose_source(calibrations, args.pose)
    addresses = [camera_address(url, _credentials(args)) for url in args.camera]
    if args.truth is not None:
        read_truth_log(args.truth)  # refused now if it is not a truth log; read for the scores when the run ends
    steps = args.steps or scenario.frames
    if len(addresses) > 1:
        return _live_network(args, scenario, calibrations, addresses, steps)
    print(f"live: {args.policy} on {addresses[0]}, up to {steps} pictures, RTSP over {args.transport}")
    label = f"live {args.policy}"

    def view(worlds, policy) -> ViewState:
        return ViewState(worlds[0], policy, steps, label, truth=False)

    with Watch(args.view, args.out is not None, view) as watch:
        (world,), (live,) = run_live_episode(
            scenario, calibrations, addresses, args.policy, steps, args.time_scale, args.seed,
            timeout_s=args.timeout_s, transport=args.transport, keep_images=args.out is not None,
            observe=watch.observe, pose_source=args.pose,
        )  # fmt: skip
    truth_log = _truth_log_after(args.truth, [live])
    episode = live_as_episode(world, live, truth_log)
    metrics = _print_metrics(episode, live, truth_log, args.truth)
    if args.out is not None:
        title = f"live {args.policy}, {scenario.detector.kind} detector: {len(live.capture_time_s)} pictures"
        with run_folder(args.out, args.overwrite) as folder:
            write_outputs(folder, episode, metrics, title, live_pictures(live), truth_log is not None)
            watch.write(folder)
        print(f"wrote {', '.join(_run_folder_files(truth_log is not None))} into {args.out}")
    return 0


def _calibrations(args: argparse.Namespace) -> list[CameraCalibrationFile]:
    """Every camera's calibration: ``--calibration`` once for all, or once per ``--camera``."""
    if len(args.calibration) not in (1, len(args.camera)):
        raise ScenarioError(
            f"live: {len(args.calibration)} --calibration for {len(args.camera)} --camera; give one for every "
            "camera, or one per camera in their order"
        )
    names = args.calibration * len(args.camera) if len(args.calibration) == 1 else args.calibration
    return [virtual_calibration() if name == "virtual" else load_camera_calibration(name) for name in names]


def _live_network(args, scenario, calibrations, addresses, steps: int) -> int:
    """``ptztrack live`` with several cameras: one belief, the network's decisions; each camera's files
    into ``--out``'s camera-K folder (K from 1, in the order of ``--camera``), and the network's view
    states (every camera's picture beside the one map) into ``--out`` itself."""
    if args.policy not in ("intg", "smpl"):
        raise ScenarioError(f"live: a network of cameras decides by intg or smpl, not {args.policy}")
    print(
        f"live: {args.policy} ({args.coordination}) on {len(addresses)} cameras, up to {steps} pictures in all, "
        f"RTSP over {args.transport}"
    )
    label = f"live {args.policy} ({args.coordination})"

    def view(worlds, policy) -> NetworkViewState:
        return NetworkViewState(
            [
                ViewState(world, member.policy, steps, f"{label}, camera {number}", truth=False)
                for number, (world, member) in enumerate(zip(worlds, policy.cameras, strict=True), start=1)
            ]
        )

    with Watch(args.view, args.out is not None, view) as watch:
        worlds, lives = run_live_episode(
            scenario, calibrations, addresses, args.policy, steps, args.time_scale, args.seed, args.coordination,
            args.timeout_s, args.transport, keep_images=args.out is not None, observe=watch.observe,
            pose_source=args.pose,
        )  # fmt: skip
    # The cameras share the recording's clock: a virtual camera's truth log places every camera's pictures.
    truth_log = _truth_log_after(args.truth, lives)
    episodes = [live_as_episode(world, live, truth_log) for world, live in zip(worlds, lives, strict=True)]
    with contextlib.ExitStack() as stack:
        folder = None if args.out is None else stack.enter_context(run_folder(args.out, args.overwrite))
        for number, (episode, live) in enumerate(zip(episodes, lives, strict=True), start=1):
            print(f"camera {number}: ", end="")
            metrics = _print_metrics(episode, live, truth_log, args.truth)
            if folder is not None:
                title = f"live {args.policy}, camera {number} of {len(lives)}: {len(live.capture_time_s)} pictures"
                write_outputs(
                    folder / f"camera-{number}", episode, metrics, title, live_pictures(live), truth_log is not None
                )
        if folder is not None:
            watch.write(folder)
    if args.out is not None:
        print(f"wrote camera-1 to camera-{len(lives)} and {VIEW_STATES_FILE} into {args.out}")
    return 0


def _truth_log_after(path: Path | None, lives: Sequence[LiveEpisode]) -> np.ndarray | None:
    """``--truth``'s log once it holds the run's last picture (serve-camera appends to it every half
    second), waiting at most ``TRUTH_LOG_WAIT_S``; None without ``--truth``, or where the log holds no
    picture (the run is then not scored, with a warning). A log that ends before the run's last picture
    is used with a warning: the pictures after its end are scored against its last step."""
    if path is None:
        return None
    last_capture_s = max((float(live.capture_time_s.max()) for live in lives if len(live.capture_time_s)), default=0.0)
    deadline_s = time.monotonic() + TRUTH_LOG_WAIT_S
    truth_log = read_truth_log(path)
    while (not len(truth_log) or truth_log[-1, 0] < last_capture_s) and time.monotonic() < deadline_s:
        time.sleep(0.25)
        truth_log = read_truth_log(path)
    if not len(truth_log):
        log.warning(f"{path}: the truth log holds no picture; the run is not scored (is serve-camera writing it?)")
        return None
    if truth_log[-1, 0] < last_capture_s:
        log.warning(
            f"{path}: the truth log ends {last_capture_s - truth_log[-1, 0]:.1f} s before the run's last picture; "
            "the pictures after its end are scored against its last step"
        )
    return truth_log


def _print_metrics(episode: Episode, live: LiveEpisode, truth_log: np.ndarray | None, truth_path: Path | None) -> dict:
    """A live run's figures, printed and returned: its pace (:func:`live_metrics`) and what the camera saw,
    and with a truth log the scores and the recording's steps its pictures were scored against (those of
    the offline run to compare it with); without, no score (a real camera's run has no truth)."""
    metrics = {**episode_metrics(episode, with_truth=truth_log is not None), **live_metrics(live)}
    print(
        f"{metrics['pictures']} pictures used ({metrics['frames_used_per_s']:.2f} per second) of "
        f"{metrics['frames_received']} received, {metrics['decisions']} decisions "
        f"({metrics['decisions_per_s']:.2f} per second, median {1e3 * metrics['median_decision_s']:.1f} ms, "
        f"95 % on a picture at most {metrics['frame_age_s_p95']:.2f} s old), {metrics['targets_sent']} new targets "
        f"sent, {metrics['tracks_reported']} tracks reported"
    )
    if truth_log is not None and len(live.capture_time_s):
        first_step, last_step = shown_span(truth_log, live.capture_time_s)
        print(f"scored against the recording's steps {first_step} to {last_step} (truth log {truth_path})")
    print(format_metrics(metrics))
    return metrics


def _run_folder_files(with_truth: bool) -> list[str]:
    """The files a live run writes into ``--out``: without truth, no truth_mot.txt."""
    return [name for name in RUN_FOLDER_FILES if with_truth or name != TRUTH_MOT_FILE]


def read_truth_log(path: Path) -> np.ndarray:
    """A virtual camera's truth log (``ptztrack serve-camera --truth-log``), (n, 5); read while the camera
    writes it, so an empty file (one it has just opened) has no rows and a last line not yet ended is
    left for the next read."""
    text = read_text(path, "truth log", 1_000_000_000, ScenarioError)
    lines = text.splitlines()[: None if text.endswith("\n") else -1]
    if lines and lines[0] != TRUTH_LOG_HEADER:
        raise ScenarioError(f"{path}: expected a truth log starting with the line {TRUTH_LOG_HEADER}")
    if len(lines) <= 1:  # nothing, or the header only: the camera has logged no picture yet
        return np.empty((0, 5))
    try:
        rows = np.array([[float(value) for value in line.split(",")] for line in lines[1:] if line], dtype=float)
    except ValueError:
        raise ScenarioError(f"{path}: a line of the truth log is not five numbers") from None
    if rows.ndim != 2 or rows.shape[1:] != (5,) or not np.all(np.isfinite(rows)):
        raise ScenarioError(f"{path}: expected rows of five finite numbers ({TRUTH_LOG_HEADER})")
    return rows


def calibrate_camera_command(args: argparse.Namespace) -> int:
    from ptztrack.cli.calibrate import calibrate_geometry_command, calibration_to_time

    if args.geometry:
        return calibrate_geometry_command(args, _credentials(args))
    if args.snapshot is not None or args.ground_points is not None:
        raise ScenarioError("camera calibrate: --snapshot and --ground-points go with --geometry")
    calibration = calibration_to_time(args.calibration)
    check_output_file(args.calibration, "--calibration")  # rewritten after minutes of timed moves
    client = ONVIFClient(camera_address(args.camera, _credentials(args)), args.timeout_s)
    stream = None
    try:
        client.connect()
        spaces = camera_spaces(calibration)
        home = client.status().position  # where the camera was put to look: its stream's delay is timed there
        uri = client.stream_uri()
        stream = FrameStream(rtsp_pictures(uri), delay_s=0.0)
        stream.start()  # opening a stream takes seconds: it opens while the moves are timed
        move_times, samples = measure_move_times(client, spaces)
        timed_move(client, home)
        for axis, (distances, seconds) in samples.items():
            intercept, slope = getattr(move_times, axis)
            unit = "zoom" if axis == "zoom" else "deg"
            print(
                f"{axis}: {intercept:.3f} s + {slope:.4f} s/{unit} "
                f"({len(seconds)} moves of {distances.max():.3g} {unit} at most)"
            )
        image_delay_s, capture_time_sd_s, delays = measure_image_delay(client, spaces, move_times, stream.latest)
        print(
            f"image delay: {image_delay_s:.3f} s (median of {len(delays)} pans, standard deviation "
            f"{capture_time_sd_s:.4f} s: a capture time's uncertainty)"
        )
    finally:
        if stream is not None:
            stream.stop()
        client.close()
    section = MoveTimesSection(pan=move_times.pan, tilt=move_times.tilt, zoom=move_times.zoom)
    update = {
        "move_times": section,
        "image_delay_s": round(image_delay_s, 4),
        "capture_time_sd_s": round(capture_time_sd_s, 4),
    }
    write_camera_calibration(args.calibration, calibration.model_copy(update=update))
    print(f"wrote move_times, image_delay_s and capture_time_sd_s into {args.calibration}")
    return 0


def serve_camera_command(args: argparse.Namespace) -> int:
    scenario = build_scenario(args.scenario, dataset=args.dataset, view=args.dataset_view)
    credentials = _credentials(args) or {}
    username = args.user or credentials.get("username", "")
    password = credentials.get("password") or os.environ.get(PASSWORD_VARIABLE, "")
    if bool(username) != bool(password):
        raise ScenarioError(
            f"serve-camera: give a user and a password (--user with --credentials or ${PASSWORD_VARIABLE}), "
            "or neither for a camera without authentication"
        )
    # Camera k on the port after camera k - 1's; port 0 gives each camera any free port.
    ports = [args.port + k if args.port else 0 for k in range(args.cameras)]
    if ports[-1] > 65535:
        raise ScenarioError(f"serve-camera: {args.cameras} cameras from port {args.port} go past port 65535")
    # A geometry of its own is the camera's truth, not told to its clients: they must calibrate it.
    geometry, hidden = None, args.geometry is not None or args.geometry_seed is not None
    shown = "hidden" if hidden else "virtual"
    if hidden:
        option = "--geometry" if args.geometry is not None else f"--geometry-seed {args.geometry_seed}"
        try:
            geometry = virtual_geometry(scenario, args.geometry_seed, args.geometry)
        except ScenarioError as error:
            raise ScenarioError(f"serve-camera {option}: {error}") from None
    if args.presets is not None:
        for number in range(1, args.cameras + 1):
            check_output_file(camera_presets_path(args.presets, number), "--presets")
    cameras = virtual_onvif_cameras(
        scenario, args.time_scale, ports, username, password, geometry, not args.no_positions,
        not args.relative_only, args.presets, args.supersample,
    )  # fmt: skip
    # The cameras share the recording's clock, so the first camera's log gives every camera's steps.
    feed = cameras[0][1]
    log_file = None if args.truth_log is None else open(args.truth_log, "w", encoding="utf-8")  # noqa: SIM115
    written = 0
    started = []
    try:
        for camera, _ in cameras:
            camera.start()
            started.append(camera)
            print(f"virtual ONVIF camera: onvif://127.0.0.1:{camera.onvif_port} (calibration: {shown})", flush=True)
            if camera.rtsp_port is not None:
                print(f"RTSP: rtsp://127.0.0.1:{camera.rtsp_port}/", flush=True)
        print(f"the recording plays in a loop, {feed.duration_s:.0f} s a play at this time scale", flush=True)
        if log_file is not None:
            log_file.write(TRUTH_LOG_HEADER + "\n")
        while True:
            time.sleep(0.5)
            if log_file is not None:
                rows = feed.rows(written)
                log_file.writelines(
                    f"{row[0]:.6f},{int(row[1])},{row[2]:.6f},{row[3]:.6f},{row[4]:.6f}\n" for row in rows
                )
                log_file.flush()
                written += len(rows)
    except KeyboardInterrupt:
        print(f"virtual ONVIF camera{'s' if len(cameras) > 1 else ''} stopped", file=sys.stderr)
    finally:
        for camera in started:
            camera.stop()
        if log_file is not None:
            log_file.close()
    return 0
