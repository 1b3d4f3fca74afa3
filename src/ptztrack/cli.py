"""The ``ptztrack`` command: a thin layer over the Python API."""

import argparse
import logging
import math
import os
import sys
import tempfile
import time
from functools import partial
from pathlib import Path

import numpy as np

from ptztrack import registry
from ptztrack.builders.budget import refuse_if_too_large
from ptztrack.builders.episode import episode_world, make_policy, run_episode
from ptztrack.builders.experiments import (
    POSE_SOURCES,
    STRATEGIES,
    closed_loop_cells,
    live_view_settings,
    recording_cells,
    registration_views,
    run_cell,
    run_closed_loop_cell,
    shared_views_key,
    synthetic_cells,
)
from ptztrack.builders.follow import FOLLOW_TRACKERS
from ptztrack.builders.follow_experiment import (
    OTB_TRACKS,
    FollowCell,
    follow_cells,
    follow_row,
    follow_run,
    otb_cells,
    run_follow_cell,
    run_otb_cell,
)
from ptztrack.builders.live import (
    TRUTH_LOG_HEADER,
    camera_spaces,
    live_as_episode,
    live_pictures,
    run_live_episode,
    virtual_calibration,
    virtual_onvif_camera,
)
from ptztrack.builders.occupancy import ROOM_FRAMES, dataset_runs, room_runs
from ptztrack.builders.pets import PROTOCOLS, protocol_folds
from ptztrack.builders.registration import reference_index
from ptztrack.camera.move_timing import measure_image_delay, measure_move_times, timed_move
from ptztrack.camera.onvif_client import PASSWORD_VARIABLE, ONVIFClient, camera_address
from ptztrack.camera.stream import FrameStream, rtsp_pictures
from ptztrack.config import (
    LiveView,
    MoveTimesSection,
    PoseError,
    Scenario,
    ScenarioError,
    load_camera_calibration,
    load_dataset,
    load_scenario,
    pets_dataset,
    pets_follow_scenario,
    pets_scenario,
    read_yaml,
    scenario_from_dict,
    write_camera_calibration,
)
from ptztrack.control.msg_scheduler import SCHEDULERS
from ptztrack.evaluate.executors import EXECUTORS, Progress, run_cells
from ptztrack.evaluate.follow import (
    FOLLOW_FIGURES,
    OTB_FIGURES,
    format_follow_people,
    format_follow_table,
    summarise_follow,
)
from ptztrack.evaluate.metrics import DISPLAY, episode_metrics
from ptztrack.evaluate.msg import (
    ambiguity_figure,
    format_ambiguity_table,
    format_paired_differences,
    msg_cells,
    run_msg,
    run_msg_cell,
    summarise_by_ambiguity,
    trails_figure,
)
from ptztrack.evaluate.occupancy_output import write_occupancy_outputs
from ptztrack.evaluate.registration import summarise_registration
from ptztrack.evaluate.report import RUN_FILES, write_figure, write_outputs
from ptztrack.evaluate.tables import format_table, paired_difference, summarise
from ptztrack.evaluate.video import view_renderer
from ptztrack.evaluate.view_state import VIEW_STATES_FILE, StepView, ViewState, read_view_states
from ptztrack.evaluate.web_view import ViewHub, ViewServer, replay
from ptztrack.files import InputError, check_output_file, check_output_folder, read_text, run_folder, write_json
from ptztrack.loop import StepObserver
from ptztrack.scene.roads import walk_roads

RUN_FOLDER_FILES = (*RUN_FILES, VIEW_STATES_FILE)  # what run, follow and live write into --out
DETECTOR_MODEL_FILE = "detector_model.json"  # and what run adds: the detector model as the run ended
RUN_FIGURES = ("mota", "motp_m", "idf1", "height_px", "detections", "zoom", "switches")


def build_scenario(
    name_or_path: str,
    detector: str | None = None,
    frames: int | None = None,
    recording_paths: dict | None = None,
    association: str | None = None,
    measurement_source: str | None = None,
    detector_model: str | None = None,
    prior_shift_px: float | None = None,
) -> Scenario:
    """The built-in synthetic or PETS scene or a YAML file, with command-line overrides applied.

    recording_paths : {'video' | 'calibration' | 'ground_truth': path} replacing the recording's files.
    association : 'hungarian' or 'cjpdaf', replacing ``tracker.association``.
    measurement_source : 'detector' or 'spatiogram', replacing ``tracker.measurement_source``.
    detector_model, prior_shift_px : replacing ``detector.model`` and ``detector.prior_shift_px``.
    """
    overrides: dict[str, object] = {
        f"recording.{key}": str(path) for key, path in (recording_paths or {}).items() if path is not None
    }
    if detector_model is not None:
        overrides["detector.model"] = detector_model
    if prior_shift_px is not None:
        overrides["detector.prior_shift_px"] = prior_shift_px
    if association is not None:
        overrides["tracker.association"] = association
    if measurement_source is not None:
        overrides["tracker.measurement_source"] = measurement_source
    if detector is not None:
        overrides["detector.kind"] = detector
    if frames is not None:
        overrides["frames"] = frames
    if name_or_path == "synthetic":
        return scenario_from_dict({}, "synthetic", **overrides)
    if name_or_path == "pets":
        return pets_scenario(str(overrides.pop("detector.kind", "ideal")), **overrides)
    return load_scenario(name_or_path, **overrides)


def recording_paths(args: argparse.Namespace) -> dict:
    return {"video": args.video, "calibration": args.calibration, "ground_truth": args.gt}


def format_metrics(metrics: dict) -> str:
    width = max(len(DISPLAY[key][0]) for key in RUN_FIGURES)
    return "\n".join(f"{DISPLAY[key][0]:<{width}}  {DISPLAY[key][1].format(metrics[key])}" for key in RUN_FIGURES)


