"""The virtual ONVIF camera with the clients that use it beyond its answers: RelativeMove in the FOV
translation space (onvif-zeep-async), RTSP over UDP and TCP (OpenCV's ffmpeg), clients that go away
mid-answer, and a session of an ONVIF client that ptztrack does not use (onveef)."""

import asyncio
import base64
import logging
import os
import re
import socket
import struct
import subprocess
import sys
import threading
import time

import cv2
import numpy as np
import pytest

from onvif_camera import (
    ERRORS,
    F_MIN_PX,
    FAST,
    HEIGHT_PX,
    HOST,
    PASSWORD,
    SPACES,
    START_POSE,
    USER,
    WIDTH_PX,
    call,
    camera,
    render,
)

onveef = pytest.importorskip("onveef", reason="the outside ONVIF client is onveef (pip install '.[test]')")

import zeep.exceptions  # noqa: E402  (onvif-zeep-async's SOAP library)

from ptztrack.geometry.ptz import rotation_world_to_camera  # noqa: E402
from ptztrack.virtual_onvif.ptz import PAN_TILT_FOV  # noqa: E402
from ptztrack.virtual_onvif.server import VirtualONVIFCamera  # noqa: E402

pytestmark = pytest.mark.onvif


@pytest.mark.slow
def test_a_fov_relative_move_centres_the_point_seen_there_within_the_limits():
    """The node offers TranslationSpaceFov; RelativeMove by FOV (x, y) brings the scene point seen at pixel
    (W/2 + x W/2, H/2 - y H/2) to the image centre, exactly on the model, at zoom 1 and zoomed in (a
    corner, then); at the pan limit the head stops there. Without a focal length the space is neither
    offered nor taken."""
    cx, cy = WIDTH_PX / 2.0, HEIGHT_PX / 2.0

    async def moves(client, token: str):
        ptz, profile = await client.create_ptz_service(), {"ProfileToken": token}
        nodes = await ptz.GetNodes()
        options = await ptz.GetConfigurationOptions({"ConfigurationToken": "PTZ_Config_1"})
        offered = [
            [space.URI for space in spaces.RelativePanTiltTranslationSpace]
            for spaces in (nodes[0].SupportedPTZSpaces, options.Spaces)
        ]

        async def idle_pose():
            while (
                status := await ptz.GetStatus(profile)
            ).MoveStatus.PanTilt != "IDLE" or status.MoveStatus.Zoom != "IDLE":
                await asyncio.sleep(0.02)
            await asyncio.sleep(0.25)  # an image rendered at the pose reached
            return cam.truth()[1][-1]

        seen = []
        for start, fov in (
            ((0.0, -1 / 3, 0.0), (0.5, -0.4)),
            ((0.1, 0.2, 0.5), (1.0, 1.0)),
            ((0.97, 0.0, 0.0), (1.0, 0.0)),
        ):
            position = {"PanTilt": {"x": start[0], "y": start[1]}, "Zoom": {"x": start[2]}}
            await ptz.AbsoluteMove({**profile, "Position": position})
            before = await idle_pose()
            translation = {"PanTilt": {"x": fov[0], "y": fov[1], "space": PAN_TILT_FOV}}
            await ptz.RelativeMove({**profile, "Translation": translation})
            seen.append((fov, before, await idle_pose()))
        return offered, seen

    with camera() as cam:
        offered, seen = call(cam.onvif_port, moves)
    assert offered == [[PAN_TILT_FOV.replace("TranslationSpaceFov", "TranslationGenericSpace"), PAN_TILT_FOV]] * 2
    for fov, before, after in seen[:2]:
        pixel = np.array([cx + fov[0] * cx, cy - fov[1] * cy])
        ray = np.array([(pixel[0] - cx) / (before[2] * F_MIN_PX), (pixel[1] - cy) / (before[2] * F_MIN_PX), 1.0])
        seen_after = (
            rotation_world_to_camera(after[0], after[1]) @ rotation_world_to_camera(before[0], before[1]).T @ ray
        )
        centred = after[2] * F_MIN_PX * seen_after[:2] / seen_after[2] + [cx, cy]
        assert np.allclose(centred, [cx, cy], atol=1e-6), (fov, before, after, centred)
        assert after[2] == before[2] and not np.allclose(after[:2], before[:2])
    # Zoomed in 4.5 times, the corner is 4.5 times nearer the centre than at zoom 1: a smaller turn.
    assert seen[1][1][2] == pytest.approx(4.5)
    assert abs(seen[1][2][0] - seen[1][1][0]) < 2 * np.degrees(np.arctan(cx / (4.5 * F_MIN_PX)))
    # At the pan limit: the pan stops there, the tilt is the one that centres the point's ray (depression).
    fov, before, after = seen[2]
    ray = rotation_world_to_camera(before[0], before[1]).T @ [fov[0] * cx / F_MIN_PX, 0.0, 1.0]
    assert before[0] < 170.0 and after[0] == 170.0
    assert after[1] == pytest.approx(np.degrees(np.arcsin(-ray[2] / np.linalg.norm(ray))), abs=1e-9)

    async def refused(client, token: str):
        ptz = await client.create_ptz_service()
        options = await ptz.GetConfigurationOptions({"ConfigurationToken": "PTZ_Config_1"})
        translation = {"PanTilt": {"x": 0.5, "y": 0.0, "space": PAN_TILT_FOV}}
        with pytest.raises(zeep.exceptions.Fault) as fault:
            await ptz.RelativeMove({"ProfileToken": token, "Translation": translation})
        return [space.URI for space in options.Spaces.RelativePanTiltTranslationSpace], fault.value

    with camera(f_min_px=None) as cam:
        spaces, fault = call(cam.onvif_port, refused)
    assert PAN_TILT_FOV not in spaces
    assert [subcode.text for subcode in fault.subcodes][-1] == f"{{{ERRORS}}}SpaceNotSupported"
    assert "Translation.PanTilt space" in fault.message


