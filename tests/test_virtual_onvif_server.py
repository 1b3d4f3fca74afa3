"""The virtual ONVIF PTZ camera against a real ONVIF client (onvif-zeep-async), RTSP reader (OpenCV's
ffmpeg) and the sockets the kernel lists: loopback only, moves that take time, authentication, images,
and a stop that leaves nothing behind."""

import asyncio
import base64
import contextlib
import http.client
import logging
import re
import socket
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path

import cv2
import numpy as np
import psutil
import pytest

pytest.importorskip("ipycam", reason="the virtual ONVIF camera needs ipycam (pip install --no-deps ipycam==1.3.0)")
onvif = pytest.importorskip("onvif", reason="the ONVIF client is onvif-zeep-async (pip install onvif-zeep-async)")

import zeep.exceptions  # noqa: E402  (onvif-zeep-async's SOAP library)

from onvif_camera import HOST, PASSWORD, USER, call  # noqa: E402
from ptztrack.camera.onvif_spaces import AxisSpeeds, CameraSpaces  # noqa: E402
from ptztrack.virtual_onvif.server import VirtualONVIFCamera  # noqa: E402

pytestmark = pytest.mark.onvif

# ONVIF's tilt: normalised +1 looks up, 10 degrees above the horizon (a depression of -10).
SPACES = CameraSpaces(pan_deg=(-170.0, 170.0), tilt_deg=(80.0, -10.0), zoom_curve=((0.0, 1.0), (1.0, 8.0)))
SPEEDS = AxisSpeeds(pan_deg_s=17.0, tilt_deg_s=17.0, zoom_per_s=2.0)
START_POSE = (0.0, 20.0, 1.0)
WIDTH_PX, HEIGHT_PX = 320, 240
ONVIF_ERRORS = "http://www.onvif.org/ver10/error"
RTSP_SKIP = "ffmpeg is not on the PATH: the camera has no RTSP stream"


def render(pose, elapsed_s: float) -> np.ndarray:
    """A 320 x 240 image: a disc where the pose points within the pan and tilt ranges, the pose in text."""
    image = np.full((HEIGHT_PX, WIDTH_PX, 3), 60, np.uint8)
    x = int((pose[0] + 170.0) / 340.0 * (WIDTH_PX - 1))
    y = int((80.0 - pose[1]) / 90.0 * (HEIGHT_PX - 1))
    cv2.circle(image, (x, y), 8 + int(2 * pose[2]), (0, 255, 255), -1)
    cv2.putText(image, f"{pose[0]:.1f} {pose[1]:.1f} {pose[2]:.2f} {elapsed_s:.1f}s", (5, 20), 0, 0.5, (255,) * 3)
    return image


def camera(speeds: AxisSpeeds = SPEEDS, **options) -> VirtualONVIFCamera:
    return VirtualONVIFCamera(
        render, SPACES, speeds, START_POSE, (WIDTH_PX, HEIGHT_PX), username=USER, password=PASSWORD, **options
    )


async def stream_uri(client, token: str) -> str:
    media = await client.create_media_service()
    setup = {"Stream": "RTP-Unicast", "Transport": {"Protocol": "RTSP"}}
    return (await media.GetStreamUri({"StreamSetup": setup, "ProfileToken": token})).Uri


async def nothing(client, token: str) -> None:
    pass


@pytest.fixture
def rtsp_reader(monkeypatch):
    """An RTSP reader over TCP that gives up after 8 s."""
    monkeypatch.setenv("OPENCV_FFMPEG_CAPTURE_OPTIONS", "rtsp_transport;tcp")

    def reader(uri: str) -> cv2.VideoCapture:
        timeouts = [cv2.CAP_PROP_OPEN_TIMEOUT_MSEC, 8000, cv2.CAP_PROP_READ_TIMEOUT_MSEC, 8000]
        return cv2.VideoCapture(uri, cv2.CAP_FFMPEG, timeouts)

    return reader


def sockets() -> set[tuple]:
    """Every inet socket of this process and its children: (pid, process name, kind, local, remote, status)."""
    listed = set()
    for process in [psutil.Process(), *psutil.Process().children(recursive=True)]:
        try:
            name = process.name()
            for connection in process.net_connections(kind="inet"):
                kind = "udp" if connection.type == socket.SOCK_DGRAM else "tcp"
                listed.add((process.pid, name, kind, connection.laddr, connection.raddr or None, connection.status))
        except psutil.NoSuchProcess:
            continue
    return listed


