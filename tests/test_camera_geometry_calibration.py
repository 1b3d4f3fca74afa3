"""``ptztrack camera calibrate --geometry`` against the virtual camera: bad ground points refused before any
move, a sweep whose pictures do not register ending in one line with the old file intact, and Ctrl-C
leaving the old file intact."""

import os
import re
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import yaml

pytest.importorskip("ipycam", reason="the virtual ONVIF camera needs ipycam (pip install --no-deps ipycam==1.3.0)")
pytest.importorskip("onvif", reason="the ONVIF client is onvif-zeep-async (pip install onvif-zeep-async)")

from ptztrack.builders.camera_calibration import camera_spaces
from ptztrack.builders.recording import pets_scenario  # noqa: E402
from ptztrack.builders.virtual_camera import (
    VIRTUAL_SPEEDS,
    VIRTUAL_SUPERSAMPLE,
    virtual_calibration,
    virtual_onvif_camera,
)
from ptztrack.cli import main  # noqa: E402
from ptztrack.virtual_onvif.server import VirtualONVIFCamera  # noqa: E402

pytestmark = pytest.mark.onvif

OLD_FILE = "pan_deg: [-90, 90]\ntilt_deg: [45, -45]\nzoom_curve: [[0, 1], [1, 8]]\n# the user's own file\n"
# Ground points spread over the 160 x 120 picture, and three of them on one line with a fourth.
SPREAD = [[20, 70, 0, 0], [140, 72, 10, 0], [30, 110, 0, 6], [130, 112, 10, 6], [80, 90, 5, 3]]
COLLINEAR = [[20, 70, 0, 0], [60, 80, 1, 1], [100, 90, 2, 2], [140, 100, 3, 3]]


def _points(path, rows) -> str:
    path.write_text(yaml.safe_dump({"points": rows}))
    return str(path)


def _calibrate(url: str, calibration, *options: str) -> int:
    return main(["camera", "calibrate", "--geometry", "--camera", url, "--calibration", str(calibration), *options])


def test_collinear_or_outside_ground_points_are_refused_in_one_line_before_any_move(tmp_path, capsys):
    """Points on one line are refused before connecting, a pixel outside the picture once its first picture
    is in and before any move: exit 2, one line naming the file, the camera where it was, the old file as
    it was."""
    scenario = pets_scenario()
    camera, _ = virtual_onvif_camera(scenario, 1.0, 0)
    calibration = tmp_path / "camera.yaml"
    calibration.write_text(OLD_FILE)
    with camera:
        url = f"onvif://127.0.0.1:{camera.onvif_port}"
        assert _calibrate(url, calibration, "--ground-points", _points(tmp_path / "line.yaml", COLLINEAR)) == 2
        line = capsys.readouterr().err.strip()
        assert "\n" not in line and "line.yaml: the points' ground positions lie on one line" in line
        outside = [*SPREAD[:4], [200, 90, 5, 3]]
        assert _calibrate(url, calibration, "--ground-points", _points(tmp_path / "out.yaml", outside)) == 2
        line = capsys.readouterr().err.strip()
        assert "\n" not in line and "point 5's pixel (200, 90) is outside the 160x120 px picture" in line
        poses = camera.truth()[1]
    assert np.all(poses == poses[0])
    assert calibration.read_text() == OLD_FILE


@pytest.mark.slow
def test_a_zoom_that_shows_a_blank_wall_ends_the_sweep_naming_its_step_and_keeps_the_old_file(tmp_path, capsys):
    """The recording's view until the zoom passes 2, a uniform grey beyond (a blank wall): the turns
    register, the zoom step that shows the wall does not (halved to the smallest step): exit 2 with one
    line naming that zoom step, the old file as it was."""
    scenario = pets_scenario()
    _, feed = virtual_onvif_camera(scenario, 1.0, 0, supersample=VIRTUAL_SUPERSAMPLE)
    world = feed.world

    def render(pose, elapsed_s: float) -> np.ndarray:
        image = feed.render(pose, elapsed_s)
        return np.full_like(image, 128) if pose[2] > 2.0 else image

    camera = VirtualONVIFCamera(
        render,
        camera_spaces(virtual_calibration()),
        VIRTUAL_SPEEDS,
        world.grid.poses[world.start_action],
        (world.camera.image_width_px, world.camera.image_height_px),
        frame_rate_hz=25.0,
    )
    calibration = tmp_path / "camera.yaml"
    calibration.write_text(OLD_FILE)
    with camera:
        url = f"onvif://127.0.0.1:{camera.onvif_port}"
        assert _calibrate(url, calibration, "--snapshot", str(tmp_path / "ground.png")) == 0
        capsys.readouterr()
        assert _calibrate(url, calibration, "--ground-points", _points(tmp_path / "points.yaml", SPREAD)) == 2
    error = capsys.readouterr().err.strip()
    assert "\n" not in error
    assert re.fullmatch(
        r"ptztrack: error: zoom step \d+ \(normalised zoom 0\.\d+\) did not register against the step before: "
        r"too few features match",
        error,
    ), error
    assert calibration.read_text() == OLD_FILE


@pytest.mark.slow
def test_ctrl_c_during_the_sweep_leaves_the_old_file_intact(tmp_path):
    """`camera calibrate --geometry` in a process of its own against `serve-camera` in another, Ctrl-C a few
    seconds into the sweep: exit 130, the old file as it was and nothing beside it."""
    serve = [
        sys.executable,
        "-m",
        "ptztrack.cli",
        "serve-camera",
        "--port",
        "0",
        "--supersample",
        str(VIRTUAL_SUPERSAMPLE),
    ]
    default_sigint = {"preexec_fn": lambda: signal.signal(signal.SIGINT, signal.SIG_DFL)}
    server = subprocess.Popen(serve, stdout=subprocess.PIPE, text=True, **default_sigint)  # type: ignore[call-overload]
    calibration = tmp_path / "camera.yaml"
    calibration.write_text(OLD_FILE)
    try:
        line = server.stdout.readline()
        url = re.search(r"onvif://127\.0\.0\.1:\d+", line).group(0)
        command = [sys.executable, "-m", "ptztrack.cli", "camera", "calibrate", "--geometry", "--camera", url]
        command += ["--calibration", str(calibration)]
        snapshot = subprocess.run([*command, "--snapshot", str(tmp_path / "ground.png")], timeout=120, check=False)
        assert snapshot.returncode == 0
        points = _points(tmp_path / "points.yaml", SPREAD)
        calibrating = subprocess.Popen(
            [*command, "--ground-points", points],
            stdout=subprocess.PIPE,
            text=True,
            env={**os.environ, "PYTHONUNBUFFERED": "1"},
            **default_sigint,
        )
        assert "ground view" in calibrating.stdout.readline()  # the sweep has begun
        time.sleep(2.0)
        calibrating.send_signal(signal.SIGINT)
        calibrating.communicate(timeout=60)
    finally:
        server.send_signal(signal.SIGINT)
        server.communicate(timeout=30)
    assert calibrating.returncode == 130
    assert calibration.read_text() == OLD_FILE
    assert sorted(path.name for path in tmp_path.iterdir()) == ["camera.yaml", "ground.png", "points.yaml"]
