"""The service: every camera of the configuration in a loop of its own, until stopped.

Each camera runs the live loop (:func:`ptztrack.loop.live.run_live_network`, a camera alone) in a
thread of its own (or, as the configuration's ``engine`` tells, in a Ray actor:
:mod:`ptztrack.service.actors`), unbounded, every picture's row handed to the camera's sink instead of kept: its
tracks appended to its rotated files (:mod:`ptztrack.service.outputs`), its track events emitted
(:mod:`ptztrack.service.events`), its health counted (:mod:`ptztrack.service.health`), and its learned
detector model saved every ``model_save_s`` (``<output>/<camera>/detector_model.json``, written to a
temporary file and renamed), read back as the prior when the service starts again (its trials go on
counting from there).

A camera that goes away is reconnected by the camera itself, with backoff
(:class:`ptztrack.camera.live_camera.LiveONVIFCamera`): the loop goes on with the same belief and
detector model, and uses no pictures meanwhile. A watcher per camera logs one line when it is lost and
one when it is back, and emits 'offline' and 'online' events. A camera that cannot be reached at the
start is tried again with the same backoff, one line and an 'offline' event at the first try, one line
and an 'online' event once it answers. Setting ``stop`` ends every loop; each camera's files are
then closed whole, its model saved and its tracks' 'end' events emitted.
"""

import contextlib
import importlib.util
import logging
import os
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ptztrack.builders.live import connected_cameras, live_network, plan_ahead_of
from ptztrack.builders.live_registered import check_pose_source
from ptztrack.builders.recording import pets_scenario
from ptztrack.builders.virtual_camera import virtual_calibration
from ptztrack.camera.live_camera import FIRST_RETRY_S, LONGEST_RETRY_S, LiveONVIFCamera
from ptztrack.camera.onvif_client import CameraError, camera_address
from ptztrack.config import Scenario, load_camera_calibration, load_scenario
from ptztrack.detect.detector_model import OnlineDetectorModel
from ptztrack.loop.live import run_live_network
from ptztrack.service.actors import DRAIN_S, RayCameras
from ptztrack.service.config import ServiceCamera, ServiceConfig, camera_engines
from ptztrack.service.events import Emit, EventOutlet, TrackEvents
from ptztrack.service.health import CameraHealth, health_routes
from ptztrack.service.outputs import TrackFiles
from ptztrack.view.view_state import ViewState
from ptztrack.view.web_view import ViewHub, ViewServer

log = logging.getLogger("ptztrack.service")

MODEL_FILE = "detector_model.json"
# How often a camera's watcher looks whether its camera was lost or is back.
WATCH_S = 0.1
# The longest wait for the cameras' loops to close their files once stopped: within SIGTERM's 2 s.
STOP_WAIT_S = 1.5
# ONVIF calls give up after this long: a camera that stops answering is lost, and the stop is not held.
CALL_TIMEOUT_S = 1.0


def camera_scenario(camera: ServiceCamera, model: Path | None) -> Scenario:
    """The scenario ``camera`` decides in, with its detector, and ``model`` (an earlier run's
    detector_model.json) as its detector model's prior where given."""
    overrides: dict = {"detector.kind": camera.detector}
    if model is not None:
        overrides["detector.model"] = str(model)
    if camera.scenario == "pets":
        return pets_scenario(**overrides)
    return load_scenario(camera.scenario, **overrides)


def model_trials(model) -> float:
    """The learned detector model's trials, its prior's (an earlier run's) included; 0 for a kept curve."""
    if not isinstance(model, OnlineDetectorModel) or model.prior_trials is None:
        return 0.0
    return float(np.sum(model.prior_trials) + np.sum(model.trials))


