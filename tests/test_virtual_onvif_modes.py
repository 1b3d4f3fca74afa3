"""The virtual ONVIF camera as the cameras integrators buy: ONVIF's tilt sign, moves that start after a
latency, presets kept across restarts, a camera without positions or without absolute moves, and a
geometry of its own that its clients are not told."""

import asyncio
import json
import re
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from onvif_camera import ERRORS, HEIGHT_PX, START_POSE, USER, WIDTH_PX, call, camera, render
from ptztrack.builders.camera_calibration import camera_spaces
from ptztrack.builders.episode import episode_world
from ptztrack.builders.recording import pets_scenario
from ptztrack.builders.virtual_camera import GeometryPriors, virtual_calibration, virtual_geometry
from ptztrack.camera.onvif_spaces import AxisSpeeds
from ptztrack.config import ScenarioError, write_camera_calibration
from ptztrack.files import InputError
from ptztrack.virtual_onvif.head import Head

pytest.importorskip("onvif", reason="the ONVIF client is onvif-zeep-async (pip install onvif-zeep-async)")

import zeep.exceptions  # noqa: E402  (onvif-zeep-async's SOAP library)

from ptztrack.builders.virtual_camera import virtual_onvif_camera
from ptztrack.virtual_onvif.ptz import PAN_TILT_FOV  # noqa: E402
from ptztrack.virtual_onvif.server import VirtualONVIFCamera  # noqa: E402

pytestmark = pytest.mark.onvif

FAST = AxisSpeeds(pan_deg_s=180.0, tilt_deg_s=180.0, zoom_per_s=14.0)


async def still(ptz, profile: dict):
    """The status once the head is still."""
    while True:
        status = await ptz.GetStatus(profile)
        if (status.MoveStatus.PanTilt, status.MoveStatus.Zoom) == ("IDLE", "IDLE"):
            return status
        await asyncio.sleep(0.02)


def vector(position) -> np.ndarray:
    """(x, y, zoom) of a PTZVector."""
    return np.array([position.PanTilt.x, position.PanTilt.y, position.Zoom.x])


def normalised(status) -> np.ndarray:
    return vector(status.Position)


def test_positive_y_looks_up_in_every_move_of_the_virtual_calibration():
    """With ``--calibration virtual``'s spaces (ONVIF's sign: normalised +1 a depression of -45 degrees),
    a ContinuousMove, an AbsoluteMove and a RelativeMove of positive y each tilt the head up (the model's
    depression falls) and raise the reported y; a ContinuousMove of positive x raises both the pan and x."""
    spaces = camera_spaces(virtual_calibration())
    assert spaces.pose([0.0, 1.0, 0.0])[1] == -45.0 and spaces.pose([0.0, -1.0, 0.0])[1] == 45.0
    cam = VirtualONVIFCamera(render, spaces, FAST, START_POSE, (WIDTH_PX, HEIGHT_PX), frame_rate_hz=50.0)

    async def moves(client, token: str):
        ptz, profile = await client.create_ptz_service(), {"ProfileToken": token}
        seen = [(normalised(await still(ptz, profile)), cam.truth()[1][-1])]

        async def after(request) -> None:
            await request
            status = await still(ptz, profile)
            await asyncio.sleep(0.1)  # an image rendered where the head stands
            seen.append((normalised(status), cam.truth()[1][-1]))

        velocity = {"PanTilt": {"x": 0.2, "y": 0.2}}
        await after(ptz.ContinuousMove({**profile, "Velocity": velocity, "Timeout": "PT0.2S"}))
        y = float(seen[-1][0][1]) + 0.2
        await after(ptz.AbsoluteMove({**profile, "Position": {"PanTilt": {"x": 0.0, "y": y}}}))
        await after(ptz.RelativeMove({**profile, "Translation": {"PanTilt": {"x": 0.0, "y": 0.1}}}))
        return seen

    with cam:
        seen = call(cam.onvif_port, moves)
    (start, start_pose), *after = seen
    for (before, before_pose), (now, pose) in zip(seen[:-1], after, strict=True):
        assert now[1] > before[1] and pose[1] < before_pose[1], (before, now, before_pose, pose)
        np.testing.assert_allclose(spaces.pose(now), pose, atol=1e-6)
    # ContinuousMove: 0.2 of 180 deg/s for 0.2 s on both axes, each the normalised space's way.
    assert after[0][1][0] - start_pose[0] == pytest.approx(7.2, abs=1e-6)
    assert after[0][1][1] - start_pose[1] == pytest.approx(-7.2, abs=1e-6)