READER = """
import sys, cv2
timeouts = [cv2.CAP_PROP_OPEN_TIMEOUT_MSEC, 8000, cv2.CAP_PROP_READ_TIMEOUT_MSEC, 8000]
capture = cv2.VideoCapture(sys.argv[1], cv2.CAP_FFMPEG, timeouts)
read, frame = capture.read()
capture.release()
sys.exit(0 if read and cv2.imwrite(sys.argv[2], frame) else 1)
"""


@pytest.mark.slow
def test_rtsp_streams_over_udp_and_tcp_to_opencv(tmp_path, caplog):
    """OpenCV's ffmpeg reads the stream with rtsp_transport udp (an RTP/AVP session, relayed from
    sockets on 127.0.0.1) and with tcp (interleaved); both frames are the rendered image."""
    caplog.set_level(logging.DEBUG, logger="ptztrack.onvif_server")

    async def stream_uri(client, token: str) -> str:
        media = await client.create_media_service()
        setup = {"Stream": "RTP-Unicast", "Transport": {"Protocol": "UDP"}}
        return (await media.GetStreamUri({"StreamSetup": setup, "ProfileToken": token})).Uri

    with camera() as cam:
        assert cam.rtsp_port is not None, "ffmpeg is not on the PATH: the camera has no RTSP stream"
        uri = call(cam.onvif_port, stream_uri)
        for transport in ("udp", "tcp"):
            environment = {**os.environ, "OPENCV_FFMPEG_CAPTURE_OPTIONS": f"rtsp_transport;{transport}"}
            path = tmp_path / f"{transport}.png"
            reader = subprocess.run([sys.executable, "-c", READER, uri, str(path)], env=environment, timeout=60)
            assert reader.returncode == 0, f"no frame over {transport}"
            frame = cv2.imread(str(path))
            assert frame.shape == (HEIGHT_PX, WIDTH_PX, 3)
            assert np.abs(frame.astype(float) - render(np.array(START_POSE), 0.0)).mean() < 10.0, transport
    udp_sessions = [record.getMessage() for record in caplog.records if "RTP over UDP" in record.getMessage()]
    assert len(udp_sessions) == 1 and f"from {HOST}:" in udp_sessions[0], udp_sessions