def run_command(args: argparse.Namespace) -> int:
    scenario = build_scenario(
        args.scenario,
        args.detector,
        args.frames,
        recording_paths(args),
        args.association,
        args.measurement_source,
        args.detector_model,
        args.prior_shift_px,
    )
    refuse_if_too_large(scenario, (args.policy,))
    world = episode_world(scenario, args.seed)
    policy = make_policy(args.policy, scenario, world)
    watch = Watch(args.view, args.out is not None, partial(_run_view, label=args.policy), Progress("step", args.quiet))
    with watch:
        episode = run_episode(scenario, policy, args.seed, world, observer=watch.observe(world, policy))
    metrics = episode_metrics(episode)
    print(
        f"scenario {args.scenario}, policy {args.policy}, detector {scenario.detector.kind}, "
        f"seed {args.seed}, {len(episode.actions)} steps, {episode.truth.positions_m.shape[1]} people"
    )
    print(format_metrics(metrics))
    if args.out is not None:
        title = f"{args.policy}, {scenario.detector.kind} detector, seed {args.seed}: MOTA {metrics['mota']:.1%}"
        with run_folder(args.out, args.overwrite) as folder:
            write_outputs(folder, episode, metrics, title, view_renderer(world))
            watch.write(folder)
            if world.detector_model is not None:
                world.detector_model.save(folder / DETECTOR_MODEL_FILE)
        print(f"wrote {', '.join((*RUN_FOLDER_FILES, DETECTOR_MODEL_FILE))} into {args.out}")
    return 0


def _run_view(world, policy, label: str) -> ViewState:
    """The view of a run in ``world``: the backend's images (the synthetic scene's drawn), its grid."""
    return ViewState(world, policy, world.truth.positions_m.shape[0], label, view_renderer(world))


class Watch:
    """What watches a run of ``run``, ``follow`` or ``live``: the web view on 127.0.0.1:``port`` (None:
    none; a context manager: the server runs inside the block), where ``keep``, every step's view
    state, for the run folder's view_states.jsonl (what ``ptztrack view`` replays), and a progress bar
    of the steps (``progress``; None: none).

    view : ``view(world, policy)`` gives the run's :class:`ViewState`.
    """

    def __init__(self, port: int | None, keep: bool, view, progress: Progress | None = None):
        self.view, self.port, self.keep, self.progress = view, port, keep, progress
        self.views: list[StepView] = []
        self.view_state: ViewState | None = None
        # A run started with a view waits after its first step for a page to open it.
        self.hub = None if port is None else ViewHub(paused=True, resume_on_connect=True)
        self._server: ViewServer | None = None

    def __enter__(self) -> "Watch":
        if self.hub is not None and self.port is not None:
            self._server = ViewServer(self.hub, self.port).__enter__()
            print(f"view at {self._server.address} (the run starts when a page opens it)", flush=True)
        return self

    def __exit__(self, *failure) -> None:
        if self.progress is not None:
            self.progress.close()
        if self._server is not None:
            self._server.__exit__(*failure)

    def observe(self, world, policy) -> StepObserver | None:
        """The run's step observer (None when nothing watches)."""
        view_state = self.view_state = self.view(world, policy)
        watching = None
        if self.hub is not None or self.keep:
            watching = view_state.observer(
                None if self.hub is None else self.hub.after_step, self.views if self.keep else None
            )
        progress = self.progress
        if progress is None:
            return watching

        def observe(step: int, context, record: dict) -> None:
            if watching is not None:
                watching(step, context, record)
            progress(step + 1, view_state.steps)

        return observe

    def write(self, folder: Path) -> None:
        """view_states.jsonl into the run's folder."""
        assert self.view_state is not None, "observe() gives the run its observer first"
        self.view_state.write(folder / VIEW_STATES_FILE, self.views)


def view_command(args: argparse.Namespace) -> int:
    lines = read_view_states(args.folder)
    hub = ViewHub(paused=True, resume_on_connect=True)
    with ViewServer(hub, args.port) as server:
        print(f"view at {server.address} (the replay of {len(lines)} steps starts when a page opens it)", flush=True)
        replay(hub, lines, args.steps_per_s)
    return 0


def _credentials(args: argparse.Namespace) -> dict | None:
    """The ``--credentials`` file's {username, password}, if given (a YAML or JSON mapping)."""
    if args.credentials is None:
        return None
    data = read_yaml(args.credentials, "credentials", ScenarioError)
    if not isinstance(data, dict) or not set(data) <= {"username", "password"}:
        raise ScenarioError(f"{args.credentials}: expected a mapping with username and password")
    return {key: str(value) for key, value in data.items()}


def live_command(args: argparse.Namespace) -> int:
    scenario = build_scenario(args.scenario, args.detector, detector_model=args.detector_model)
    calibration = virtual_calibration() if args.calibration == "virtual" else load_camera_calibration(args.calibration)
    address = camera_address(args.camera, _credentials(args))
    truth_log = None if args.truth is None else read_truth_log(args.truth)
    steps = args.steps or scenario.frames
    print(f"live: {args.policy} on {address}, up to {steps} pictures, RTSP over {args.transport}")
    label = f"live {args.policy}"
    with Watch(args.view, args.out is not None, lambda w, p: ViewState(w, p, steps, label, truth=False)) as watch:
        world, live = run_live_episode(
            scenario, calibration, address, args.policy, steps, args.time_scale, args.seed, args.timeout_s,
            watch.observe, args.transport, keep_images=args.out is not None,
        )  # fmt: skip
    episode = live_as_episode(world, live, truth_log)
    rates = live.rates()
    print(
        f"{len(live.capture_time_s)} pictures used ({rates['frames_used_per_s']:.2f} per second) of "
        f"{live.frames_received} received, {int(np.isfinite(live.decided_s).sum())} decisions "
        f"({rates['decisions_per_s']:.2f} per second, median {1e3 * rates['median_decision_s']:.1f} ms, "
        f"95 % on a picture at most {rates['frame_age_s_p95']:.2f} s old), {int(live.sent.sum())} new targets sent"
    )
    metrics = episode_metrics(episode)
    if truth_log is not None:
        print(format_metrics(metrics))
    if args.out is not None:
        title = f"live {args.policy}, {scenario.detector.kind} detector: {len(live.capture_time_s)} pictures"
        with run_folder(args.out, args.overwrite) as folder:
            write_outputs(folder, episode, metrics, title, live_pictures(live))
            watch.write(folder)
        print(f"wrote {', '.join(RUN_FOLDER_FILES)} into {args.out}")
    return 0