def test_a_command_moves_the_head_after_its_latency_and_it_is_moving_from_the_command_on():
    """On the head's clock: a move commanded at 0 with a latency of 0.2 s leaves the pose as it was
    until 0.2 s, while the axis is reported moving, then travels at its rate; a command during another's
    latency lets the first go on until its own start; an axis a command leaves where it stands is not
    moving; Stop halts at once and drops what has not started."""
    clock_s = [100.0]
    limits = np.array([[-170.0, 170.0], [-10.0, 80.0], [1.0, 8.0]])
    head = Head(np.array([0.0, 20.0, 1.0]), limits, np.array([10.0, 10.0, 1.0]), 0.2, lambda: clock_s[0])

    def at(t_s: float):
        clock_s[0] = 100.0 + t_s
        _, pose, moving = head.now()
        return pose.tolist(), moving

    head.move_to([5.0, 20.0, None], [1.0, 1.0, 1.0])
    for t_s in (0.0, 0.1, 0.2):
        pose, moving = at(t_s)
        assert pose == [0.0, 20.0, 1.0] and moving == [True, False, False], (t_s, pose, moving)
    assert at(0.45)[0][0] == pytest.approx(2.5) and at(0.7) == ([5.0, 20.0, 1.0], [False] * 3)
    # A second command 0.1 s into the first's travel (0.4 s), the first goes on till 0.6 s, then back.
    at(0.4)
    head.move_to([-5.0, None, None], [1.0, 1.0, 1.0])
    assert at(0.5)[0][0] == pytest.approx(3.0) and at(0.6)[0][0] == pytest.approx(4.0)
    assert at(0.8)[0][0] == pytest.approx(2.0) and at(1.6) == ([-5.0, 20.0, 1.0], [False] * 3)
    head.run([None, None, 0.5], 2.0)  # zoom at 0.5 per second for 2 s, from 1.8 s
    assert at(1.8) == ([-5.0, 20.0, 1.0], [False, False, True]) and at(2.8)[0][2] == pytest.approx(1.5)
    head.stop([False, False, True])
    assert at(2.8) == ([-5.0, 20.0, 1.5], [False] * 3) and at(5.0)[0][2] == 1.5
    head.run([0.5, None, None], 1.0)
    head.stop([True, False, False])  # within the latency: the run never starts
    assert at(6.0) == ([-5.0, 20.0, 1.5], [False] * 3)


def test_getstatus_says_moving_and_the_position_stays_until_the_latency_has_passed():
    """Through ONVIF, a camera of latency 0.4 s: the statuses answered within 0.4 s of sending an
    AbsoluteMove say MOVING and give the start position (a bound load cannot break: they were answered
    before the move could start); the head then arrives at the target. The latency is the camera's
    ``move_latency_s``."""
    latency_s = 0.4
    target = np.array([0.3, 0.0, 0.0])

    async def move(client, token: str):
        ptz, profile = await client.create_ptz_service(), {"ProfileToken": token}
        start = normalised(await still(ptz, profile))
        position = {"PanTilt": {"x": float(target[0]), "y": float(target[1])}, "Zoom": {"x": float(target[2])}}
        sent_s = time.monotonic()
        await ptz.AbsoluteMove({**profile, "Position": position})
        early = []
        while True:
            status = await ptz.GetStatus(profile)
            if time.monotonic() - sent_s >= latency_s:
                break
            early.append(status)
        return start, early, normalised(await still(ptz, profile))

    with camera(move_latency_s=latency_s) as cam:
        start, early, end = call(cam.onvif_port, move)
    assert early, "no GetStatus was answered within the latency"
    for status in early:
        assert status.MoveStatus.PanTilt == "MOVING" and np.allclose(normalised(status), start, atol=1e-9)
    np.testing.assert_allclose(end, target, atol=1e-6)


