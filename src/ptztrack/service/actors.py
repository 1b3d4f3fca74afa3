"""The service's cameras in Ray actors: each camera's loop in a process of its own, its events and
health brought back to the service.

A :class:`CameraActor` runs a camera's loop (the runner's ``run_camera``, handed in so that this
module stays below the runner) in a thread of its own, writing the camera's files and detector model
under the configuration's output folder as a thread of the service would: so the actor's node sees
that folder (one machine, or a filesystem shared by the nodes). It publishes nothing itself: its
events and its log lines are queued, and :class:`RayCameras`, in the service's process, drains them
every DRAIN_S, emits the events through the service's one outlet (one writer of the JSON lines and
one MQTT client) and copies each camera's health into the service's, which ``/healthz`` and
``/metrics`` report.
"""

import logging
import signal
import sys
import threading
from collections.abc import Callable, Sequence

from ptztrack.loop.executors import connect_ray
from ptztrack.service.config import ServiceCamera, ServiceConfig
from ptztrack.service.events import Emit
from ptztrack.service.health import CameraHealth

# How often the service asks each actor for its queued events and its health.
DRAIN_S = 0.2

CameraLoop = Callable[[ServiceCamera, ServiceConfig, CameraHealth, Emit, None, threading.Event], None]
"""``run(camera, config, health, emit, hub, stop)``: one camera's loop until ``stop`` (the runner's
``run_camera``; no web view, ``hub`` None)."""

Drained = tuple[dict, list[tuple[str, dict]], list[tuple[str, int, str]], bool, BaseException | None]
"""What :meth:`CameraActor.drain` returns: the health's snapshot, the events (topic's last part,
payload) and the log records (logger, level, message) queued since the last drain, whether the loop
has ended (nothing more will come), and then its failure (None if it ended without one)."""


class _Queued(logging.Handler):
    """A logging handler that keeps (logger, level, message) of each record for the next drain."""

    def __init__(self, lines: list, lock: threading.Lock):
        super().__init__(logging.WARNING)
        self.lines, self.lines_lock = lines, lock

    def emit(self, record: logging.LogRecord) -> None:
        with self.lines_lock:
            self.lines.append((record.name, record.levelno, record.getMessage()))


class CameraActor:
    """One camera's loop ``run`` in a thread of this actor, until :meth:`stop`; its events, its log
    lines (ptztrack's, warnings and above) and its health kept for :meth:`drain`."""

    def __init__(self, run: CameraLoop, camera: ServiceCamera, config: ServiceConfig):
        self._lock = threading.Lock()
        self._events: list[tuple[str, dict]] = []
        self._lines: list[tuple[str, int, str]] = []
        self._failure: BaseException | None = None
        self._stop = threading.Event()
        self.health = CameraHealth(camera.name)
        logger = logging.getLogger("ptztrack")
        logger.setLevel(logging.WARNING)
        logger.addHandler(_Queued(self._lines, self._lock))
        self._thread = threading.Thread(target=self._run, args=(run, camera, config), daemon=True)
        self._thread.start()

    def _queue(self, kind: str, payload: dict) -> None:
        with self._lock:
            self._events.append((kind, payload))

    def _run(self, run: CameraLoop, camera: ServiceCamera, config: ServiceConfig) -> None:
        try:
            run(camera, config, self.health, self._queue, None, self._stop)
        except BaseException as error:  # noqa: BLE001 - handed to the service by drain(), which raises it
            self._failure = error
            self.health.status = "stopped"

    def drain(self) -> Drained:
        """The health, what was queued since the last drain, whether the loop ended and how (``Drained``)."""
        # In this order: a loop whose thread has ended has kept its failure and queued its last events, and a
        # snapshot 'stopped' comes after the camera's last events were queued; so they come with it.
        ended = not self._thread.is_alive()
        snapshot = self.health.snapshot()
        with self._lock:  # emptied in place: the log handler holds the list of lines
            events, lines = self._events[:], self._lines[:]
            self._events.clear()
            self._lines.clear()
        return snapshot, events, lines, ended, self._failure if ended else None

    def stop(self) -> None:
        """End the loop: its files closed whole, its tracks' 'end' events queued, its model saved."""
        self._stop.set()


