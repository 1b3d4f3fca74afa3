"""`ptztrack serve` against a virtual camera on 127.0.0.1, as an integrator runs it: the camera killed
and started again, the service stopped by SIGTERM and started again, a real broker counting its
messages."""

import json

import numpy as np
import pytest
import yaml

from mqtt_broker import Subscriber, free_port, mosquitto
from ptztrack.detect.detector_model import HEIGHT_BIN_EDGES_PX, PRIOR_TRIALS_PER_BIN
from serve_process import serve_process, stop, until, virtual_camera, virtual_cameras, whole_rows

pytest.importorskip("ipycam", reason="the virtual ONVIF camera needs ipycam (pip install --no-deps ipycam==1.3.0)")
# One live loop at a time (one xdist worker), as tests/test_loop_live_onvif.py runs them.
pytestmark = [pytest.mark.onvif, pytest.mark.xdist_group("live-loop")]


def test_serve_goes_on_through_a_camera_restart_stops_on_sigterm_whole_and_keeps_its_model(tmp_path):
    port = free_port()
    with mosquitto(tmp_path) as broker:
        subscriber = Subscriber(broker, ["ptztrack/+/events", "ptztrack/+/status"])
        config = tmp_path / "serve.yaml"
        camera = {"name": "front", "url": f"onvif://127.0.0.1:{port}", "calibration": "virtual", "policy": "smpl"}
        settings = {"output": "out", "events": "events.jsonl", "mqtt": {"port": broker}, "http_port": 0}
        config.write_text(yaml.safe_dump({"cameras": [camera], **settings, "rotate_s": 2, "model_save_s": 2}))
        with virtual_cameras() as cameras:
            # The service starts before its camera is up: it tries again until the camera answers.
            service, health = serve_process(config)
            try:
                until(health, lambda report: report["status"] == "offline")
                cameras.append(virtual_camera(port))
                before = until(health, lambda report: report["steps"] >= 10)
                cameras[0].kill()  # gone at once, as a camera that loses power
                cameras[0].wait()
                until(health, lambda report: report["status"] == "offline")
                cameras.append(virtual_camera(port))
                going_on = before["steps"] + 10
                after = until(health, lambda report: report["reconnects"] == 1 and report["steps"] > going_on)
            finally:
                stop_s, errors = stop(service)
            assert after["outages"] == 1 and after["status"] == "running"  # the start's wait is no outage
            assert service.returncode == 0 and stop_s <= 2.0, (stop_s, errors)
            assert "Traceback" not in errors
            assert errors.count("camera front unreachable") == 1 and errors.count("camera front lost") == 1, errors
            assert errors.count("camera front back") == 1, errors
            trials = np.sum(json.loads((tmp_path / "out" / "front" / "detector_model.json").read_text())["trials"])
            # Started again: the model is read back, and its trials go on from where they were.
            service, health = serve_process(config)
            try:
                until(health, lambda report: report["steps"] >= 5)
            finally:
                _, errors = stop(service)
            assert service.returncode == 0 and "Traceback" not in errors
        received = subscriber.count_settles()
        subscriber.close()
    prior_trials = PRIOR_TRIALS_PER_BIN * (len(HEIGHT_BIN_EDGES_PX) - 1)
    again = np.sum(json.loads((tmp_path / "out" / "front" / "detector_model.json").read_text())["trials"])
    assert prior_trials < trials <= again
    folder = tmp_path / "out" / "front"
    assert whole_rows(folder) and len(list(folder.glob("tracks-*.jsonl"))) >= 3
    events = [json.loads(line) for line in (tmp_path / "events.jsonl").read_text().splitlines()]
    statuses = [event["type"] for event in events if event["topic"] == "ptztrack/front/status"]
    # Unreachable at the start, then lost and back.
    assert statuses == ["offline", "online", "offline", "online"]
    assert {"new", "update", "end"} <= {event["type"] for event in events}
    assert received == len(events)