def test_presets_are_kept_in_their_file_across_a_restart_and_a_bad_file_is_one_line(tmp_path):
    """A preset set on one camera is there, at its position, for a new camera started with the same
    presets file; the next new preset takes the next token; a removed one leaves the file. A file that
    is not a presets file is refused in one line naming it."""
    path = tmp_path / "presets.json"

    async def set_preset(client, token: str):
        ptz, profile = await client.create_ptz_service(), {"ProfileToken": token}
        await ptz.AbsoluteMove({**profile, "Position": {"PanTilt": {"x": 0.2, "y": 0.1}, "Zoom": {"x": 0.3}}})
        position = normalised(await still(ptz, profile))
        return await ptz.SetPreset({**profile, "PresetName": "door"}), position

    async def use_presets(client, token: str):
        ptz, profile = await client.create_ptz_service(), {"ProfileToken": token}
        presets = [(preset.token, preset.Name, vector(preset.PTZPosition)) for preset in await ptz.GetPresets(profile)]
        await ptz.GotoPreset({**profile, "PresetToken": presets[0][0]})
        arrived = normalised(await still(ptz, profile))
        second = await ptz.SetPreset({**profile, "PresetName": "gate"})
        await ptz.RemovePreset({**profile, "PresetToken": presets[0][0]})
        return presets, arrived, second

    with camera(presets_path=path) as first:
        token, position = call(first.onvif_port, set_preset)
    assert path.exists()
    with camera(presets_path=path) as second:
        presets, arrived, second_token = call(second.onvif_port, use_presets)
    assert [(kept_token, name) for kept_token, name, _ in presets] == [(token, "door")]
    np.testing.assert_allclose(presets[0][2], position, atol=1e-9)
    np.testing.assert_allclose(arrived, position, atol=1e-6)
    assert second_token == "2"
    assert [entry["token"] for entry in json.loads(path.read_text())["presets"]] == ["2"]
    for text in ("{not json", '{"presets": [{"token": "1", "name": "door", "pose": [1, 2]}]}', "[]"):
        path.write_text(text)
        with pytest.raises(InputError) as refused:
            camera(presets_path=path)
        message = str(refused.value)
        assert message.startswith(str(path)) and "\n" not in message, message


def test_a_camera_without_positions_reports_its_moves_and_its_presets_without_them():
    """--no-positions: GetStatus has MoveStatus and UtcTime but no Position; a preset has its name and no
    PTZPosition, and going to it works; the capabilities do not claim StatusPosition."""

    async def blind(client, token: str):
        ptz, profile = await client.create_ptz_service(), {"ProfileToken": token}
        capabilities = await ptz.GetServiceCapabilities()
        await ptz.RelativeMove({**profile, "Translation": {"PanTilt": {"x": 0.1, "y": 0.0}}})
        moving = await ptz.GetStatus(profile)
        await still(ptz, profile)
        preset = await ptz.SetPreset({**profile, "PresetName": "door"})
        await ptz.GotoHomePosition(profile)
        await still(ptz, profile)
        await ptz.GotoPreset({**profile, "PresetToken": preset})
        status = await still(ptz, profile)
        await asyncio.sleep(0.2)  # an image rendered where the head stands
        return capabilities, moving, status, await ptz.GetPresets(profile)

    with camera(positions=False) as cam:
        capabilities, moving, status, presets = call(cam.onvif_port, blind)
        pose = cam.truth()[1][-1]
    assert capabilities._attr_1 == {"MoveStatus": "true", "StatusPosition": "false"}  # attributes of ONVIF > 2.4
    assert moving.Position is None and moving.MoveStatus.PanTilt == "MOVING" and moving.UtcTime is not None
    assert status.Position is None and status.MoveStatus.PanTilt == "IDLE"
    assert [(preset.Name, preset.PTZPosition) for preset in presets] == [("door", None)]
    # The preset was set 0.1 of the normalised pan (17 degrees) from home, and the head went back there.
    assert pose[0] == pytest.approx(START_POSE[0] + 17.0, abs=1e-6)


