"""The service's configuration file: what a user writes, and one line naming the file, the field and the
value for what is wrong."""

import sys
from pathlib import Path

import pytest

from ptztrack.cli import main
from ptztrack.config import ScenarioError
from ptztrack.service import load_service_config
from ptztrack.service.config import ServiceConfig, camera_engines

CAMERA = "cameras:\n  - name: front\n    url: onvif://127.0.0.1:8080\n"


def _written(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "serve.yaml"
    path.write_text(text)
    return path


def test_a_minimal_file_takes_the_defaults_and_its_paths_are_beside_it(tmp_path):
    path = _written(tmp_path, CAMERA + "output: out\nevents: events.jsonl\nmqtt: {port: 1884}\n")
    config = load_service_config(path)
    (camera,) = config.cameras
    assert (camera.name, camera.policy, camera.detector, camera.calibration, camera.scenario, camera.pose) == (
        "front", "smpl", "hog", "virtual", "pets", "status"
    )  # fmt: skip
    assert config.output == str(tmp_path / "out") and config.events == str(tmp_path / "events.jsonl")
    assert config.mqtt is not None and (config.mqtt.host, config.mqtt.port) == ("127.0.0.1", 1884)
    assert config.mqtt.topic_prefix == "ptztrack" and config.rotate_s == 3600 and config.position_rate_hz == 1


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("cameras: []\n", "cameras: List should have at least 1 item"),
        ("cameras:\n  - name: front door\n    url: onvif://h\n", "cameras.0.name: String should match pattern"),
        (CAMERA + "  - name: front\n    url: onvif://h\n", "front appears more than once"),
        (CAMERA + "    adress: x\n", "cameras.0.adress: unknown key"),
        (CAMERA + "    policy: best\n", "cameras.0.policy: expected one of"),
        (CAMERA + "    transport: quic\n", "cameras.0.transport: Input should be 'tcp' or 'udp' (got 'quic')"),
        (CAMERA + "mqtt: {port: 70000}\n", "mqtt.port: Input should be less than or equal to 65535 (got 70000)"),
        (CAMERA + "mqtt: {topic_prefix: a/#}\n", "mqtt.topic_prefix: String should match pattern"),
        (CAMERA + "rotate_s: 0\n", "rotate_s: Input should be greater than 0 (got 0)"),
        (CAMERA + "position_rate_hz: 100\n", "position_rate_hz: must be at most 30"),
        (CAMERA + "engine: processes\n", "engine: Input should be 'auto', 'threads' or 'ray' (got 'processes')"),
        ("- front\n", "expected a mapping of service fields"),
    ],
)
def test_a_bad_file_is_one_line_naming_the_file_the_field_and_the_value(tmp_path, text, message):
    path = _written(tmp_path, text)
    with pytest.raises(ScenarioError) as error:
        load_service_config(path)
    assert str(error.value).startswith(f"{path}: ") and message in str(error.value)
    assert "\n" not in str(error.value)


def test_serve_with_a_bad_file_exits_2_with_one_line(tmp_path, capsys):
    path = _written(tmp_path, CAMERA + "http_port: -1\n")
    assert main(["serve", str(path)]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and f"{path}: http_port: " in error and "(got -1)" in error


def _cameras(count: int, engine: str) -> ServiceConfig:
    cameras = [{"name": f"camera{number}", "url": f"onvif://127.0.0.1:{8080 + number}"} for number in range(count)]
    return ServiceConfig.model_validate({"cameras": cameras, "engine": engine})


@pytest.mark.parametrize(
    ("count", "engine", "cores", "engines"),
    [
        (3, "threads", 1, ["thread"] * 3),
        (3, "ray", 8, ["thread", "ray", "ray"]),
        (1, "ray", 8, ["thread"]),
        (4, "auto", 4, ["thread"] * 4),
        (5, "auto", 4, ["thread"] + ["ray"] * 4),
    ],
)
def test_the_first_camera_is_a_thread_and_auto_puts_the_others_in_ray_beyond_the_cores(count, engine, cores, engines):
    assert camera_engines(_cameras(count, engine), cores) == engines


def test_cameras_on_ray_without_ray_installed_exit_2_with_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)  # as if not installed: importing it fails, find_spec is None
    path = _written(tmp_path, CAMERA + "  - name: side\n    url: onvif://127.0.0.1:8081\nengine: ray\n")
    assert main(["serve", str(path)]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "2 cameras" in error and "pip install 'ptztrack[ray]'" in error