class RayCameras:
    """Cameras of the service, each in a :class:`CameraActor`, on the cluster that
    :func:`~ptztrack.loop.executors.connect_ray` connects to (``RAY_ADDRESS``, else a local one started
    here, and shut down by :meth:`close`).

    run : the camera's loop; cameras, healths, emits : each camera, the service's health of it and its
    ``emit`` (of the service's outlet); failures : where a camera's failure is appended (the service
    raises the first). A context manager: leaving it drains the last events, then ends the actors.
    """

    def __init__(
        self,
        run: CameraLoop,
        cameras: Sequence[ServiceCamera],
        config: ServiceConfig,
        healths: Sequence[CameraHealth],
        emits: Sequence[Emit],
        failures: list[BaseException],
    ):
        self.healths, self.emits, self.failures = list(healths), list(emits), failures
        self.names = [camera.name for camera in cameras]
        already = sys.modules.get("ray")
        # Shut down at the end only if started here: a cluster this process was already connected to is not ours.
        self._own_ray = already is None or not already.is_initialized()
        on_sigterm = signal.getsignal(signal.SIGTERM)
        ray = connect_ray()
        if threading.current_thread() is threading.main_thread():
            # ray.init puts in a SIGTERM handler that exits at once: the service's stops it whole.
            signal.signal(signal.SIGTERM, on_sigterm)
        self._ray = ray
        remote_actor = ray.remote(CameraActor).options(max_concurrency=4, scheduling_strategy="SPREAD")
        self.actors = [remote_actor.remote(run, camera, config) for camera in cameras]
        self._running = [True] * len(self.actors)
        self._pending = {actor.drain.remote(): index for index, actor in enumerate(self.actors)}

    def drain(self) -> None:
        """Take what the actors have answered since the last call (none is waited for): their events
        emitted, their log lines logged here, their health copied, their failures appended; ask those
        actors again."""
        if not self._pending:
            return
        answered, _ = self._ray.wait(list(self._pending), num_returns=len(self._pending), timeout=0)
        for reference in answered:
            index = self._pending.pop(reference)
            try:
                snapshot, events, lines, ended, failure = self._ray.get(reference)
            except self._ray.exceptions.RayError as error:  # the actor's process died, or could not start
                reason = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
                self.failures.append(RuntimeError(f"camera {self.names[index]}: its Ray actor failed ({reason})"))
                self.healths[index].status = "stopped"
                self._running[index] = False
                continue
            for kind, payload in events:
                self.emits[index](kind, payload)
            for name, level, message in lines:
                logging.getLogger(name).log(level, "%s", message)
            self.healths[index].take(snapshot)
            if failure is not None:
                self.failures.append(failure)
            if ended:
                self._running[index] = False
            else:
                self._pending[self.actors[index].drain.remote()] = index

    def stop(self) -> None:
        """Tell every actor to end its loop (:meth:`drain` then brings the last events)."""
        for actor, running in zip(self.actors, self._running, strict=True):
            if running:
                actor.stop.remote()

    def __enter__(self) -> "RayCameras":
        return self

    def __exit__(self, *failure) -> None:
        self.close()

    def close(self) -> None:
        """What the actors have answered drained, the actors ended, and a local cluster started here shut
        down (no Ray process left)."""
        self.drain()
        for actor in self.actors:
            self._ray.kill(actor)
        if self._own_ray:
            # Ray's autoscaler monitor, idle on a local cluster, answers ray.shutdown's SIGTERM by reporting
            # to the cluster being shut down and is killed only after a second's wait, past the stop's 2 s:
            # ended first, through Ray's record of the processes it started (none when it joined a cluster).
            node = getattr(sys.modules.get("ray._private.worker"), "_global_node", None)
            kill_monitor = getattr(node, "kill_monitor", None)
            if kill_monitor is not None:
                kill_monitor(check_alive=False)
            self._ray.shutdown()