def read_truth_log(path: Path) -> np.ndarray:
    """A virtual camera's truth log (``ptztrack serve-camera --truth-log``), (n, 5)."""
    lines = read_text(path, "truth log", 1_000_000_000, ScenarioError).splitlines()
    if not lines or lines[0] != TRUTH_LOG_HEADER:
        raise ScenarioError(f"{path}: expected a truth log starting with the line {TRUTH_LOG_HEADER}")
    try:
        rows = np.array([[float(value) for value in line.split(",")] for line in lines[1:] if line], dtype=float)
    except ValueError:
        raise ScenarioError(f"{path}: a line of the truth log is not five numbers") from None
    if rows.ndim != 2 or rows.shape[1:] != (5,) or not np.all(np.isfinite(rows)):
        raise ScenarioError(f"{path}: expected rows of five finite numbers ({TRUTH_LOG_HEADER})")
    return rows


def calibrate_camera_command(args: argparse.Namespace) -> int:
    calibration = load_camera_calibration(args.calibration)
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
        image_delay_s, delays = measure_image_delay(client, spaces, move_times, stream.latest)
        print(f"image delay: {image_delay_s:.3f} s (median of {len(delays)} pans, {np.ptp(delays):.3f} s apart)")
    finally:
        if stream is not None:
            stream.stop()
        client.close()
    section = MoveTimesSection(pan=move_times.pan, tilt=move_times.tilt, zoom=move_times.zoom)
    update = {"move_times": section, "image_delay_s": round(image_delay_s, 4)}
    write_camera_calibration(args.calibration, calibration.model_copy(update=update))
    print(f"wrote move_times and image_delay_s into {args.calibration}")
    return 0


def serve_camera_command(args: argparse.Namespace) -> int:
    scenario = build_scenario(args.scenario)
    credentials = _credentials(args) or {}
    username = args.user or credentials.get("username", "")
    password = credentials.get("password") or os.environ.get(PASSWORD_VARIABLE, "")
    if bool(username) != bool(password):
        raise ScenarioError(
            f"serve-camera: give a user and a password (--user with --credentials or ${PASSWORD_VARIABLE}), "
            "or neither for a camera without authentication"
        )
    camera, feed = virtual_onvif_camera(scenario, args.time_scale, args.port, username, password)
    log_file = None if args.truth_log is None else open(args.truth_log, "w", encoding="utf-8")  # noqa: SIM115
    written = 0
    camera.start()
    try:
        print(f"virtual ONVIF camera: onvif://127.0.0.1:{camera.onvif_port} (calibration: virtual)", flush=True)
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
        print("virtual ONVIF camera stopped", file=sys.stderr)
    finally:
        camera.stop()
        if log_file is not None:
            log_file.close()
    return 0


def _run_cells(args: argparse.Namespace, cells: list, run, noun: str = "episode", together=None) -> list:
    """An experiment's cells on ``--executor``, with a progress bar (none with ``--quiet`` or off a terminal);
    ``together`` as :func:`run_cells`'."""
    with Progress(noun, args.quiet) as progress:
        return run_cells(cells, run, args.executor, args.workers, progress, together)


def msg_experiment_command(args: argparse.Namespace) -> int:
    cells = msg_cells(args.runs)
    print(f"{len(cells)} simulations x {len(SCHEDULERS)} schedulers, {args.executor} executor", file=sys.stderr)
    rows = [row for rows in _run_cells(args, cells, run_msg_cell, "simulation") for row in rows]
    print("Face capture on the MSG: M by N_j/s bin, mean +- standard deviation (runs)")
    print(format_ambiguity_table(summarise_by_ambiguity(rows)))
    print(format_paired_differences(rows))
    written = []
    if args.json is not None:
        write_json(args.json, rows)
        written.append(args.json)
    if args.plot is not None:
        write_figure(args.plot, ambiguity_figure(rows))
        written.append(args.plot)
    if args.trails is not None:
        cell = cells[0]
        scene = walk_roads(cell.scene, np.random.default_rng(cell.seed))
        run = run_msg(scene, "msg", cell.tracker, cell.zoom_out_score, cell.seed, cell.zoomed_half_width_m)
        title = f"simulation {cell.seed}: {cell.scene.people} walkers, N_j/s {scene.nj_s}, msg scheduler, M {run.m:.2f}"
        write_figure(args.trails, trails_figure(scene, run, title))
        written.append(args.trails)
    if written:
        print(f"wrote {', '.join(str(path) for path in written)}")
    return 0


