"""How each camera of the service is doing, for ``/healthz`` (JSON) and ``/metrics`` (the Prometheus
text exposition format), served beside the web view."""

import json
import threading
import time
from collections import deque
from dataclasses import dataclass, field

from starlette.requests import Request
from starlette.responses import PlainTextResponse, Response
from starlette.routing import Route

# Steps per second over the last this many seconds.
RATE_WINDOW_S = 10.0
# A camera's picture older than this is reported stale (/healthz's 'ok' false, status 503).
STALE_S = 10.0


@dataclass
class CameraHealth:
    """One camera's counters, written by its loop's thread, read by the server's.

    status : 'connecting', 'running', 'offline' (lost, reconnecting) or 'stopped'; steps : pictures
    used; last_picture_s : the newest one's capture time (epoch s); reconnects, outages : the camera's
    connections made again and lost; events : events emitted; model_trials : the detector model's
    trials (the sum over its height bins, counts from earlier runs included).
    """

    name: str
    status: str = "connecting"
    steps: int = 0
    last_picture_s: float | None = None
    reconnects: int = 0
    outages: int = 0
    events: int = 0
    model_trials: float = 0.0
    _recent_s: deque = field(default_factory=lambda: deque(maxlen=4096))
    _lock: threading.Lock = field(default_factory=threading.Lock)

    def stepped(self, capture_time_s: float) -> None:
        with self._lock:
            self.steps += 1
            self.last_picture_s = capture_time_s
            self._recent_s.append(time.time())

    def emitted(self) -> None:
        """One more event (from the loop's thread or the camera's watcher)."""
        with self._lock:
            self.events += 1

    def snapshot(self) -> dict:
        """Its counters, and the times (epoch s) of its steps of the last RATE_WINDOW_S, as plain data:
        what :meth:`take` copies into the service's health of a camera that runs in another process."""
        with self._lock:
            since_s = time.time() - RATE_WINDOW_S
            counters = {name: value for name, value in vars(self).items() if not name.startswith("_")}
            return {**counters, "recent_s": [used_s for used_s in self._recent_s if used_s >= since_s]}

    def take(self, snapshot: dict) -> None:
        """Its counters and recent steps as ``snapshot`` (of :meth:`snapshot`) tells them."""
        with self._lock:
            for name, value in snapshot.items():
                if name != "recent_s":
                    setattr(self, name, value)
            self._recent_s.clear()
            self._recent_s.extend(snapshot["recent_s"])

    def steps_per_s(self, now_s: float) -> float:
        """Pictures used per second over the last RATE_WINDOW_S."""
        with self._lock:
            recent = sum(1 for used_s in self._recent_s if used_s >= now_s - RATE_WINDOW_S)
        return recent / RATE_WINDOW_S

    def report(self, now_s: float) -> dict:
        age_s = None if self.last_picture_s is None else round(now_s - self.last_picture_s, 3)
        return {
            "status": self.status,
            "last_picture_age_s": age_s,
            "steps_per_s": round(self.steps_per_s(now_s), 3),
            "steps": self.steps,
            "reconnects": self.reconnects,
            "outages": self.outages,
            "events": self.events,
            "model_trials": round(self.model_trials, 3),
        }


def healthz(cameras: list[CameraHealth], now_s: float) -> dict:
    """``{"ok": bool, "cameras": {name: report}}``: ok while every camera runs with a picture newer than
    STALE_S."""
    reports = {camera.name: camera.report(now_s) for camera in cameras}
    ok = all(
        report["status"] == "running" and report["last_picture_age_s"] is not None
        and report["last_picture_age_s"] <= STALE_S
        for report in reports.values()
    )  # fmt: skip
    return {"ok": ok, "cameras": reports}


# (name, type, help, the report's key) of every metric, one sample per camera.
METRICS = (
    ("ptztrack_steps_total", "counter", "Pictures used by the camera's loop.", "steps"),
    ("ptztrack_steps_per_second", "gauge", f"Pictures used per second over the last {RATE_WINDOW_S:g} s.",
     "steps_per_s"),
    ("ptztrack_last_picture_age_seconds", "gauge", "Seconds since the newest picture used was taken.",
     "last_picture_age_s"),
    ("ptztrack_reconnects_total", "counter", "Connections to the camera made again after it was lost.", "reconnects"),
    ("ptztrack_outages_total", "counter", "Times the camera was lost.", "outages"),
    ("ptztrack_events_total", "counter", "Events emitted (track new, update, end; camera status).", "events"),
    ("ptztrack_detector_model_trials", "gauge", "The learned detector model's trials, earlier runs' included.",
     "model_trials"),
    ("ptztrack_up", "gauge", "1 while the camera's loop runs with the camera connected.", "status"),
)  # fmt: skip


def metrics_text(cameras: list[CameraHealth], now_s: float) -> str:
    """Every camera's metrics in the Prometheus text exposition format (version 0.0.4)."""
    reports = {camera.name: camera.report(now_s) for camera in cameras}
    lines = []
    for name, kind, help_text, key in METRICS:
        lines += [f"# HELP {name} {help_text}", f"# TYPE {name} {kind}"]
        for camera, report in reports.items():
            value = report[key]
            if key == "status":
                value = 1 if value == "running" else 0
            lines.append(f'{name}{{camera="{camera}"}} {"NaN" if value is None else value}')
    return "\n".join(lines) + "\n"


def health_routes(cameras: list[CameraHealth]) -> list[Route]:
    """``/healthz`` (JSON; status 503 unless ok) and ``/metrics`` (Prometheus text)."""

    async def health(request: Request) -> Response:
        report = healthz(cameras, time.time())
        return Response(json.dumps(report), 200 if report["ok"] else 503, media_type="application/json")

    async def metrics(request: Request) -> Response:
        return PlainTextResponse(metrics_text(cameras, time.time()), media_type="text/plain; version=0.0.4")

    return [Route("/healthz", health), Route("/metrics", metrics)]
