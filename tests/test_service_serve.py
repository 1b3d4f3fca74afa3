"""`ptztrack serve` against a virtual camera on 127.0.0.1, as an integrator runs it: the camera killed
and started again, the service stopped by SIGTERM and started again, a real broker counting its
messages."""

import json
import re
import signal
import subprocess
import sys
import time
import urllib.error
import urllib.request

import numpy as np
import pytest
import yaml

from mqtt_broker import Subscriber, free_port, mosquitto
from ptztrack.detect.detector_model import HEIGHT_BIN_EDGES_PX, PRIOR_TRIALS_PER_BIN

pytest.importorskip("ipycam", reason="the virtual ONVIF camera needs ipycam (pip install --no-deps ipycam==1.3.0)")
# One live loop at a time (one xdist worker), as tests/test_loop_live_onvif.py runs them.
pytestmark = [pytest.mark.onvif, pytest.mark.xdist_group("live-loop")]

TIMEOUT_S = 90.0


def _camera(port: int) -> subprocess.Popen:
    """`ptztrack serve-camera` on 127.0.0.1:``port``, up."""
    command = [sys.executable, "-m", "ptztrack.cli", "serve-camera", "--port", str(port)]
    camera = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    assert f"onvif://127.0.0.1:{port}" in camera.stdout.readline()
    return camera


def _serve(config) -> tuple[subprocess.Popen, str]:
    """`ptztrack serve CONFIG` and the address of its /healthz, once it serves."""
    command = [sys.executable, "-m", "ptztrack.cli", "serve", str(config)]
    service = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = service.stdout.readline()
    assert line.startswith("serving 1 camera"), line + service.stderr.read()
    return service, re.search(r"health at (\S+)", line).group(1).rstrip(",")


def _health(address: str) -> dict:
    try:
        with urllib.request.urlopen(address, timeout=5) as answer:
            return json.loads(answer.read())
    except urllib.error.HTTPError as unhealthy:  # 503: a camera not running, its report all the same
        return json.loads(unhealthy.read())


def _until(address: str, condition) -> dict:
    deadline = time.monotonic() + TIMEOUT_S
    while time.monotonic() < deadline:
        report = _health(address)["cameras"]["front"]
        if condition(report):
            return report
        time.sleep(0.2)
    raise AssertionError(f"not reached within {TIMEOUT_S} s: {report}")


def _stop(service: subprocess.Popen) -> tuple[float, str]:
    """SIGTERM: the seconds the service took to end, and its stderr."""
    sent_s = time.monotonic()
    service.send_signal(signal.SIGTERM)
    _, errors = service.communicate(timeout=30)
    return time.monotonic() - sent_s, errors


def test_serve_goes_on_through_a_camera_restart_stops_on_sigterm_whole_and_keeps_its_model(tmp_path):
    port = free_port()
    with mosquitto(tmp_path) as broker:
        subscriber = Subscriber(broker, ["ptztrack/+/events", "ptztrack/+/status"])
        config = tmp_path / "serve.yaml"
        camera = {"name": "front", "url": f"onvif://127.0.0.1:{port}", "calibration": "virtual", "policy": "smpl"}
        settings = {"output": "out", "events": "events.jsonl", "mqtt": {"port": broker}, "http_port": 0}
        config.write_text(yaml.safe_dump({"cameras": [camera], **settings, "rotate_s": 2, "model_save_s": 2}))
        cameras: list[subprocess.Popen] = []
        try:
            # The service starts before its camera is up: it tries again until the camera answers.
            service, health = _serve(config)
            try:
                _until(health, lambda report: report["status"] == "offline")
                cameras.append(_camera(port))
                before = _until(health, lambda report: report["steps"] >= 10)
                cameras[0].kill()  # gone at once, as a camera that loses power
                cameras[0].wait()
                _until(health, lambda report: report["status"] == "offline")
                cameras.append(_camera(port))
                going_on = before["steps"] + 10
                after = _until(health, lambda report: report["reconnects"] == 1 and report["steps"] > going_on)
            finally:
                stop_s, errors = _stop(service)
            assert after["outages"] == 1 and after["status"] == "running"  # the start's wait is no outage
            assert service.returncode == 0 and stop_s <= 2.0, (stop_s, errors)
            assert "Traceback" not in errors
            assert errors.count("camera front unreachable") == 1 and errors.count("camera front lost") == 1, errors
            assert errors.count("camera front back") == 1, errors
            trials = np.sum(json.loads((tmp_path / "out" / "front" / "detector_model.json").read_text())["trials"])
            # Started again: the model is read back, and its trials go on from where they were.
            service, health = _serve(config)
            try:
                _until(health, lambda report: report["steps"] >= 5)
            finally:
                _, errors = _stop(service)
            assert service.returncode == 0 and "Traceback" not in errors
        finally:
            for running in cameras:
                running.kill()
                running.wait()
        received = subscriber.count_settles()
        subscriber.close()
    prior_trials = PRIOR_TRIALS_PER_BIN * (len(HEIGHT_BIN_EDGES_PX) - 1)
    again = np.sum(json.loads((tmp_path / "out" / "front" / "detector_model.json").read_text())["trials"])
    assert prior_trials < trials <= again
    # Every file is whole: none is left as .part, each line of each is a whole record.
    folder = tmp_path / "out" / "front"
    assert not list(folder.glob("*.part")) and len(list(folder.glob("tracks-*.jsonl"))) >= 3
    for jsonl in folder.glob("tracks-*.jsonl"):
        assert all(json.loads(line)["frame"] >= 1 for line in jsonl.read_text().splitlines())
    for mot in folder.glob("tracks-*.mot.txt"):
        assert all(len(line.split(",")) == 10 for line in mot.read_text().splitlines())
    events = [json.loads(line) for line in (tmp_path / "events.jsonl").read_text().splitlines()]
    statuses = [event["type"] for event in events if event["topic"] == "ptztrack/front/status"]
    # Unreachable at the start, then lost and back.
    assert statuses == ["offline", "online", "offline", "online"]
    assert {"new", "update", "end"} <= {event["type"] for event in events}
    assert received == len(events)
