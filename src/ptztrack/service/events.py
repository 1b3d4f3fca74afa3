"""What the service tells the world as it runs: a track started, its ground position at a set rate, a
track ended, a camera lost and back; as JSON lines (stdout or a file) and over MQTT.

The payloads follow Frigate's ``frigate/events``: a track's event is
``{"type": "new" | "update" | "end", "camera", "time_s", "before": {...}, "after": {...}}`` on
``<prefix>/<camera>/events``, ``before`` the track as its previous event told it (for 'new', the same
as ``after``), each a person on the ground plane::

    {"id": "<camera>-<run start, epoch ms>-<track id>", "track_id": 7, "camera": "front", "label": "person",
     "start_time": 1764454500.12, "end_time": null, "frame_time": 1764454503.52,
     "x_m": 3.1, "y_m": 7.9, "vx_m_s": 0.8, "vy_m_s": -0.1, "position_sd_m": 0.21, "existence": 0.97}

A camera's connection is ``{"type": "offline" | "online", "camera", "time_s", "reason", "outages",
"reconnects"}`` on ``<prefix>/<camera>/status``. Every event is written as one JSON line (its topic
beside it as ``"topic"``) and, with a broker, published once at QoS 1: the messages a subscriber gets
equal the lines written.
"""

import json
import logging
import sys
import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

from ptztrack.service.outputs import track_states
from ptztrack.types import Tracks

log = logging.getLogger("ptztrack.service")

Emit = Callable[[str, dict], None]
"""``emit(topic_suffix, payload)``: an event of one camera, its topic's last part 'events' or 'status'."""

# How long the stop waits for the broker's acknowledgements of what was published.
ACK_WAIT_S = 1.0
# What paho keeps while the broker is away, beyond which events are written but not published.
MAX_QUEUED_MESSAGES = 100_000
# How long the outlet waits for the broker at its start. Messages published before the first connection
# are sent by paho's thread when it connects, while later ones go out at once, so they could overtake
# them; a broker that answers within this wait gets every message in order.
CONNECT_WAIT_S = 5.0


@dataclass
class _Track:
    """What the events told last of one track: the object, and when the track was last reported."""

    told: dict
    seen_s: float


class TrackEvents:
    """One camera's track events from its reported tracks, picture after picture.

    A track reported for the first time is 'new'; while reported, an 'update' at most ``position_rate_hz``
    times a second; not reported for ``track_end_s`` (seconds between pictures' capture times), 'end'.
    ``run_id`` tells this run's ids from an earlier run's (the tracker counts ids from 0 again).
    """

    def __init__(self, camera: str, run_id: str, position_rate_hz: float, track_end_s: float, emit: Emit):
        self.camera, self.run_id = camera, run_id
        self.period_s, self.track_end_s, self._emit = 1.0 / position_rate_hz, track_end_s, emit
        self._tracks: dict[int, _Track] = {}

    def step(self, time_s: float, tracks: Tracks) -> None:
        """The tracks reported after the picture captured at epoch ``time_s``."""
        for state in track_states(tracks):
            known = self._tracks.get(state["id"])
            if known is None:
                after = self._object(state, time_s, time_s)
                self._tracks[state["id"]] = _Track(after, time_s)
                self._send("new", time_s, after, after)
                continue
            known.seen_s = time_s
            if time_s >= known.told["frame_time"] + self.period_s:
                after = self._object(state, known.told["start_time"], time_s)
                self._send("update", time_s, known.told, after)
                known.told = after
        for track_id in [key for key, known in self._tracks.items() if time_s - known.seen_s > self.track_end_s]:
            self._end(track_id, time_s)

    def end_all(self, time_s: float) -> None:
        """Every track ended (the service stops: its belief goes with it)."""
        for track_id in list(self._tracks):
            self._end(track_id, time_s)

    def _end(self, track_id: int, time_s: float) -> None:
        before = self._tracks.pop(track_id).told
        self._send("end", time_s, before, {**before, "end_time": round(time_s, 6)})

    def _object(self, state: dict, started_s: float, time_s: float) -> dict:
        track_id = state["id"]
        return {
            "id": f"{self.camera}-{self.run_id}-{track_id}",
            "track_id": track_id,
            "camera": self.camera,
            "label": "person",
            "start_time": round(started_s, 6),
            "end_time": None,
            "frame_time": round(time_s, 6),
            **{key: value for key, value in state.items() if key != "id"},
        }

    def _send(self, kind: str, time_s: float, before: dict, after: dict) -> None:
        self._emit("events", {"type": kind, "camera": self.camera, "time_s": round(time_s, 6), "before": before,
                              "after": after})  # fmt: skip