def multicast_groups() -> set[tuple[str, str]]:
    """(interface, group) of every multicast group joined on this host (/proc/net/igmp)."""
    groups, interface = set(), ""
    for line in Path("/proc/net/igmp").read_text().splitlines()[1:]:
        if line[:1].isdigit():
            interface = line.split()[1]
        elif line.strip():
            groups.add((interface, line.split()[0]))
    return groups


def ffmpeg_children() -> list[psutil.Process]:
    return [child for child in psutil.Process().children(recursive=True) if "ffmpeg" in child.name()]


@pytest.mark.slow
def test_every_socket_is_on_127_0_0_1_and_nothing_multicasts(rtsp_reader):
    """While an ONVIF client, an MJPEG viewer, an RTSP reader (TCP) and an RTSP session over UDP are
    open, every new socket of this process and of its children (ffmpeg) is bound to 127.0.0.1 and talks
    to 127.0.0.1, the UDP session's server ports among them, none is UDP 3702 (WS-Discovery), and no
    multicast group is joined."""
    igmp = Path("/proc/net/igmp").exists()
    groups_before = multicast_groups() if igmp else set()
    before = sockets()
    with camera() as cam, contextlib.ExitStack() as open_until_listed:
        call(cam.onvif_port, nothing)
        viewer = http.client.HTTPConnection(HOST, cam.onvif_port, timeout=5)
        open_until_listed.callback(viewer.close)
        credentials = base64.b64encode(f"{USER}:{PASSWORD}".encode()).decode()
        viewer.request("GET", "/stream.mjpeg", headers={"Authorization": f"Basic {credentials}"})
        mjpeg = viewer.getresponse()
        assert mjpeg.status == 200 and b"--frame" in mjpeg.read1(4096)
        server_ports: set[int] = set()
        if cam.rtsp_port is not None:
            rtsp = open_until_listed.enter_context(socket.create_connection((HOST, cam.rtsp_port), timeout=5))
            rtsp.sendall(
                f"SETUP rtsp://{HOST}:{cam.rtsp_port}/video_main/trackID=0 RTSP/1.0\r\nCSeq: 1\r\n"
                "Transport: RTP/AVP;unicast;client_port=50000-50001\r\n\r\n".encode()
            )
            answer = rtsp.recv(4096).decode()
            assert answer.startswith("RTSP/1.0 200"), answer
            server_ports = {int(port) for port in re.search(r"server_port=(\d+)-(\d+)", answer).groups()}
            capture = rtsp_reader(call(cam.onvif_port, stream_uri))
            open_until_listed.callback(capture.release)
            assert capture.read()[0]
        opened = sockets() - before
        groups_during = multicast_groups() if igmp else set()
    listening = {(kind, local.port) for _, _, kind, local, _, status in opened if status == psutil.CONN_LISTEN}
    assert ("tcp", cam.onvif_port) in listening
    if cam.rtsp_port is not None:
        assert ("tcp", cam.rtsp_port) in listening
        assert server_ports <= {local.port for _, _, kind, local, _, _ in opened if kind == "udp"}
        assert any(name.startswith("ffmpeg") for _, name, *_ in opened), "no ffmpeg encoder socket was seen"
    for pid, name, kind, local, remote, _ in opened:
        assert local.ip == HOST and local.port != 3702, (pid, name, kind, local)
        assert remote is None or remote.ip == HOST, (pid, name, kind, local, remote)
    assert groups_during == groups_before


