"""`ptztrack serve` for a long while, as an integrator runs it: its cameras killed and restarted, the
service itself stopped by SIGTERM and started again, a real broker and a subscriber counting.

Runs ``ptztrack serve`` as a process of its own on ``examples/serve.yaml`` (two virtual cameras), with
the ports it finds free on 127.0.0.1 and its output in a temporary folder (or ``--folder``); each
camera is a ``ptztrack serve-camera --time-scale T`` process of its own, both killed (SIGKILL) and
started again on their ports every ``--restart-every-min`` minutes; the service is stopped by SIGTERM
once halfway and started again. Debian's Mosquitto runs on 127.0.0.1 with a subscriber to
``ptztrack/+/events`` and ``ptztrack/+/status``. It prints and writes (``--json``):

- ``steps``: the pictures the service used, both cameras, both runs (the rows of its tracks' files);
- ``steps_lost_outside_outages``: the pictures lost in gaps between consecutive rows of a camera,
  less the time the gap shares with the camera's outages (from its 'offline' event to its 'online'
  one) and the service's stop (from SIGTERM to its second run's cameras running), where that is
  longer than ``GAP_S``: over the camera's median interval, less one;
- ``mqtt_messages``: the messages the subscriber got; ``events_written``: the lines of the events file;
- ``rss_mb_start``, ``rss_mb_end``: the service's resident memory a minute after its second start
  and at its end (``rss_mb`` holds every sample: minute, run, MB);
- ``stop_s``: the longer of the two SIGTERMs' times to exit; ``tracebacks``: "Traceback" in the
  service's stderr (both runs);
- ``rotated_files_whole``: whether every tracks file is whole (no .part left, every line a record),
  with ``rotated_files`` their number;
- ``model_trials_before_restart``: the trials of the detector models saved at the first stop (both
  cameras); ``model_trials_after_restart``: those the second run read back (its /healthz at its start).

    python benchmarks/soak_serve.py --json PATH [--minutes 20] [--time-scale 4] [--restart-every-min 5]
                                    [--folder DIR] [--rotate-s 60]
"""

import argparse
import json
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np
import paho.mqtt.client as paho
import psutil
import yaml

from ptztrack.files import write_json

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "serve.yaml"
# A gap between two pictures of a camera longer than this is a loss unless it holds an outage.
GAP_S = 2.0
# The camera servers stay away this long when killed.
AWAY_S = 3.0
MOSQUITTO = shutil.which("mosquitto") or "/usr/sbin/mosquitto"


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def start_camera(port: int, time_scale: float) -> subprocess.Popen:
    command = [sys.executable, "-m", "ptztrack.cli", "serve-camera", "--port", str(port)]
    camera = subprocess.Popen(
        [*command, "--time-scale", str(time_scale)], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True
    )
    assert camera.stdout is not None and f"onvif://127.0.0.1:{port}" in camera.stdout.readline()
    return camera


def start_serve(config: Path, errors) -> tuple[subprocess.Popen, str]:
    """The service, and its /healthz address once it serves; its stderr appended to ``errors``."""
    service = subprocess.Popen(
        [sys.executable, "-m", "ptztrack.cli", "serve", str(config)], stdout=subprocess.PIPE, stderr=errors, text=True
    )
    assert service.stdout is not None
    line = service.stdout.readline()
    found = re.search(r"health at (\S+?),", line)
    assert found, f"ptztrack serve did not start: {line}"
    return service, found.group(1)


def health(address: str) -> dict:
    try:
        with urllib.request.urlopen(address, timeout=5) as answer:
            return json.loads(answer.read())
    except urllib.error.HTTPError as unhealthy:
        return json.loads(unhealthy.read())


def stop(service: subprocess.Popen) -> float:
    """SIGTERM, and the seconds until the process ended."""
    sent_s = time.monotonic()
    service.send_signal(signal.SIGTERM)
    service.wait(timeout=60)
    return time.monotonic() - sent_s


class Counter:
    """A subscriber at QoS 1 counting the messages of ``topics``."""

    def __init__(self, port: int, topics: list[str]):
        self.count = 0
        subscribed = threading.Event()
        self.client = paho.Client(paho.CallbackAPIVersion.VERSION2, client_id="soak-serve-subscriber")
        self.client.on_connect = lambda client, *rest: client.subscribe([(topic, 1) for topic in topics])
        self.client.on_subscribe = lambda *rest: subscribed.set()
        self.client.on_message = self._on_message
        self.client.connect("127.0.0.1", port)
        self.client.loop_start()
        assert subscribed.wait(10)

    def _on_message(self, *rest) -> None:
        self.count += 1