class EventOutlet:
    """Where every camera's events go: JSON lines to ``events`` ('stdout' or a file, appended) and, with
    ``mqtt`` (an :class:`ptztrack.service.config.MQTTSection`), the broker. Thread-safe; a context
    manager: leaving it waits up to ACK_WAIT_S for the broker's acknowledgements, then disconnects."""

    def __init__(self, events: str, mqtt=None, client_id: str = "ptztrack"):
        self._lock = threading.Lock()
        self.written, self.acknowledged, self.unpublished = 0, 0, 0
        self._sent = 0
        # Apart from the writers' lock: paho calls on_publish holding its own lock, which publish takes.
        self._acks = threading.Condition()
        self._file: TextIO = sys.stdout if events == "stdout" else open(Path(events), "a", encoding="utf-8")  # noqa: SIM115
        self._client = None if mqtt is None else self._connect(mqtt, client_id)
        self.prefix = "ptztrack" if mqtt is None else mqtt.topic_prefix

    def _connect(self, mqtt, client_id: str):
        import paho.mqtt.client as paho  # only a service with a broker needs it

        client = paho.Client(paho.CallbackAPIVersion.VERSION2, client_id=client_id)
        client.max_queued_messages_set(MAX_QUEUED_MESSAGES)
        client.reconnect_delay_set(1, 8)
        client.on_publish = self._on_publish
        connected = threading.Event()

        def on_connect(client, data, flags, reason, properties) -> None:
            log.warning("MQTT broker %s:%d: %s", mqtt.host, mqtt.port, "connected" if not reason.is_failure else reason)
            if not reason.is_failure:
                connected.set()

        client.on_connect = on_connect
        client.on_disconnect = lambda client, data, flags, reason, properties: (
            log.warning("MQTT broker %s:%d lost (%s); reconnecting", mqtt.host, mqtt.port, reason)
            if reason.is_failure
            else None
        )
        client.on_connect_fail = lambda client, data: log.warning(
            "MQTT broker %s:%d unreachable; retrying", mqtt.host, mqtt.port
        )
        self._queue_full = paho.MQTT_ERR_QUEUE_SIZE
        client.connect_async(mqtt.host, mqtt.port)
        client.loop_start()
        if not connected.wait(CONNECT_WAIT_S):
            log.warning("MQTT broker %s:%d not connected after %.0f s; events are queued until it is", mqtt.host,
                        mqtt.port, CONNECT_WAIT_S)  # fmt: skip
        return client

    def _on_publish(self, client, userdata, mid, reason, properties) -> None:
        with self._acks:
            self.acknowledged += 1
            self._acks.notify_all()

    def emitter(self, camera: str) -> Emit:
        """``emit`` of camera ``camera``."""
        return lambda kind, payload: self.emit(f"{self.prefix}/{camera}/{kind}", payload)

    def emit(self, topic: str, payload: dict) -> None:
        """Write one event as a JSON line, and publish it."""
        message = json.dumps(payload, separators=(",", ":"), allow_nan=False)
        with self._lock:
            self._file.write(json.dumps({"topic": topic, **payload}, separators=(",", ":"), allow_nan=False) + "\n")
            self._file.flush()
            self.written += 1
            if self._client is None:
                return
            # Kept by paho while the broker is away, and sent when it is back; refused when its queue is full.
            refused = self._client.publish(topic, message, qos=1).rc == self._queue_full
        with self._acks:
            if refused:
                self.unpublished += 1
            else:
                self._sent += 1

    def __enter__(self) -> "EventOutlet":
        return self

    def __exit__(self, *failure) -> None:
        if self._client is not None:
            with self._acks:
                self._acks.wait_for(lambda: self.acknowledged >= self._sent, ACK_WAIT_S)
            self._client.disconnect()
            self._client.loop_stop()
        if self._file is not sys.stdout:
            self._file.close()
