"""`ptztrack serve` and its virtual cameras as processes on 127.0.0.1, as an integrator runs them: start,
read /healthz, wait for a camera's report, stop by SIGTERM; `ptztrack serve-camera` as a user runs it,
stopped by Ctrl-C."""

import json
import re
import signal
import subprocess
import sys
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from contextlib import contextmanager

TIMEOUT_S = 90.0


def virtual_camera(port: int) -> subprocess.Popen:
    """`ptztrack serve-camera` on 127.0.0.1:``port``, up."""
    (camera,) = virtual_cameras_up([port])
    return camera


def virtual_cameras_up(ports: list[int]) -> list[subprocess.Popen]:
    """`ptztrack serve-camera` on each of 127.0.0.1:``ports``, started together, each up."""
    command = [sys.executable, "-m", "ptztrack.cli", "serve-camera", "--port"]
    cameras = [
        subprocess.Popen([*command, str(port)], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        for port in ports
    ]
    for camera, port in zip(cameras, ports, strict=True):
        assert f"onvif://127.0.0.1:{port}" in camera.stdout.readline()
    return cameras


@contextmanager
def serve_camera(options: list[str], environment: dict | None = None) -> Iterator[tuple[subprocess.Popen, list[str]]]:
    """`ptztrack serve-camera --port 0 OPTIONS` in a process of its own, as a camera is a machine of its own:
    the process and its cameras' onvif:// addresses once every one is up; stopped by Ctrl-C at the end of
    the block, as a user stops it (its return code then tells whether it stopped cleanly)."""
    command = [sys.executable, "-m", "ptztrack.cli", "serve-camera", "--port", "0", *options]
    server = subprocess.Popen(
        command,
        stdout=subprocess.PIPE,
        text=True,
        env=environment,
        # A test run in the background of a non-interactive shell inherits SIGINT ignored: give the
        # server the disposition a terminal gives, so that the Ctrl-C at the end stops it.
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    try:
        assert server.stdout is not None
        addresses: list[str] = []
        while True:
            line = server.stdout.readline()
            assert line, "serve-camera ended before its cameras were up"
            addresses += re.findall(r"onvif://127\.0\.0\.1:\d+", line)
            if line.startswith("the recording plays"):  # printed once every camera is up
                break
        yield server, addresses
    finally:
        server.send_signal(signal.SIGINT)
        server.communicate(timeout=30)


@contextmanager
def virtual_cameras() -> Iterator[list[subprocess.Popen]]:
    """A list to put :func:`virtual_camera`'s processes in, each killed at the end of the block."""
    cameras: list[subprocess.Popen] = []
    try:
        yield cameras
    finally:
        for camera in cameras:
            camera.kill()
            camera.wait()


def serve_process(config, cameras: int = 1) -> tuple[subprocess.Popen, str]:
    """`ptztrack serve CONFIG` (of ``cameras`` cameras) and the address of its /healthz, once it serves."""
    command = [sys.executable, "-m", "ptztrack.cli", "serve", str(config)]
    service = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = service.stdout.readline()
    assert line.startswith(f"serving {cameras} camera"), line + service.stderr.read()
    return service, re.search(r"health at (\S+)", line).group(1).rstrip(",")


def health(address: str) -> dict:
    """The service's /healthz report, whatever its status."""
    try:
        with urllib.request.urlopen(address, timeout=5) as answer:
            return json.loads(answer.read())
    except urllib.error.HTTPError as unhealthy:  # 503: a camera not running, its report all the same
        return json.loads(unhealthy.read())


def until(address: str, condition, camera: str = "front") -> dict:
    """``camera``'s /healthz report once ``condition`` holds of it (within TIMEOUT_S)."""
    deadline = time.monotonic() + TIMEOUT_S
    while time.monotonic() < deadline:
        report = health(address)["cameras"][camera]
        if condition(report):
            return report
        time.sleep(0.2)
    raise AssertionError(f"not reached within {TIMEOUT_S} s: {report}")


def stop(service: subprocess.Popen) -> tuple[float, str]:
    """SIGTERM: the seconds the service took to end, and its stderr."""
    sent_s = time.monotonic()
    service.send_signal(signal.SIGTERM)
    _, errors = service.communicate(timeout=30)
    return time.monotonic() - sent_s, errors


def whole_rows(folder) -> list[dict]:
    """Every row of the tracks' files in a camera's ``folder``, each file checked whole: none is left as
    .part, each line of each is a whole record."""
    assert not list(folder.glob("*.part"))
    jsonls = sorted(folder.glob("tracks-*.jsonl"))
    rows = [json.loads(line) for jsonl in jsonls for line in jsonl.read_text().splitlines()]
    assert all(row["frame"] >= 1 for row in rows)
    for mot in folder.glob("tracks-*.mot.txt"):
        assert all(len(line.split(",")) == 10 for line in mot.read_text().splitlines())
    return rows