def test_a_relative_only_camera_refuses_absolute_moves_and_offers_no_absolute_space():
    """--relative-only: no absolute position space in the node or the configuration options, no default
    absolute space or limits in the configuration; AbsoluteMove is env:Receiver ter:ActionNotSupported
    ter:OptionalActionNotSupported; RelativeMove (generic and FOV), ContinuousMove, GotoHomePosition and
    presets move the head."""

    async def relative(client, token: str):
        ptz, profile = await client.create_ptz_service(), {"ProfileToken": token}
        node = (await ptz.GetNodes())[0]
        options = await ptz.GetConfigurationOptions({"ConfigurationToken": "PTZ_Config_1"})
        configuration = (await ptz.GetConfigurations())[0]
        with pytest.raises(zeep.exceptions.Fault) as refused:
            await ptz.AbsoluteMove({**profile, "Position": {"PanTilt": {"x": 0.1, "y": 0.1}}})
        start = normalised(await still(ptz, profile))
        await ptz.RelativeMove({**profile, "Translation": {"PanTilt": {"x": 0.1, "y": 0.0}}})
        relative = normalised(await still(ptz, profile))
        translation = {"PanTilt": {"x": 0.5, "y": 0.0, "space": PAN_TILT_FOV}}
        await ptz.RelativeMove({**profile, "Translation": translation})
        fov = normalised(await still(ptz, profile))
        preset = await ptz.SetPreset(profile)
        await ptz.ContinuousMove({**profile, "Velocity": {"PanTilt": {"x": -0.5, "y": 0.0}}, "Timeout": "PT0.1S"})
        continuous = normalised(await still(ptz, profile))
        await ptz.GotoHomePosition(profile)
        home = normalised(await still(ptz, profile))
        await ptz.GotoPreset({**profile, "PresetToken": preset})
        back = normalised(await still(ptz, profile))
        return node, options, configuration, refused.value, (start, relative, fov, continuous, home, back)

    with camera(absolute_moves=False) as cam:
        node, options, configuration, fault, positions = call(cam.onvif_port, relative)
    for spaces in (node.SupportedPTZSpaces, options.Spaces):
        assert not spaces.AbsolutePanTiltPositionSpace and not spaces.AbsoluteZoomPositionSpace
        assert spaces.RelativePanTiltTranslationSpace and spaces.ContinuousPanTiltVelocitySpace
    assert configuration.DefaultAbsolutePantTiltPositionSpace is None
    assert configuration.DefaultAbsoluteZoomPositionSpace is None and configuration.PanTiltLimits is None
    assert fault.code.endswith("Receiver") and [subcode.text for subcode in fault.subcodes] == [
        f"{{{ERRORS}}}ActionNotSupported",
        f"{{{ERRORS}}}OptionalActionNotSupported",
    ]
    start, relative, fov, continuous, home, back = positions
    assert relative[0] == pytest.approx(start[0] + 0.1, abs=1e-9)
    assert fov[0] > relative[0] and continuous[0] < fov[0]
    np.testing.assert_allclose(home, start, atol=1e-9)
    np.testing.assert_allclose(back, fov, atol=1e-9)


@pytest.fixture(scope="module")
def pets():
    return pets_scenario("hog")


def test_a_seeded_geometry_is_reproducible_within_its_priors_and_contains_the_start_pose(pets, tmp_path):
    """The same seed draws the same geometry, another seed another; the draws lie within the priors and
    contain the recording's start pose (pan and tilt), at the recording camera's position and focal
    length; written as a calibration file and read back with --geometry it is the same geometry. A file
    elsewhere than the recording camera, or not containing the start pose, is refused in one line."""
    priors, world = GeometryPriors(), episode_world(pets, 0)
    world_start = world.grid.poses[world.start_action]
    geometries = [virtual_geometry(pets, seed=seed) for seed in (0, 0, 1, 2, 3)]
    assert geometries[0] == geometries[1] and geometries[0] != geometries[2]
    for geometry in geometries:
        span_deg = geometry.pan_deg[1] - geometry.pan_deg[0]
        assert priors.pan_span_deg[0] <= span_deg <= priors.pan_span_deg[1]
        start_pan = 2.0 * (world_start[0] - geometry.pan_deg[0]) / span_deg - 1.0
        assert priors.start_pan[0] <= start_pan <= priors.start_pan[1]
        assert priors.tilt_down_deg[0] <= geometry.tilt_deg[0] <= priors.tilt_down_deg[1]
        assert priors.tilt_up_deg[0] <= geometry.tilt_deg[1] <= priors.tilt_up_deg[1]
        zoom = np.array(geometry.zoom_curve)
        assert len(zoom) == priors.zoom_points and priors.widest_zoom[0] <= zoom[0, 1] <= priors.widest_zoom[1]
        assert priors.longest_zoom[0] <= zoom[-1, 1] <= priors.longest_zoom[1]
        assert geometry.tilt_deg[1] <= world_start[1] <= geometry.tilt_deg[0]
        assert geometry.move_times.pan[0] == virtual_calibration().move_times.pan[0] > 0
    assert geometries[0].f_min_px == world.camera.f_min_px
    assert geometries[0].position_m == pytest.approx(world.camera.position_m, abs=0.0)
    path = tmp_path / "geometry.yaml"
    write_camera_calibration(path, geometries[2])
    assert virtual_geometry(pets, path=path) == geometries[2]
    elsewhere = geometries[2].model_copy(update={"position_m": (0.0, 0.0, 6.0)})
    write_camera_calibration(path, elsewhere)
    with pytest.raises(ScenarioError, match="position_m .* is not the recording camera's"):
        virtual_geometry(pets, path=path)
    write_camera_calibration(path, geometries[2].model_copy(update={"pan_deg": (-90.0, 0.0)}))
    with pytest.raises(ScenarioError, match=f"does not contain the recording's start pan {world_start[0]:.6g} deg"):
        virtual_geometry(pets, path=path)
    with pytest.raises(ScenarioError, match="negative"):
        virtual_geometry(pets, seed=-1)