def noise(pose, elapsed_s: float) -> np.ndarray:
    """A 2880 x 2160 image of noise: its JPEG, about 5 MB, outlasts a socket's send buffer (Linux's
    default limit is 4 MB), so that the snapshot is still being written when its client resets."""
    return np.random.default_rng(int(elapsed_s * 1000)).integers(0, 256, (2160, 2880, 3), dtype=np.uint8)


def reset(connection: socket.socket) -> None:
    """Close with a TCP reset, as a client that dies does."""
    connection.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
    connection.close()


def rtsp_request(connection: socket.socket, request: str) -> str:
    connection.sendall(request.encode())
    answer = b""
    while b"\r\n\r\n" not in answer:
        answer += connection.recv(4096)
    return answer.decode(errors="replace")


@pytest.mark.slow
def test_clients_that_go_away_mid_answer_leave_no_traceback_and_no_warning(caplog, capfd, monkeypatch):
    """Clients reset their connections in the middle of a snapshot, an MJPEG stream, a SOAP request and
    an RTSP stream (TCP-interleaved), and one leaves a UDP session to a closed port: nothing is logged
    at WARNING or above, no thread dies of an exception, nothing reaches stderr, and the server noted
    the two clients it was reading from or writing to going away (at debug level)."""
    caplog.set_level(logging.DEBUG)
    thread_errors = []
    monkeypatch.setattr(threading, "excepthook", thread_errors.append)
    basic = "Basic " + base64.b64encode(f"{USER}:{PASSWORD}".encode()).decode()
    big = VirtualONVIFCamera(
        noise, SPACES, FAST, START_POSE, (2880, 2160), username=USER, password=PASSWORD, frame_rate_hz=2.0, rtsp=False
    )
    with big, camera() as cam:
        for path in ("/snapshot.jpg", "/stream.mjpeg"):
            client = socket.socket()
            client.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)  # before connect: a small window
            client.connect((HOST, big.onvif_port))
            client.sendall(f"GET {path} HTTP/1.1\r\nHost: {HOST}\r\nAuthorization: {basic}\r\n\r\n".encode())
            assert client.recv(1024).startswith(b"HTTP/1.0 200")
            time.sleep(0.3)  # the server is writing
            reset(client)
        with socket.create_connection((HOST, cam.onvif_port)) as client:
            client.sendall(b"POST /onvif/device_service HTTP/1.1\r\nContent-Length: 5000\r\n\r\n<s:Envelope")
            time.sleep(0.2)  # the server is reading the body
            reset(client)
        rtsp = socket.create_connection((HOST, cam.rtsp_port), timeout=5)
        base = f"rtsp://{HOST}:{cam.rtsp_port}/video_main"
        setup = rtsp_request(
            rtsp,
            f"SETUP {base}/trackID=0 RTSP/1.0\r\nCSeq: 1\r\nTransport: RTP/AVP/TCP;unicast;interleaved=0-1\r\n\r\n",
        )
        session = re.search(r"Session: (\w+)", setup).group(1)
        rtsp_request(rtsp, f"PLAY {base} RTSP/1.0\r\nCSeq: 2\r\nSession: {session}\r\n\r\n")
        received = b""
        while b"$\x00" not in received:  # an interleaved RTP packet
            received += rtsp.recv(4096)
        reset(rtsp)
        closed = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        closed.bind((HOST, 0))
        port = closed.getsockname()[1]
        closed.close()
        with socket.create_connection((HOST, cam.rtsp_port), timeout=5) as rtsp:
            transport = f"RTP/AVP;unicast;client_port={port}-{port + 1}"
            setup = rtsp_request(rtsp, f"SETUP {base}/trackID=0 RTSP/1.0\r\nCSeq: 1\r\nTransport: {transport}\r\n\r\n")
            session = re.search(r"Session: (\w+)", setup).group(1)
            rtsp_request(rtsp, f"PLAY {base} RTSP/1.0\r\nCSeq: 2\r\nSession: {session}\r\n\r\n")
            time.sleep(1.0)  # ffmpeg starts and RTP goes to the closed port
        time.sleep(0.3)
    loud = [f"{record.name}: {record.getMessage()}" for record in caplog.records if record.levelno >= logging.WARNING]
    assert not loud and not thread_errors, (loud, thread_errors)
    assert "Traceback" not in capfd.readouterr().err
    # The snapshot's write and the SOAP request's read met the reset (MJPEG and RTSP are ipycam's to end).
    assert sum("went away" in record.getMessage() for record in caplog.records) == 2