def lost_steps(times_s: np.ndarray, away_s: list[tuple[float, float]]) -> int:
    """Pictures lost in the gaps of ``times_s`` (sorted capture times, s) outside the intervals ``away_s``
    ((start, end) s: a camera's outages, the service's stop): each gap less the time it shares with
    those intervals, counted where that is longer than GAP_S, in the camera's median interval, less one."""
    if len(times_s) < 3:
        return 0
    gaps_s = np.diff(times_s)
    interval_s = float(np.median(gaps_s))
    lost = 0
    long = gaps_s > GAP_S  # a gap no longer than GAP_S loses nothing, whatever it shares
    for start_s, gap_s in zip(times_s[:-1][long], gaps_s[long], strict=True):
        shared_s = sum(max(0.0, min(start_s + gap_s, end_s) - max(start_s, begin_s)) for begin_s, end_s in away_s)
        if gap_s - shared_s > GAP_S:
            lost += int(round((gap_s - shared_s) / interval_s)) - 1
    return lost


def outages_of(camera: str, events: list[dict], stops: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """A camera's outages (start, end) s: each 'offline' event to the camera's next 'online' event or the
    service's next stop, whichever is first (a service started again says 'online' only for a camera
    that was offline at its start)."""
    times = {kind: [event["time_s"] for event in events if event["type"] == kind and event["camera"] == camera]
             for kind in ("offline", "online")}  # fmt: skip
    outages = []
    for begin_s in times["offline"]:
        ends_s = [end_s for end_s in times["online"] if end_s > begin_s]
        ends_s += [stop_s for stop_s, _ in stops if stop_s > begin_s]
        outages.append((begin_s, min(ends_s, default=np.inf)))
    return outages


def whole_files(folder: Path) -> tuple[bool, int]:
    """Whether every tracks file under ``folder`` is whole (no .part, every line a record); their number."""
    files = sorted(folder.glob("*/tracks-*"))
    whole = not any(path.suffix == ".part" for path in files)
    for path in files:
        lines = path.read_text().splitlines()
        if path.name.endswith(".jsonl"):
            whole &= all(isinstance(json.loads(line), dict) for line in lines)
        else:
            whole &= all(len(line.split(",")) == 10 for line in lines)
    return whole, len(files)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=20.0, help="wall-clock minutes in all")
    parser.add_argument("--time-scale", type=float, default=4.0, help="the recording's speed, cameras and service")
    parser.add_argument("--restart-every-min", type=float, default=5.0, help="minutes between camera restarts")
    parser.add_argument("--rotate-s", type=float, default=60.0, help="the tracks' files rotated this often")
    parser.add_argument("--folder", type=Path, help="the service's output (default: a temporary folder)")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    folder = args.folder or Path(tempfile.mkdtemp(prefix="soak-serve-"))
    folder.mkdir(parents=True, exist_ok=True)
    broker_port, camera_ports = free_port(), [free_port(), free_port()]
    broker_config = f"listener {broker_port} 127.0.0.1\nallow_anonymous true\npersistence false\n"
    (folder / "mosquitto.conf").write_text(broker_config)
    config = yaml.safe_load(EXAMPLE.read_text())
    for camera, port in zip(config["cameras"], camera_ports, strict=True):
        camera["url"], camera["time_scale"] = f"onvif://127.0.0.1:{port}", args.time_scale
    config.update(output=str(folder / "output"), events=str(folder / "events.jsonl"), http_port=0)
    config["rotate_s"] = args.rotate_s
    config["mqtt"]["port"] = broker_port
    config_path = folder / "serve.yaml"
    config_path.write_text(yaml.safe_dump(config, sort_keys=False))

    broker = subprocess.Popen([MOSQUITTO, "-c", str(folder / "mosquitto.conf")], stderr=subprocess.DEVNULL)
    time.sleep(0.5)
    counter = Counter(broker_port, ["ptztrack/+/events", "ptztrack/+/status"])
    cameras = [start_camera(port, args.time_scale) for port in camera_ports]
    errors = open(folder / "serve.stderr", "w")  # noqa: SIM115 - both runs' stderr, read at the end
    started_s = time.monotonic()
    total_s, every_s = 60 * args.minutes, 60 * args.restart_every_min
    next_restart_s, halfway_s = every_s, total_s / 2
    service, address = start_serve(config_path, errors)
    process, run = psutil.Process(service.pid), 1
    # The service's stop: SIGTERM sent to its second run's cameras running (s since the epoch).
    rss_mb, stops_s, stopped = [], [], []
    trials_before = trials_after = None
    next_sample_s = 60.0
    try:
        while (elapsed_s := time.monotonic() - started_s) < total_s:
            if elapsed_s >= next_sample_s:
                rss_mb.append((round(elapsed_s / 60, 2), run, round(process.memory_info().rss / 2**20, 1)))
                print(f"{elapsed_s / 60:5.1f} min, run {run}: {rss_mb[-1][2]} MB, {health(address)['cameras']}")
                next_sample_s += 60.0
            if elapsed_s >= next_restart_s:
                for camera in cameras:
                    camera.kill()
                    camera.wait()
                time.sleep(AWAY_S)
                cameras = [start_camera(port, args.time_scale) for port in camera_ports]
                next_restart_s += every_s
                print(f"{elapsed_s / 60:5.1f} min: the cameras killed and restarted")
            if run == 1 and elapsed_s >= halfway_s:
                stopped_at_s = time.time()
                stops_s.append(stop(service))
                trials_before = sum(
                    float(np.sum(json.loads(path.read_text())["trials"]))
                    for path in (folder / "output").glob("*/detector_model.json")
                )
                service, address = start_serve(config_path, errors)
                process, run = psutil.Process(service.pid), 2
                deadline_s = time.monotonic() + 120
                while any(report["status"] != "running" for report in health(address)["cameras"].values()):
                    assert time.monotonic() < deadline_s, "the second run's cameras are not running"
                    time.sleep(0.2)
                stopped.append((stopped_at_s, time.time()))
                trials_after = sum(report["model_trials"] for report in health(address)["cameras"].values())
                next_sample_s = elapsed_s + 60.0
                print(f"{elapsed_s / 60:5.1f} min: serve stopped in {stops_s[-1]:.2f} s and started again")
            time.sleep(0.5)
        rss_mb.append((round((time.monotonic() - started_s) / 60, 2), run, round(process.memory_info().rss / 2**20, 1)))
        stops_s.append(stop(service))
    finally:
        for running in [service, *cameras]:
            if running.poll() is None:
                running.kill()
                running.wait()
        errors.close()
    time.sleep(2.0)  # the last acknowledged messages reach the subscriber
    counter.client.disconnect()
    counter.client.loop_stop()
    broker.terminate()
    broker.wait()

    events = [json.loads(line) for line in (folder / "events.jsonl").read_text().splitlines()]
    steps, lost = 0, 0
    for camera in config["cameras"]:
        times_s = np.sort(
            [
                json.loads(line)["time_s"]
                for path in (folder / "output" / camera["name"]).glob("tracks-*.jsonl")
                for line in path.read_text().splitlines()
            ]
        )
        steps += len(times_s)
        lost += lost_steps(times_s, outages_of(camera["name"], events, stopped) + stopped)
    whole, rotated = whole_files(folder / "output")
    second_run = [sample for sample in rss_mb if sample[1] == 2]
    result = {
        "steps": steps,
        "steps_lost_outside_outages": lost,
        "mqtt_messages": counter.count,
        "events_written": len(events),
        "rss_mb_start": second_run[0][2] if second_run else rss_mb[0][2],
        "rss_mb_end": rss_mb[-1][2],
        "rss_mb": rss_mb,
        "stop_s": round(max(stops_s), 3),
        "tracebacks": (folder / "serve.stderr").read_text().count("Traceback"),
        "rotated_files_whole": whole,
        "rotated_files": rotated,
        "model_trials_before_restart": trials_before,
        "model_trials_after_restart": trials_after,
        "outages": sum(event["type"] == "offline" for event in events),
        "minutes": args.minutes,
        "time_scale": args.time_scale,
        "folder": str(folder),
    }
    print(json.dumps(result, indent=1))
    if args.json is not None:
        write_json(args.json, result)


if __name__ == "__main__":
    main()