@pytest.mark.slow
def test_an_absolute_move_takes_the_time_the_axis_speed_gives_and_ends_on_the_target():
    """34 degrees of pan at 17 deg/s: MOVING at once (the zoom, not asked to move, IDLE), IDLE once there,
    GetStatus on the target, and the last rendered image taken at the target pose. The time the move
    takes is read on the camera's own clock, from the poses of the images rendered on the way (17 deg/s
    between any two of them: 2 s for the 34 degrees), not from when the client saw it end (later on a
    loaded machine); the client saw MOVING for at least 1.6 s (a lower bound, which load cannot break)."""
    target_pose = np.array([34.0, 20.0, 1.0])
    target = SPACES.normalised(target_pose)

    async def move(client, token: str):
        ptz = await client.create_ptz_service()
        status = await ptz.GetStatus({"ProfileToken": token})
        assert (status.MoveStatus.PanTilt, status.MoveStatus.Zoom) == ("IDLE", "IDLE")
        position = {"PanTilt": {"x": float(target[0]), "y": float(target[1])}, "Zoom": {"x": float(target[2])}}
        sent_s = time.monotonic()
        await ptz.AbsoluteMove({"ProfileToken": token, "Position": position})
        first = status = await ptz.GetStatus({"ProfileToken": token})
        while status.MoveStatus.PanTilt == "MOVING" and time.monotonic() - sent_s < 60.0:  # only stops a hang
            await asyncio.sleep(0.05)
            status = await ptz.GetStatus({"ProfileToken": token})
        return first, status, time.monotonic() - sent_s

    with camera() as cam:
        first, last, travel_s = call(cam.onvif_port, move)
        time.sleep(0.3)  # a few more images at the target
        elapsed_s, poses = cam.truth()
    assert (first.MoveStatus.PanTilt, first.MoveStatus.Zoom) == ("MOVING", "IDLE")
    assert last.MoveStatus.PanTilt == "IDLE" and travel_s >= 1.6, travel_s
    position = last.Position
    assert np.allclose([position.PanTilt.x, position.PanTilt.y, position.Zoom.x], target, atol=1e-3)
    assert np.allclose(poses[-1], target_pose, rtol=0.0, atol=1e-6)
    # The images on the way saw the head between its ends, turning at 17 deg/s on the camera's clock,
    # and none came faster than the rate asked for (10 per second; a loaded machine can only make them later).
    assert np.any((poses[:, 0] > 5.0) & (poses[:, 0] < 29.0))
    on_the_way = (poses[:, 0] > START_POSE[0] + 1e-3) & (poses[:, 0] < target_pose[0] - 1e-3)  # not at rest
    assert np.count_nonzero(on_the_way) >= 2, elapsed_s
    pan_speed = np.diff(poses[on_the_way, 0]) / np.diff(elapsed_s[on_the_way])
    assert np.allclose(pan_speed, SPEEDS.pan_deg_s, rtol=1e-6), pan_speed
    assert np.all(np.diff(elapsed_s) > 0) and 0.08 < np.mean(np.diff(elapsed_s))


@pytest.mark.slow
def test_relative_and_continuous_moves_stop_and_presets_and_a_position_out_of_range():
    """A translation adds to the normalised position; a ContinuousMove runs until its Timeout at its
    fraction of full speed; Stop stops only the axes it names; a preset brings the head back after
    GotoHomePosition; GetConfigurationOptions is answered as itself; a position beyond 1 is a fault."""
    start = SPACES.normalised(START_POSE)

    async def operations(client, token: str):
        ptz, profile = await client.create_ptz_service(), {"ProfileToken": token}

        async def still():
            while True:
                status = await ptz.GetStatus(profile)
                if (status.MoveStatus.PanTilt, status.MoveStatus.Zoom) == ("IDLE", "IDLE"):
                    position = status.Position
                    return np.array([position.PanTilt.x, position.PanTilt.y, position.Zoom.x])
                await asyncio.sleep(0.02)

        seen = {"options": await ptz.GetConfigurationOptions({"ConfigurationToken": "PTZ_Config_1"})}
        translation = {"PanTilt": {"x": 0.1, "y": 0.2}, "Zoom": {"x": 0.5}}
        await ptz.RelativeMove({**profile, "Translation": translation})
        seen["relative"] = await still()
        sent_s = time.monotonic()
        await ptz.ContinuousMove({**profile, "Velocity": {"PanTilt": {"x": -0.5, "y": 0.0}}, "Timeout": "PT0.5S"})
        seen["continuous"], seen["continuous_s"] = await still(), time.monotonic() - sent_s  # MOVING till then
        await ptz.ContinuousMove({**profile, "Velocity": {"PanTilt": {"x": 0.5, "y": 0.0}, "Zoom": {"x": 1.0}}})
        await asyncio.sleep(0.2)
        await ptz.Stop({**profile, "PanTilt": False, "Zoom": True})
        status = await ptz.GetStatus(profile)
        seen["stopped"] = (status.MoveStatus.PanTilt, status.MoveStatus.Zoom)
        await ptz.Stop(profile)
        preset = await ptz.SetPreset({**profile, "PresetName": "door"})
        seen["preset"] = await still()
        await ptz.GotoHomePosition(profile)
        seen["home"] = await still()
        await ptz.GotoPreset({**profile, "PresetToken": preset})
        seen["back"] = await still()
        seen["presets"] = [(p.token, p.Name) for p in await ptz.GetPresets(profile)]
        await ptz.RemovePreset({**profile, "PresetToken": preset})
        seen["removed"] = await ptz.GetPresets(profile)
        with pytest.raises(zeep.exceptions.Fault) as refused:
            await ptz.AbsoluteMove({**profile, "Position": {"PanTilt": {"x": 1.5, "y": 0.0}}})
        seen["fault"] = [subcode.text for subcode in refused.value.subcodes]
        return seen

    with camera(AxisSpeeds(pan_deg_s=170.0, tilt_deg_s=90.0, zoom_per_s=7.0)) as cam:
        seen = call(cam.onvif_port, operations)
    assert seen["options"].PTZTimeout.Max.total_seconds() == 60.0
    assert np.allclose(seen["relative"], start + [0.1, 0.2, 0.5], atol=1e-6)
    # Half of 170 deg/s for 0.5 s: 42.5 degrees, a quarter of the normalised pan range.
    assert np.allclose(seen["continuous"], seen["relative"] - [0.25, 0.0, 0.0], atol=1e-6)
    # The head stopped at the Timeout (the position above: 0.5 s of turning), and GetStatus said MOVING
    # until then (a lower bound on the client's wait, which load cannot break; an upper one could).
    assert seen["continuous_s"] >= 0.45, seen["continuous_s"]
    assert seen["stopped"] == ("MOVING", "IDLE")
    assert np.allclose(seen["home"], start, atol=1e-6) and np.allclose(seen["back"], seen["preset"], atol=1e-6)
    assert seen["presets"] == [("1", "door")] and not seen["removed"]
    assert seen["fault"] == [f"{{{ONVIF_ERRORS}}}InvalidArgVal", f"{{{ONVIF_ERRORS}}}InvalidPosition"]