def test_a_relative_move_turns_the_head_by_the_hidden_geometrys_span(pets):
    """A camera of a seeded geometry: RelativeMove by a normalised dx turns the head by exactly
    dx x span / 2 degrees of the geometry (not the virtual calibration's 90)."""
    geometry = virtual_geometry(pets, seed=7)
    span_deg = geometry.pan_deg[1] - geometry.pan_deg[0]
    cam, _ = virtual_onvif_camera(pets, 1.0, 0, USER, "s3cret-pass", geometry=geometry)

    async def move(client, token: str):
        ptz, profile = await client.create_ptz_service(), {"ProfileToken": token}
        await still(ptz, profile)
        before = cam.truth()[1][-1]
        await ptz.RelativeMove({**profile, "Translation": {"PanTilt": {"x": 0.1, "y": 0.0}}})
        await still(ptz, profile)
        await asyncio.sleep(0.1)  # an image at the pose reached
        return before, cam.truth()[1][-1]

    with cam:
        before, after = call(cam.onvif_port, move)
    assert after[0] - before[0] == pytest.approx(0.1 * span_deg / 2.0, abs=1e-9)
    assert after[1:] == pytest.approx(before[1:], abs=1e-12) and span_deg != 180.0


@pytest.mark.slow
def test_serve_camera_hides_its_geometry_and_threads_every_mode_to_each_camera(tmp_path):
    """`ptztrack serve-camera --cameras 2 --geometry-seed 3 --no-positions --relative-only --presets FILE`
    in a process of its own: each camera says its calibration is hidden; the second answers GetStatus
    without a Position, refuses AbsoluteMove, and keeps its preset in FILE with -2 before the suffix."""
    presets = tmp_path / "presets.json"
    command = [sys.executable, "-m", "ptztrack.cli", "serve-camera", "--port", "0", "--cameras", "2"]
    command += ["--geometry-seed", "3", "--no-positions", "--relative-only", "--presets", str(presets)]
    server = subprocess.Popen(
        command,
        stdout=subprocess.PIPE,
        text=True,
        # A test run in the background of a non-interactive shell inherits SIGINT ignored.
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )

    async def second(client, token: str):
        ptz, profile = await client.create_ptz_service(), {"ProfileToken": token}
        with pytest.raises(zeep.exceptions.Fault) as refused:
            await ptz.AbsoluteMove({**profile, "Position": {"PanTilt": {"x": 0.1, "y": 0.1}}})
        await ptz.SetPreset({**profile, "PresetName": "door"})
        return await ptz.GetStatus(profile), refused.value

    try:
        lines = [line for line in (server.stdout.readline() for _ in range(4)) if "onvif://" in line]
        assert len(lines) == 2 and all(line.endswith("(calibration: hidden)\n") for line in lines), lines
        port = int(re.search(r"onvif://127\.0\.0\.1:(\d+)", lines[1]).group(1))
        status, fault = call(port, second)  # the camera asks for no credentials: those given are not read
    finally:
        server.send_signal(signal.SIGINT)
        server.communicate(timeout=30)
    assert status.Position is None and status.MoveStatus.PanTilt == "IDLE"
    assert [subcode.text for subcode in fault.subcodes][-1] == f"{{{ERRORS}}}OptionalActionNotSupported"
    assert not presets.exists()
    assert [entry["name"] for entry in json.loads((tmp_path / "presets-2.json").read_text())["presets"]] == ["door"]