def serve(config: ServiceConfig, stop: threading.Event, started: Callable[[str], None] = print) -> list[CameraHealth]:
    """Run every camera of ``config`` until ``stop`` is set (or Ctrl-C); the cameras' health at the end.

    Each camera runs in a thread of this process or in a Ray actor, as :func:`camera_engines` tells.
    started : told one line once the service is up (the health's address, when it has one).
    """
    engines = camera_engines(config, os.cpu_count() or 1)
    on_ray = [number for number, engine in enumerate(engines) if engine == "ray"]
    if on_ray and importlib.util.find_spec("ray") is None:
        raise RuntimeError(
            f"{len(config.cameras)} cameras on {os.cpu_count()} cores (engine '{config.engine}'): all but the first "
            "run in Ray actors, which need Ray: pip install 'ptztrack[ray]' (or engine: threads)"
        )
    # The camera's own lines do not name it: the watchers' lines say what they say, with its name.
    logging.getLogger("ptztrack.loop.live").setLevel(logging.ERROR)
    healths = [CameraHealth(camera.name) for camera in config.cameras]
    hub = ViewHub()
    failures: list[BaseException] = []
    with contextlib.ExitStack() as stack:
        outlet = stack.enter_context(EventOutlet(config.events, config.mqtt))
        server = None
        if config.http_port is not None:
            server = stack.enter_context(ViewServer(hub, config.http_port, health_routes(healths)))
        actors = None
        if on_ray:  # left before the outlet: its last events are emitted while the outlet is open
            actors = stack.enter_context(
                RayCameras(
                    run_camera,
                    [config.cameras[number] for number in on_ray],
                    config,
                    [healths[number] for number in on_ray],
                    [outlet.emitter(config.cameras[number].name) for number in on_ray],
                    failures,
                )
            )
        threads = [
            threading.Thread(
                target=_camera_thread,
                args=(camera, config, health, outlet.emitter(camera.name), hub if number == 0 else None, stop,
                      failures),
                name=f"serve-{camera.name}",
                daemon=True,  # a camera's close that hangs past the stop's wait does not hold the process
            )
            for number, (camera, health) in enumerate(zip(config.cameras, healths, strict=True))
            if engines[number] == "thread"
        ]  # fmt: skip
        for thread in threads:
            thread.start()
        where = "" if server is None else f"; health at {server.address}healthz, metrics at {server.address}metrics"
        started(f"serving {len(config.cameras)} camera{'s' if len(config.cameras) > 1 else ''}{where}")
        try:
            while not stop.wait(DRAIN_S) and not failures:
                if actors is not None:
                    actors.drain()
        except KeyboardInterrupt:
            pass
        stop.set()
        if actors is not None:
            actors.stop()
        # Each camera's files are closed whole once its status is 'stopped' (its camera may still be closing).
        deadline_s = time.monotonic() + STOP_WAIT_S
        while any(health.status != "stopped" for health in healths) and time.monotonic() < deadline_s:
            time.sleep(0.02)
            if actors is not None:
                actors.drain()
    if failures:
        raise failures[0]
    return healths


def _camera_thread(camera, config, health, emit, hub, stop, failures) -> None:
    """:func:`run_camera`, its failure handed to the service's thread (which raises it)."""
    try:
        run_camera(camera, config, health, emit, hub, stop)
    except BaseException as error:  # noqa: BLE001 - raised again by serve()
        failures.append(error)
        health.status = "stopped"