def registration_experiment_command(args: argparse.Namespace) -> int:
    scenario = build_scenario(
        args.scenario,
        args.detector,
        args.frames,
        recording_paths(args),
        args.association,
        args.measurement_source,
        args.detector_model,
    )
    if scenario.recording is None or scenario.recording.video is None:
        raise ScenarioError(f"{args.scenario}: the registration experiment needs a recording with a video")
    live_view = None if args.exact_views else scenario.camera.live_view or LiveView()
    scenario = scenario.model_copy(update={"camera": scenario.camera.model_copy(update={"live_view": live_view})})
    settings = live_view_settings(scenario)
    with tempfile.TemporaryDirectory() as scratch:
        index_path = args.index or Path(scratch) / "index.npz"
        feedback = scenario.pose_feedback.model_copy(update={"index": str(index_path)})
        scenario = scenario.model_copy(update={"pose_feedback": feedback})
        built = not Path(index_path).exists()
        print(f"{'building' if built else 'reading'} the reference index {index_path}", file=sys.stderr)
        index = reference_index(scenario)
        print(f"{len(index.poses)} reference views; registering {args.views} live views", file=sys.stderr)
        with Progress("view", args.quiet) as progress:
            views = registration_views(scenario, index, args.views, args.seed, progress)
        summary = summarise_registration(views)
        pose_error = PoseError(pan_tilt_sigma_deg=args.pose_noise_deg, zoom_sigma=args.zoom_noise)
        cells = closed_loop_cells(scenario, pose_error, args.policy, args.pose_sources)
        print(f"{len(cells)} closed-loop runs, {args.executor} executor", file=sys.stderr)
        closed_loop = _run_cells(args, cells, run_closed_loop_cell)
    size = scenario.pose_feedback.image_size_px
    print(
        f"Registration of {summary['views']} live views at random reachable poses, {size[0]} x {size[1]} px, "
        f"against {len(index.poses)} reference views: {summary['registered']} registered"
    )
    print(f"  {_describe_live_views(settings)}")
    for name, key, unit in (
        ("focal length error", "focal_err", "pct"),
        ("ground error", "ground_err", "m"),
        ("  with true pose", "oracle_ground_err", "m"),
        ("  with lens", "lens_ground_err", "m"),
    ):
        median, p90 = (_unless_failed(summary[f"{key}_{which}_{unit}"]) for which in ("median", "p90"))
        symbol = "%" if unit == "pct" else unit
        print(f"  {name:<19} median {median} {symbol}   p90 {p90} {symbol}")
    print(f"  time per view       median {summary['register_ms_median']:.0f} ms")
    print(
        f"\nClosed loop: {args.policy}, {scenario.detector.kind} detector, {scenario.tracker.association} association, "
        f"camera off its commands by {args.pose_noise_deg:g} deg and {100 * args.zoom_noise:g} % zoom (1 sigma)"
    )
    width = max(len(name) for name in POSE_SOURCES)
    print(f"  {'pose source':<{width + 2}} MOTA     MOTP [m]  pose known  tracker pose error (pan, tilt, zoom)")
    for row in closed_loop:
        print(
            f"  {row['pose_source']:<{width + 2}} {row['mota']:6.1%}   {row['motp_m']:.3f}     {row['pose_known']:6.1%}"
            f"      {row['tracker_pan_err_deg']:.3f} deg, {row['tracker_tilt_err_deg']:.3f} deg, "
            f"{row['tracker_zoom_err_pct']:.2f} %"
        )
    if args.json is not None:
        document = {**summary, "live_view_model": settings, "closed_loop": closed_loop, "views_detail": views}
        write_json(args.json, document)
        print(f"wrote {args.json}")
    return 0


def _describe_live_views(settings: dict) -> str:
    """One line on the registration experiment's live views (see ``live_view_settings``)."""
    frames = (
        f"reference views of frames {settings['reference_frames'][0]}-{settings['reference_frames'][1]}, "
        f"live views of frames {settings['first_live_frame']} on"
    )
    if settings["exact"]:
        return f"exact pinhole live views; {frames}"
    k1 = f"k1 {settings['k1_wide']:g} at zoom 1 to {settings['k1_tele']:g} at zoom {settings['tele_zoom']:g}"
    return (
        f"live views rolled up to {settings['roll_max_deg']:g} deg, principal point up to "
        f"{settings['principal_offset_max_px']:g} px off, {k1}, gain {settings['gain'][0]:g}-{settings['gain'][1]:g}, "
        f"brightness +-{settings['brightness_max']:g}, JPEG quality {settings['jpeg_quality']}; {frames}"
    )


def _unless_failed(error: float | None) -> str:
    """An error statistic, or what it means when it fell on views that were not registered."""
    return "(unregistered views)" if error is None else f"{error:.3f}"


def synthetic_experiment_command(args: argparse.Namespace) -> int:
    scenario = build_scenario(
        args.scenario,
        args.detector,
        args.frames,
        association=args.association,
        measurement_source=None,
        detector_model=args.detector_model,
        prior_shift_px=args.prior_shift_px,
    )
    cells = synthetic_cells(scenario, args.sequences, args.strategies)
    title = (
        f"{args.scenario} scene, {scenario.detector.kind} detector, beta {scenario.control.beta:g}, "
        f"detector model {scenario.detector.model} (prior shifted {scenario.detector.prior_shift_px:g} px), "
        f"{args.sequences} sequences of {scenario.frames} frames (means over sequences)"
    )
    model = {"detector_model": scenario.detector.model, "prior_shift_px": scenario.detector.prior_shift_px}
    return _run_table(args, cells, title, extra=model)


def pets_experiment_command(args: argparse.Namespace) -> int:
    scenario = build_scenario(
        "pets",
        args.detector,
        args.frames,
        recording_paths(args),
        args.association,
        args.measurement_source,
        args.detector_model,
    )
    folds = protocol_folds(scenario, args.protocol)
    for fold in folds:
        if fold.fitted:
            fitted = ", ".join(f"{name} {value:.4g}" for name, value in fold.fitted.items())
            print(f"fold {fold.index}: fitted on the other half's frames: {fitted}", file=sys.stderr)
    betas = args.beta or [9.0, 1.0]
    cells = [
        cell
        for fold in folds
        for cell in recording_cells(fold.scenario, betas, args.strategies, args.seeds, fold.index)
    ]
    title = (
        f"PETS 2009 S2.L1 View_001, {scenario.detector.kind} detector ({scenario.detector.model} model), every 2nd "
        f"frame, protocol {args.protocol}, "
        f"{args.seeds} seeds where a run depends on its seed (MOTA +- standard deviation over seeds and folds)"
    )
    extra = {
        "protocol": args.protocol,
        "fitted": [fold.fitted for fold in folds],
        "detector_model": scenario.detector.model,
    }
    return _run_table(args, cells, title, "mota_sd", extra, together=shared_views_key)


def _run_table(
    args: argparse.Namespace,
    cells: list,
    title: str,
    spread: str = "mota_se",
    extra: dict | None = None,
    together=None,
) -> int:
    print(f"{len(cells)} episodes, {args.executor} executor", file=sys.stderr)
    runs_at_once = 1 if args.executor == "serial" else min(len(cells), args.workers or os.cpu_count() or 1)
    refuse_if_too_large(cells[0].scenario, tuple(args.strategies), runs_at_once)
    summary = summarise(_run_cells(args, cells, run_cell, together=together))
    summary = [{**row, **(extra or {})} for row in summary]
    print(format_table(summary, title, spread))
    labels = {row["label"] for row in summary}
    if {"smpl", "intg"} <= labels and summary[0]["sequences"] > 1:
        mean, error, count = paired_difference(summary, "smpl", "intg")
        paired = f"paired over {count} sequences, standard error"
        print(f"smpl - intg: {100 * mean:+.1f} +- {100 * error:.1f} MOTA points ({paired})")
    if args.json is not None:
        write_json(args.json, summary)
        print(f"wrote {args.json}")
    return 0