def test_an_onvif_client_ptztrack_does_not_use_runs_a_session_with_a_fov_move_and_a_digest_snapshot():
    """onveef (its own SOAP and XML, httpx for HTTP) connects, reads the capabilities, profiles, video
    sources, stream URI and status, moves in the FOV space, sees the head arrive, and gets a snapshot
    (HTTP Digest)."""
    with camera() as cam, onveef.OnvifClient(HOST, cam.onvif_port, USER, PASSWORD, timeout_s=5.0) as client:
        services = client.get_capabilities()
        profile = client.get_profiles()[0]
        sources = client.get_video_sources()
        uri = client.get_stream_uri(profile_token=profile["token"])
        before = client.ptz_get_status(profile_token=profile["token"])
        move = (
            f"<tptz:RelativeMove><tptz:ProfileToken>{profile['token']}</tptz:ProfileToken><tptz:Translation>"
            f'<tt:PanTilt x="0.5" y="0" space="{PAN_TILT_FOV}"/></tptz:Translation></tptz:RelativeMove>'
        )
        client.call(service="ptz", operation="RelativeMove", body_inner=move)
        moving = client.ptz_get_status(profile_token=profile["token"])
        deadline = time.monotonic() + 60.0  # the head arrives within a second; this only stops a hang
        while (after := client.ptz_get_status(profile_token=profile["token"]))["move_status"]["pan_tilt"] != "IDLE":
            assert time.monotonic() < deadline, "the head never arrived"
            time.sleep(0.02)
        jpeg, content_type = client.get_snapshot(profile_token=profile["token"])
    assert set(services) >= {"device", "media", "ptz"}
    assert profile["video_encoder"]["width"] == WIDTH_PX and profile["ptz"]["token"] == "PTZ_Config_1"
    assert sources == [{"token": "VS_1", "framerate": 10.0, "width": WIDTH_PX, "height": HEIGHT_PX}]
    assert uri == f"rtsp://{HOST}:{cam.rtsp_port}/video_main"
    assert before["move_status"]["pan_tilt"] == "IDLE" and moving["move_status"]["pan_tilt"] == "MOVING"
    # x = 0.5 is 80 px right of the centre at zoom 1, a ray a = 80 / 300 to the right of the optical axis;
    # looking down 20 degrees, centring it turns the pan by atan(a / cos 20 deg) = 15.84 degrees (of 340).
    turn = (after["pan"] - before["pan"]) * 170.0
    offset = 0.5 * WIDTH_PX / 2.0 / F_MIN_PX
    assert turn == pytest.approx(np.degrees(np.arctan(offset / np.cos(np.radians(START_POSE[1])))), abs=1e-9)
    assert content_type == "image/jpeg" and cv2.imdecode(np.frombuffer(jpeg, np.uint8), 1).shape == (240, 320, 3)