def run_camera(
    camera: ServiceCamera,
    config: ServiceConfig,
    health: CameraHealth,
    emit: Emit,
    hub: ViewHub | None,
    stop: threading.Event,
) -> None:
    """One camera's loop until ``stop``: connected (again and again while it cannot be), its rows into
    its files, its events into ``emit`` and its health into ``health``, its model saved every
    ``config.model_save_s`` and at the end; the web view fed through ``hub`` (None: none)."""
    folder = Path(config.output) / camera.name
    folder.mkdir(parents=True, exist_ok=True)
    model_path = folder / MODEL_FILE
    scenario = camera_scenario(camera, model_path if model_path.exists() else None)
    calibration = (
        virtual_calibration() if camera.calibration == "virtual" else load_camera_calibration(camera.calibration)
    )
    check_pose_source([calibration], camera.pose)
    address = camera_address(camera.url)
    network = live_network(scenario, [calibration], camera.policy, camera.seed)
    (world,) = network.worlds
    model = world.detector_model
    health.model_trials = model_trials(model)

    def counted(kind: str, payload: dict) -> None:
        health.emitted()
        emit(kind, payload)

    events = TrackEvents(
        camera.name, f"{int(1000 * time.time())}", config.position_rate_hz, config.track_end_s, counted
    )
    files = TrackFiles(folder, config.rotate_s)
    next_save_s = time.monotonic() + config.model_save_s

    def save_model() -> None:
        if isinstance(model, OnlineDetectorModel):
            model.save(model_path)

    def sink(index: int, row: dict) -> None:
        nonlocal next_save_s
        health.stepped(row["capture_time_s"])
        health.model_trials = model_trials(model)
        files.append(row)
        events.step(row["capture_time_s"], row["tracks"])
        if time.monotonic() >= next_save_s:  # on the loop's thread: the model is not changing meanwhile
            save_model()
            next_save_s = time.monotonic() + config.model_save_s

    observer = None
    if hub is not None:  # the web view shows the first camera
        observer = ViewState(world, network.shown, sys.maxsize, f"serve {camera.name}", truth=False).observer(
            hub.after_step
        )
    try:
        retry_s = FIRST_RETRY_S
        while not stop.is_set():
            try:
                connected = connected_cameras(
                    [address], [calibration], network.worlds, CALL_TIMEOUT_S, camera.transport, camera.pose
                )
                with connected as cameras:
                    if health.status == "offline":
                        log.warning("camera %s answers; running", camera.name)
                        counted("status", _status("online", camera.name, time.time(), "", cameras[0]))
                    health.status = "running"
                    watcher = threading.Thread(
                        target=_watch, args=(camera.name, cameras[0], health, counted, stop), daemon=True
                    )
                    watcher.start()
                    run_live_network(
                        network.worlds, network.policy, network.tracker, cameras, sys.maxsize, camera.time_scale,
                        camera.seed, observer, False, plan_ahead_of(scenario), sink, stop,
                    )  # fmt: skip
                    _finish(files, events, save_model)
                    health.status = "stopped"
                return
            except CameraError as error:
                if health.status != "offline":  # one line and one event until it answers
                    log.warning("camera %s unreachable (%s); trying again with backoff", camera.name, error)
                    counted("status", _status("offline", camera.name, time.time(), str(error)))
                health.status = "offline"
                stop.wait(retry_s)
                retry_s = min(2 * retry_s, LONGEST_RETRY_S)
    finally:
        if health.status != "stopped":
            _finish(files, events, save_model)
            health.status = "stopped"


def _finish(files: TrackFiles, events: TrackEvents, save_model: Callable[[], None]) -> None:
    """The camera's files closed whole, its tracks ended, its model saved."""
    files.close()
    events.end_all(time.time())
    save_model()


def _watch(name: str, camera: LiveONVIFCamera, health: CameraHealth, emit, stop: threading.Event) -> None:
    """Until ``stop``: one line and an 'offline' event when ``camera`` is lost, one line and an 'online'
    event when it is back, and the health's outages and reconnects."""
    outages, reconnects = camera.failures, camera.reconnects
    while not stop.wait(WATCH_S):
        if camera.failures > outages:
            outages = health.outages = camera.failures
            health.status = "offline"
            log.warning(
                "camera %s lost (%s); tracking on predictions, reconnecting with backoff", name, camera.lost_because
            )
            emit("status", _status("offline", name, camera.away_since_s or time.time(), camera.lost_because, camera))
        if camera.reconnects > reconnects:
            reconnects = health.reconnects = camera.reconnects
            health.status = "running"
            log.warning("camera %s back (reconnect %d)", name, reconnects)
            emit("status", _status("online", name, time.time(), "", camera))


def _status(kind: str, name: str, time_s: float, reason: str, camera: LiveONVIFCamera | None = None) -> dict:
    """A status event of camera ``name``: 'offline' (with the reason) or 'online', and the connected
    ``camera``'s outages and reconnects so far (none before it was first connected)."""
    return {
        "type": kind,
        "camera": name,
        "time_s": round(time_s, 6),
        "reason": reason,
        "outages": 0 if camera is None else camera.failures,
        "reconnects": 0 if camera is None else camera.reconnects,
    }
