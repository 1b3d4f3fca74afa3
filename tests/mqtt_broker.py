"""Debian's Mosquitto on 127.0.0.1, on a free port, for the service's MQTT tests; and a subscriber that
keeps what it gets."""

import shutil
import socket
import subprocess
import threading
import time
from contextlib import contextmanager
from pathlib import Path

import paho.mqtt.client as paho

MOSQUITTO = shutil.which("mosquitto") or "/usr/sbin/mosquitto"


def free_port() -> int:
    """A port nobody listens on at 127.0.0.1 (as the kernel gives one)."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@contextmanager
def mosquitto(folder: Path):
    """A broker listening on 127.0.0.1 only, anonymous, without persistence; its port. Stopped after."""
    port = free_port()
    config = folder / "mosquitto.conf"
    config.write_text(f"listener {port} 127.0.0.1\nallow_anonymous true\npersistence false\n")
    broker = subprocess.Popen([MOSQUITTO, "-c", str(config)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 10
        while True:
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                assert broker.poll() is None and time.monotonic() < deadline, broker.stderr.read()
                time.sleep(0.05)
        yield port
    finally:
        broker.terminate()
        broker.wait(timeout=10)


class Subscriber:
    """A client subscribed at QoS 1 to ``topics`` on the broker at 127.0.0.1:``port``: ``messages`` holds
    (topic, payload) of every message, in order."""

    def __init__(self, port: int, topics: list[str]):
        self.messages: list[tuple[str, bytes]] = []
        self._subscribed = threading.Event()
        self._lock = threading.Lock()
        self.client = paho.Client(paho.CallbackAPIVersion.VERSION2, client_id="ptztrack-test-subscriber")
        self.client.on_connect = lambda client, data, flags, reason, properties: client.subscribe(
            [(topic, 1) for topic in topics]
        )
        self.client.on_subscribe = lambda *arguments: self._subscribed.set()
        self.client.on_message = self._on_message
        self.client.connect("127.0.0.1", port)
        self.client.loop_start()
        assert self._subscribed.wait(10), "the subscriber did not subscribe"

    def _on_message(self, client, data, message) -> None:
        with self._lock:
            self.messages.append((message.topic, message.payload))

    def count_settles(self, quiet_s: float = 0.5, timeout_s: float = 10.0) -> int:
        """The messages received once none has come for ``quiet_s``."""
        deadline, seen = time.monotonic() + timeout_s, -1
        while time.monotonic() < deadline:
            with self._lock:
                count = len(self.messages)
            if count == seen:
                return count
            seen = count
            time.sleep(quiet_s)
        return len(self.messages)

    def close(self) -> None:
        self.client.disconnect()
        self.client.loop_stop()
