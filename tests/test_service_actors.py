"""`ptztrack serve` with a camera in a Ray actor: it runs as a thread's camera would, its rows in its
files, its events through the service's one outlet (JSON lines and MQTT), its health in /healthz, its log
lines on the service's stderr and its failure raised by the service; the stop within 2 s leaves no Ray
process of the cluster the service started."""

import importlib.util
import json
import threading

import psutil
import pytest
import yaml

from mqtt_broker import Subscriber, free_port, mosquitto
from ptztrack.config import ScenarioError
from ptztrack.loop.executors import connect_ray
from ptztrack.service import ServiceConfig, serve
from serve_process import health, serve_process, stop, until, virtual_cameras, virtual_cameras_up, whole_rows

pytest.importorskip("ipycam", reason="the virtual ONVIF camera needs ipycam (pip install --no-deps ipycam==1.3.0)")
NAMES = ("front", "side")
pytestmark = [
    pytest.mark.skipif(importlib.util.find_spec("ray") is None, reason="needs the ray extra"),
    pytest.mark.xdist_group("ray"),
]


@pytest.mark.onvif
def test_a_camera_in_a_ray_actor_writes_its_files_and_its_events_lines_and_health_reach_the_service(tmp_path):
    ports = [free_port(), free_port()]
    with mosquitto(tmp_path) as broker:
        subscriber = Subscriber(broker, ["ptztrack/+/events", "ptztrack/+/status"])
        config = tmp_path / "serve.yaml"
        named = [{"name": name, "url": f"onvif://127.0.0.1:{port}"} for name, port in zip(NAMES, ports, strict=True)]
        settings = {"output": "out", "events": "events.jsonl", "mqtt": {"port": broker}, "http_port": 0}
        config.write_text(yaml.safe_dump({"cameras": named, **settings, "rotate_s": 2, "engine": "ray"}))
        with virtual_cameras() as cameras:
            cameras += virtual_cameras_up(ports)
            service, address = serve_process(config, cameras=2)
            try:
                # The Ray processes the service started, to see them gone after it.
                ray_processes = psutil.Process(service.pid).children(recursive=True)
                until(address, lambda report: report["steps"] >= 5, "side")
                report = health(address)
                # The actor's camera lost: its line and its 'offline' event are the service's.
                cameras[1].kill()
                until(address, lambda report: report["status"] == "offline", "side")
            finally:
                stop_s, errors = stop(service)
        received = subscriber.count_settles()
        subscriber.close()
    assert service.returncode == 0 and stop_s <= 2.0, (stop_s, errors)
    assert "Traceback" not in errors and errors.count("camera side lost") == 1, errors
    assert report["ok"] and [report["cameras"][name]["status"] for name in NAMES] == ["running", "running"]
    # Ended with the service: its actors' workers may take a moment more on a busy machine.
    assert ray_processes and not psutil.wait_procs(ray_processes, timeout=5)[1]
    side_rows = whole_rows(tmp_path / "out" / "side")
    assert len(side_rows) >= report["cameras"]["side"]["steps"] >= 5
    assert (tmp_path / "out" / "side" / "detector_model.json").exists()
    events = [json.loads(line) for line in (tmp_path / "events.jsonl").read_text().splitlines()]
    assert [event["type"] for event in events if event["topic"] == "ptztrack/side/status"] == ["offline"]
    side = [event for event in events if event["topic"] == "ptztrack/side/events"]
    # Every track the actor's camera started was ended at the stop, and its 'end' reached the outlet.
    started = {event["after"]["id"] for event in side if event["type"] == "new"}
    assert started and started == {event["after"]["id"] for event in side if event["type"] == "end"}
    assert received == len(events)


@pytest.fixture(scope="module")
def local_ray():
    ray = connect_ray(num_cpus=2)
    yield ray
    ray.shutdown()


def test_an_actor_cameras_failure_is_raised_by_the_service_and_a_cluster_it_joined_stays_up(tmp_path, local_ray):
    """The actor's camera cannot start (its calibration file is missing): the service raises its error, as
    for a camera in a thread; the first camera, which nobody answers for, is stopped."""
    calibration = str(tmp_path / "none.yaml")
    cameras = [{"name": name, "url": f"onvif://127.0.0.1:{free_port()}"} for name in NAMES]
    config = ServiceConfig.model_validate(
        {"cameras": [cameras[0], {**cameras[1], "calibration": calibration}], "output": str(tmp_path / "out"),
         "events": str(tmp_path / "events.jsonl"), "http_port": None, "engine": "ray"}
    )  # fmt: skip
    with pytest.raises(ScenarioError, match="none.yaml"):
        serve(config, threading.Event(), started=lambda line: None)
    assert local_ray.is_initialized()