def test_a_wrong_password_is_a_fault_and_one_log_line_without_the_password(caplog):
    caplog.set_level(logging.DEBUG)
    with camera() as cam, pytest.raises(zeep.exceptions.Fault) as refused:
        call(cam.onvif_port, nothing, password="not-the-password")
    assert "not authorized" in str(refused.value.message).lower()
    served = [record for record in caplog.records if record.name.startswith(("ptztrack.onvif_server", "ipycam"))]
    assert any("refused" in record.getMessage() for record in served)
    for record in served:
        message = record.getMessage()
        assert record.exc_info is None and "\n" not in message and "Traceback" not in message, message
    for record in caplog.records:
        assert PASSWORD not in record.getMessage() and "not-the-password" not in record.getMessage()


@pytest.mark.slow
def test_the_snapshot_is_the_rendered_image_and_the_rtsp_stream_has_its_size(rtsp_reader):
    async def snapshot(client, token: str) -> tuple[bytes, str]:
        return await client.get_snapshot(token, basic_auth=True), await client.get_snapshot_uri(token)

    with camera() as cam:
        jpeg, uri = call(cam.onvif_port, snapshot)
        with pytest.raises(urllib.error.HTTPError) as refused:
            urllib.request.urlopen(uri, timeout=5)  # no HTTP Basic credentials
        assert refused.value.code == 401
        image = cv2.imdecode(np.frombuffer(jpeg, np.uint8), cv2.IMREAD_COLOR)
        assert uri.startswith(f"http://{HOST}:{cam.onvif_port}/")
        assert image is not None and image.shape == (HEIGHT_PX, WIDTH_PX, 3)
        # JPEG-compressed, but the image of the start pose: the disc is where render() draws it.
        assert np.abs(image.astype(float) - render(np.array(START_POSE), 0.0)).mean() < 10.0
        if cam.rtsp_port is None:
            pytest.skip(RTSP_SKIP)
        uri = call(cam.onvif_port, stream_uri)
        assert uri.startswith(f"rtsp://{HOST}:{cam.rtsp_port}/")
        capture = rtsp_reader(uri)
        try:
            read, frame = capture.read()
        finally:
            capture.release()
    assert read and frame.shape == (HEIGHT_PX, WIDTH_PX, 3)


@pytest.mark.slow
def test_stop_ends_ffmpeg_joins_its_threads_and_frees_the_port_for_a_new_camera(rtsp_reader):
    """stop() while an RTSP reader is still connected: no ffmpeg left (not even unreaped), nothing listening
    on the camera's ports, no thread of the camera left, and a new camera binds the same port at once and
    answers."""
    threads_before = set(threading.enumerate())
    first = camera()
    first.start()
    port = first.onvif_port
    capture = None
    try:
        if first.rtsp_port is not None:
            capture = rtsp_reader(call(port, stream_uri))
            assert capture.read()[0] and ffmpeg_children(), "the RTSP session has no ffmpeg encoder"
        else:
            call(port, nothing)  # connections, whose TIME_WAIT the new camera's bind must not mind
        first.stop()
    finally:
        first.stop()
        if capture is not None:
            capture.release()
    assert not ffmpeg_children()
    ports = {port, first.rtsp_port}
    assert not [entry for entry in sockets() if entry[3].port in ports and entry[5] == psutil.CONN_LISTEN]
    assert set(threading.enumerate()) <= threads_before, set(threading.enumerate()) - threads_before
    with camera(port=port) as second:
        assert second.onvif_port == port
        call(port, nothing)