def _follow_scenario(args: argparse.Namespace, tracker: str = "particle") -> Scenario:
    """The follow camera's scenario: the built-in PETS one or a YAML file, with the command line's changes."""
    overrides: dict[str, object] = {
        f"recording.{key}": str(path) for key, path in recording_paths(args).items() if path is not None
    }
    if args.achromatic_bins:
        overrides["follow.achromatic_bins"] = True
    if getattr(args, "target_point_px", None) is not None:
        overrides["follow.target_point_px"] = tuple(args.target_point_px)
    if args.scenario == "pets":
        return pets_follow_scenario(tracker, **overrides)
    return load_scenario(args.scenario, **overrides, **{"tracker.kind": tracker})


def follow_command(args: argparse.Namespace) -> int:
    out = args.out or Path(f"follow-{args.target}")
    check_output_folder(out, "--out", args.overwrite)
    scenario = _follow_scenario(args, args.tracker)
    if args.frames is not None:
        scenario = scenario.model_copy(update={"frames": args.frames})
    label = f"follow person {args.target}, {args.tracker}"

    def view(world, policy) -> ViewState:
        target_point_px = policy.parameters.target_point_px
        steps = world.truth.positions_m.shape[0]
        return ViewState(world, policy, steps, label, view_renderer(world), grid=False, target_point_px=target_point_px)

    with Watch(args.view, True, view, Progress("step", args.quiet)) as watch:
        narrowed, world, episode = follow_run(FollowCell(scenario, args.tracker, args.target, args.seed), watch.observe)
    row = follow_row(narrowed, world, episode)
    frame_range = narrowed.required_recording("the follow camera").frame_range
    first_frame = frame_range[0] if frame_range is not None else 0
    print(f"person {args.target} followed by {args.tracker} from frame {first_frame}, {row['steps']} steps")
    print(format_follow_table([row], FOLLOW_FIGURES))
    title = f"person {args.target}, {args.tracker}: in view {row['in_view_fraction']:.0%}"
    with run_folder(out, args.overwrite) as folder:
        write_outputs(folder, episode, row, title, view_renderer(world))
        watch.write(folder)
    print(f"wrote {', '.join(RUN_FOLDER_FILES)} into {out}")
    return 0


def follow_experiment_command(args: argparse.Namespace) -> int:
    scenario = _follow_scenario(args)
    cells = follow_cells(scenario, args.trackers, args.targets, args.seed)
    print(f"{len(cells)} closed-loop runs, {args.executor} executor", file=sys.stderr)
    people = _run_cells(args, cells, run_follow_cell)
    otb_runs = otb_cells(scenario, args.trackers, args.otb_tracks, args.seed)
    print(f"{len(otb_runs)} one-pass runs on the still recording", file=sys.stderr)
    otb_people = _run_cells(args, otb_runs, run_otb_cell, "run")
    closed_loop, otb = summarise_follow(people, FOLLOW_FIGURES), summarise_follow(otb_people, OTB_FIGURES)
    print(
        f"Follow camera, {scenario.camera.image_size_px[0]} x {scenario.camera.image_size_px[1]} view, "
        f"person {scenario.follow.target_height_px:g} px tall wanted; per person:"
    )
    print(format_follow_people(people))
    print(format_follow_table(closed_loop, FOLLOW_FIGURES, "\nMeans over the people:"))
    tracks = ", ".join(str(row["target_id"]) for row in otb_people[: len(otb_people) // len(args.trackers)])
    print(format_follow_table(otb, OTB_FIGURES, f"\nOne-pass (OTB) on the still recording, people {tracks}:"))
    if args.json is not None:
        document = {"closed_loop": closed_loop, "otb": otb, "people": people, "otb_people": otb_people}
        write_json(args.json, document)
        print(f"wrote {args.json}")
    return 0


OCCUPANCY_COLUMNS = (
    ("method", "{}"),
    ("people", "{}"),
    ("moda", "{:.1%}"),
    ("modp", "{:.1%}"),
    ("precision", "{:.1%}"),
    ("recall", "{:.1%}"),
    ("error_m", "{:.3f}"),
    ("mota", "{:.1%}"),
    ("motp_m", "{:.3f}"),
    ("idf1", "{:.1%}"),
)


def occupancy_experiment_command(args: argparse.Namespace) -> int:
    with Progress("frame", args.quiet) as progress:
        if args.dataset == "synthetic-room":
            runs = room_runs(args.frames or ROOM_FRAMES, args.seed, progress)
        else:
            dataset = pets_dataset() if args.dataset == "pets" else load_dataset(args.dataset)
            runs = dataset_runs(dataset, args.frames, progress)
    rows = [row for run in runs for row in run.rows]
    columns = [(key, form) for key, form in OCCUPANCY_COLUMNS if any(key in row for row in rows)]
    print(f"Occupancy-map detection on {args.dataset}: MODA, MODP, precision, recall within 0.5 m; tracker fed by LPOM")
    print("  ".join(f"{key:>10}" for key, _ in columns))
    for row in rows:
        print("  ".join(f"{form.format(row[key]) if key in row else '':>10}" for key, form in columns))
    for row in rows:
        fitted = {key: value for key, value in row.items() if key.startswith("fitted_")}
        print(f"{row['dataset']} {row['method']}: {fitted} (each half of the frames scored with the other's fit)")
    written = []
    if args.out is not None:
        with run_folder(args.out, args.overwrite) as folder:
            for run in runs:
                write_occupancy_outputs(folder / str(run.rows[0]["dataset"]), run, args.images_every)
        written.append(args.out)
    if args.json is not None:
        write_json(args.json, rows)
        written.append(args.json)
    if written:
        print(f"wrote {', '.join(str(path) for path in written)}")
    return 0


class OneLineParser(argparse.ArgumentParser):
    """Command-line mistakes end in one line on stderr and exit status 2, like every other bad input."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def parser() -> argparse.ArgumentParser:
    root = OneLineParser(prog="ptztrack", description="Multi-person tracking with a PTZ camera.")
    commands = root.add_subparsers(dest="command", required=True)
    policies, detectors = registry.names("policies"), registry.names("detectors")
    run = commands.add_parser("run", help="run one closed-loop episode and print its metrics")
    run.add_argument(
        "--scenario", default="synthetic", help="'synthetic' or 'pets' (built in), or a scenario YAML file"
    )
    run.add_argument("--policy", choices=policies, default="smpl")
    run.add_argument("--detector", choices=detectors, help="overrides the scenario's detector")
    run.add_argument(
        "--prior-shift-px",
        type=float,
        help="shifts the prior recall curve's r0 by this many pixels from the detector's own (a test of the learning)",
    )
    run.add_argument(
        "--detector-model",
        help="what the policies and the tracker know of the detector: online (learned as the camera runs; the "
        "default), a-priori (the prior curve, kept), true (a simulation's own curve) or an earlier run's "
        "detector_model.json as the prior",
    )
    run.add_argument("--seed", type=_non_negative_int, default=0)
    run.add_argument("--frames", type=_positive_int, help="overrides the scenario's number of frames")
    _add_tracker_arguments(run)
    run.add_argument(
        "--out", type=Path, help=f"directory for {', '.join(RUN_FOLDER_FILES)}; written whole or not at all"
    )
    run.add_argument("--overwrite", action="store_true", help="replace a non-empty --out folder")
    _add_view_argument(run)
    _add_quiet_argument(run)
    _add_recording_arguments(run)
    run.set_defaults(handler=run_command)

    view = commands.add_parser("view", help="replay a finished run's --out folder in the web view")
    view.add_argument("folder", type=Path, help="a folder written by ptztrack run, follow or live with --out")
    view.add_argument("--port", type=_port, default=0, help="serve on http://127.0.0.1:PORT/ (default: any free one)")
    view.add_argument("--steps-per-s", type=_positive_float, default=10.0, help="the replay's pace")
    view.set_defaults(handler=view_command)

    experiment = commands.add_parser("experiment", help="run one of the papers' experiments and print its table")
    experiments = experiment.add_subparsers(
        dest="name", required=True, metavar="{synthetic,pets,msg,registration,follow,occupancy}"
    )

    synthetic = experiments.add_parser("synthetic", help="the PTZ paper's Tables 1-2 on the synthetic scene")
    synthetic.add_argument("--scenario", default="synthetic", help="'synthetic' (built in) or a scenario YAML file")
    synthetic.add_argument("--detector", choices=detectors, default="realistic")
    synthetic.add_argument(
        "--prior-shift-px",
        type=float,
        help="shifts the prior recall curve's r0 by this many pixels from the detector's own (a test of the learning)",
    )
    synthetic.add_argument(
        "--detector-model",
        help="what the policies and the tracker know of the detector: online (learned as the camera runs; the "
        "default), a-priori (the prior curve, kept), true (a simulation's own curve) or an earlier run's "
        "detector_model.json as the prior",
    )
    synthetic.add_argument("--sequences", type=_positive_int, default=12)
    synthetic.add_argument("--frames", type=_positive_int, help="overrides the scenario's number of frames")
    synthetic.add_argument("--strategies", nargs="+", choices=_strategies(policies), default=list(STRATEGIES))
    _add_association_argument(synthetic)
    _add_executor_arguments(synthetic, "one row per strategy")
    synthetic.set_defaults(handler=synthetic_experiment_command)

    pets = experiments.add_parser("pets", help="the PTZ paper's Tables 3-4 on PETS 2009 S2.L1")
    pets.add_argument("--detector", default="ideal", help="ideal (the annotations) or hog")
    pets.add_argument(
        "--detector-model",
        help="what the policies and the tracker know of the detector: online (learned as the camera runs; the "
        "default), a-priori (the prior curve, kept), true (a simulation's own curve) or an earlier run's "
        "detector_model.json as the prior",
    )
    pets.add_argument(
        "--beta",
        type=_non_negative_float,
        action="append",
        help="a weight of the patrolling term (repeatable; default 9 and 1)",
    )
    pets.add_argument("--strategies", nargs="+", choices=_strategies(policies), default=list(STRATEGIES))
    pets.add_argument("--frames", type=_positive_int, help="overrides the scenario's number of steps")
    pets.add_argument(
        "--protocol",
        choices=PROTOCOLS,
        default="a-priori",
        help="a-priori: every parameter fixed before looking at S2.L1; two-fold: the detector's model fitted on "
        "one half of the frames, the table scored on the other, both ways",
    )
    pets.add_argument("--seeds", type=_positive_int, default=5, help="runs of a strategy whose run depends on its seed")
    _add_tracker_arguments(pets)
    _add_executor_arguments(pets, "one row per strategy and beta")
    _add_recording_arguments(pets)
    pets.set_defaults(handler=pets_experiment_command)

    msg = experiments.add_parser("msg", help="the face-capture paper's Figure 7")
    msg.add_argument("--runs", type=_positive_int, default=414, help="simulations")
    msg.add_argument("--plot", type=Path, help="M against N_j/s per scheduler (PNG)")
    msg.add_argument("--trails", type=Path, help="one simulation's trails in (x, y, t) (PNG)")
    _add_executor_arguments(msg, "one row per run and scheduler")
    msg.set_defaults(handler=msg_experiment_command)

    registration = experiments.add_parser(
        "registration", help="the scale-invariant paper: registered PTZ views, and the closed loop on their poses"
    )
    registration.add_argument("--scenario", default="pets", help="'pets' (built in) or a recording scenario YAML file")
    registration.add_argument("--views", type=_positive_int, default=100, help="random live views to register")
    registration.add_argument(
        "--seed", type=_non_negative_int, default=0, help="draws the live views' poses and frames"
    )
    registration.add_argument(
        "--index", type=Path, help="reference index file: read if it exists, else built and written (default: built)"
    )
    registration.add_argument(
        "--exact-views",
        action="store_true",
        help="exact pinhole views instead of the scenario's camera.live_view (default: the realistic model)",
    )
    registration.add_argument("--detector", choices=detectors, default="hog", help="closed-loop detector")
    registration.add_argument(
        "--detector-model",
        help="what the policies and the tracker know of the detector: online (learned as the camera runs; the "
        "default), a-priori (the prior curve, kept), true (a simulation's own curve) or an earlier run's "
        "detector_model.json as the prior",
    )
    registration.add_argument("--policy", choices=policies, default="smpl", help="closed-loop policy")
    registration.add_argument(
        "--pose-sources", nargs="+", choices=POSE_SOURCES, default=list(POSE_SOURCES), help="closed-loop pose sources"
    )
    registration.add_argument(
        "--pose-noise-deg",
        type=_non_negative_float,
        default=2.0,
        help="closed loop: pan and tilt landing error, 1 sigma",
    )
    registration.add_argument(
        "--zoom-noise", type=_non_negative_float, default=0.02, help="closed loop: relative zoom landing error, 1 sigma"
    )
    registration.add_argument(
        "--frames", type=_positive_int, help="closed loop: overrides the scenario's number of steps"
    )
    _add_tracker_arguments(registration)
    _add_executor_arguments(registration, "the registration errors and the closed-loop rows")
    _add_recording_arguments(registration)
    registration.set_defaults(handler=registration_experiment_command)
    _add_follow_commands(commands, experiments)
    _add_occupancy_parser(experiments)
    _add_camera_commands(commands, policies)
    return root


def _add_camera_commands(commands, policies: list[str]) -> None:
    """``ptztrack live`` and ``ptztrack serve-camera``: real ONVIF cameras, and a virtual one to test with."""
    live = commands.add_parser("live", help="drive an ONVIF PTZ camera in real time: capture, detect, track, decide")
    live.add_argument("--camera", required=True, help="onvif://[user[:password]@]host[:port]")
    live.add_argument("--credentials", type=Path, help="a YAML file with username and password")
    live.add_argument(
        "--calibration", required=True, help="the camera's calibration YAML, or 'virtual' for ptztrack serve-camera"
    )
    live.add_argument("--policy", choices=policies, default="smpl")
    live.add_argument("--scenario", default="pets", help="'pets' (built in) or a scenario YAML file")
    live.add_argument("--detector", default="hog", help="the scenario's detector (default hog)")
    live.add_argument(
        "--detector-model",
        help="what the policies and the tracker know of the detector: online (learned as the camera runs; the "
        "default), a-priori (the prior curve, kept), true (a simulation's own curve) or an earlier run's "
        "detector_model.json as the prior",
    )
    live.add_argument(
        "--steps", type=_positive_int, help="use at most this many pictures (default: the scenario's frames)"
    )
    live.add_argument(
        "--time-scale", type=_positive_float, default=1.0, help="the scenario's seconds per second (serve-camera's)"
    )
    live.add_argument("--transport", choices=("tcp", "udp"), default="tcp", help="RTSP's transport (default tcp)")
    live.add_argument("--timeout-s", type=_positive_float, default=5.0, help="the longest wait for any camera call")
    live.add_argument(
        "--truth", type=Path, help="score against a virtual camera's truth log (serve-camera --truth-log)"
    )
    live.add_argument("--seed", type=_non_negative_int, default=0)
    live.add_argument(
        "--out", type=Path, help=f"directory for {', '.join(RUN_FOLDER_FILES)}; written whole, Ctrl-C too"
    )
    live.add_argument("--overwrite", action="store_true", help="replace a non-empty --out folder")
    _add_view_argument(live)
    live.set_defaults(handler=live_command)

    camera = commands.add_parser("camera", help="tools for a real camera").add_subparsers(dest="tool", required=True)
    calibrate = camera.add_parser("calibrate", help="time the camera's moves and write them into its calibration")
    calibrate.add_argument("--camera", required=True, help="onvif://[user[:password]@]host[:port]")
    calibrate.add_argument("--credentials", type=Path, help="a YAML file with username and password")
    calibrate.add_argument("--calibration", type=Path, required=True, help="the camera's calibration YAML (updated)")
    calibrate.add_argument(
        "--timeout-s", type=_positive_float, default=5.0, help="the longest wait for any camera call"
    )
    calibrate.set_defaults(handler=calibrate_camera_command)

    serve = commands.add_parser("serve-camera", help="serve the PETS virtual PTZ camera over ONVIF on 127.0.0.1")
    serve.add_argument("--port", type=_port, default=8080)
    serve.add_argument("--scenario", default="pets", help="'pets' (built in) or a recording scenario YAML file")
    serve.add_argument("--time-scale", type=_positive_float, default=1.0, help="the recording's speed")
    serve.add_argument("--user", help=f"require this user (password: --credentials or ${PASSWORD_VARIABLE})")
    serve.add_argument("--credentials", type=Path, help="a YAML file with username and password to require")
    serve.add_argument("--truth-log", type=Path, help="append every picture's time, step and pose here (CSV)")
    serve.set_defaults(handler=serve_camera_command)


def _add_follow_commands(commands, experiments) -> None:
    """``ptztrack follow`` and ``ptztrack experiment follow``: the robot-cameraman paper's follow camera."""
    follow = commands.add_parser("follow", help="follow one annotated PETS person with the virtual PTZ camera")
    follow.add_argument("--target", type=_non_negative_int, required=True, help="the annotated person's id")
    follow.add_argument("--tracker", choices=FOLLOW_TRACKERS, default="particle")
    follow.add_argument("--seed", type=_non_negative_int, default=0)
    follow.add_argument("--frames", type=_positive_int, help="at most this many steps")
    follow.add_argument(
        "--target-point-px",
        type=_non_negative_float,
        nargs=2,
        metavar=("X", "Y"),
        help="(x*, y*); default: the image centre",
    )
    follow.add_argument(
        "--out",
        type=Path,
        help=f"directory for {', '.join(RUN_FOLDER_FILES)} (default follow-TARGET); written whole or not at all",
    )
    follow.add_argument("--overwrite", action="store_true", help="replace a non-empty --out folder")
    _add_view_argument(follow)
    _add_quiet_argument(follow)
    _add_follow_scenario_arguments(follow)
    follow.set_defaults(handler=follow_command)

    experiment = experiments.add_parser(
        "follow", help="the robot-cameraman paper: every PETS person followed, and the one-pass benchmark"
    )
    experiment.add_argument("--trackers", nargs="+", choices=FOLLOW_TRACKERS, default=list(FOLLOW_TRACKERS))
    experiment.add_argument("--targets", type=_non_negative_int, nargs="+", help="people to follow (default: all)")
    experiment.add_argument(
        "--otb-tracks", type=_non_negative_int, default=OTB_TRACKS, help="longest tracks of the one-pass benchmark"
    )
    experiment.add_argument("--seed", type=_non_negative_int, default=0)
    _add_follow_scenario_arguments(experiment)
    _add_executor_arguments(experiment, '{"closed_loop": [...], "otb": [...]} and the rows per person')
    experiment.set_defaults(handler=follow_experiment_command)


def _add_follow_scenario_arguments(command: argparse.ArgumentParser) -> None:
    command.add_argument(
        "--scenario", default="pets", help="'pets' (built in) or a recording scenario YAML file with a follow section"
    )
    command.add_argument(
        "--achromatic-bins",
        action="store_true",
        help="the particle filter bins greys by value (Perez et al.) besides the paper's hue-saturation bins",
    )
    _add_recording_arguments(command)


def _add_occupancy_parser(experiments) -> None:
    occupancy = experiments.add_parser(
        "occupancy", help="the LPOM paper: people on the ground from several calibrated views, against clustering"
    )
    occupancy.add_argument("dataset", help="'synthetic-room' or 'pets' (built in), or a multi-view dataset YAML file")
    occupancy.add_argument(
        "--frames", type=_positive_int, help=f"frames to use (synthetic-room: {ROOM_FRAMES} per sequence; else all)"
    )
    occupancy.add_argument(
        "--seed", type=_non_negative_int, default=0, help="synthetic-room: draws people and textures"
    )
    occupancy.add_argument(
        "--out", type=Path, help="directory for maps, video, detections and tracks per recording; written whole"
    )
    occupancy.add_argument("--overwrite", action="store_true", help="replace a non-empty --out folder")
    occupancy.add_argument("--images-every", type=_positive_int, default=10, help="a map picture every N frames")
    occupancy.add_argument("--json", type=Path, help="write one row per method (and people count) here")
    _add_quiet_argument(occupancy)
    occupancy.set_defaults(handler=occupancy_experiment_command)


def _strategies(policies: list[str]) -> list[str]:
    """The tables' strategy names ('rnd' for the 'random' policy) and every other registered policy."""
    return list(dict.fromkeys([*STRATEGIES, *(name for name in policies if name != "random")]))


def _add_executor_arguments(command: argparse.ArgumentParser, rows: str) -> None:
    command.add_argument("--executor", choices=EXECUTORS, default="local")
    command.add_argument("--workers", type=_positive_int, help="processes of the local executor (default: all cores)")
    command.add_argument("--json", type=Path, help=f"write {rows} here")
    _add_quiet_argument(command)


def _add_quiet_argument(command: argparse.ArgumentParser) -> None:
    command.add_argument(
        "--quiet", action="store_true", help="no progress bar (there is none either where stderr is not a terminal)"
    )


def _add_view_argument(command: argparse.ArgumentParser) -> None:
    command.add_argument(
        "--view",
        type=_port,
        nargs="?",
        const=0,
        metavar="PORT",
        help="serve a live view of the run on http://127.0.0.1:PORT/ (no PORT or 0: any free one)",
    )


def _add_tracker_arguments(command: argparse.ArgumentParser) -> None:
    _add_association_argument(command)
    command.add_argument(
        "--measurement-source",
        choices=("detector", "spatiogram"),
        help="overrides the scenario's tracker.measurement_source (spatiogram: templates between detector steps)",
    )


def _add_association_argument(command: argparse.ArgumentParser) -> None:
    command.add_argument(
        "--association", choices=("hungarian", "cjpdaf"), help="overrides the scenario's tracker.association"
    )


def _add_recording_arguments(command: argparse.ArgumentParser) -> None:
    """Files of a recording that replace the scenario's (the built-in PETS ones with ``pets``)."""
    recording = command.add_argument_group("recording files (replace the scenario's)")
    recording.add_argument("--video", type=Path, help="the recorded video")
    recording.add_argument("--calibration", type=Path, help="pinhole JSON or Tsai XML calibration of the recording")
    recording.add_argument("--gt", type=Path, help="MOTChallenge ground truth with world positions in metres")


def _non_negative_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number (got {text!r})") from None
    if not (math.isfinite(value) and value >= 0):
        raise argparse.ArgumentTypeError(f"must be a finite number of at least 0 (got {text})")
    return value


def _non_negative_int(text: str) -> int:
    value = int(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be at least 0 (got {value})")
    return value


def _positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1 (got {value})")
    return value


def _positive_float(text: str) -> float:
    value = _non_negative_float(text)
    if value == 0:
        raise argparse.ArgumentTypeError(f"must be above 0 (got {text})")
    return value


def _port(text: str) -> int:
    value = _non_negative_int(text)
    if value > 65535:
        raise argparse.ArgumentTypeError(f"must be a port from 0 to 65535 (got {value})")
    return value


def check_outputs(args: argparse.Namespace) -> None:
    """Refuse, before any work, output paths that could not be written."""
    for option in ("json", "plot", "trails", "truth_log"):
        if getattr(args, option, None) is not None:
            check_output_file(getattr(args, option), f"--{option}")
    if getattr(args, "index", None) is not None and not args.index.exists():
        check_output_file(args.index, "--index")
    if getattr(args, "out", None) is not None:
        check_output_folder(args.out, "--out", args.overwrite)


def main(argv: list[str] | None = None) -> int:
    """The command line: 0 when done, 2 with one line on stderr for any bad input, 130 on Ctrl-C."""
    # Before any library configures the root logger (onvif-zeep-async does at import): warnings only,
    # one line each (a camera lost, back, still unreachable).
    logging.basicConfig(level=logging.WARNING, format="ptztrack: %(message)s")
    try:
        args = parser().parse_args(argv)
        check_outputs(args)
        return args.handler(args)
    except (InputError, RuntimeError) as error:
        print(f"ptztrack: error: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("ptztrack: interrupted; nothing was left half-written", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # The reader (say, `head`) has gone: stop quietly, and keep Python from
        # complaining again when it flushes stdout at exit.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except OSError as error:
        where = f"{error.filename}: " if error.filename else ""
        print(f"ptztrack: error: {where}{error.strerror or error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
