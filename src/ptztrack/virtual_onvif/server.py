"""A virtual ONVIF PTZ camera on 127.0.0.1, for testing the live loop without a camera.

:class:`VirtualONVIFCamera` answers ONVIF's device, media and PTZ services (SOAP 1.2 over HTTP,
WS-Security UsernameToken; :mod:`~ptztrack.virtual_onvif.soap`, :mod:`~ptztrack.virtual_onvif.media`,
:mod:`~ptztrack.virtual_onvif.ptz`), serves JPEG snapshots and MJPEG (HTTP Basic or Digest;
:mod:`~ptztrack.virtual_onvif.http`), and streams H.264 over RTSP, RTP over TCP or UDP, when ffmpeg is
on the PATH (:mod:`~ptztrack.virtual_onvif.rtsp`). Its images come from a ``render(pose, elapsed_s)``
callable, rendered at a fixed rate with the pose of that instant. The head moves like a real one
(:mod:`~ptztrack.virtual_onvif.head`): a move starts a latency after its command and each axis travels
towards its target at its speed, so a move takes time and GetStatus reports it MOVING until it
arrives. The pose of every rendered image is kept (:meth:`VirtualONVIFCamera.truth`), to compare with
what a client believes.

The transport is ipycam 1.3.0's HTTP handler (snapshot, MJPEG), MJPEG streamer and ffmpeg-backed RTSP
server; its ``IPCamera`` and its SOAP service are not used. Its defects, and what is done about them
(ipycam file:line):

* ``IPCamera.start`` always starts WS-Discovery, which binds UDP 3702 on every interface, joins
  239.255.255.250 and multicasts (camera.py:125-126, discovery.py:36-49): ``IPCamera`` is not used,
  so nothing is discovered.
* HTTP binds every interface (camera.py:131-133), RTSP 0.0.0.0 (rtsp.py:94, camera.py:211): both bind
  127.0.0.1 here.
* Its SOAP answers fail the ONVIF schemas (GetProfiles' encoder configuration lacks the required
  Multicast, GetVideoEncoderConfiguration's elements are out of order, GetCapabilities' System lacks
  required elements); its envelope declares s, tds, tt and trt only while the PTZ templates use
  ``ptz:`` (static/soap/envelope.xml); GetStatus leaves its MoveStatus and UtcTime placeholders
  unfilled (onvif.py:428-429); operations are routed by substring of the SOAPAction or body
  (onvif.py:176-178, http.py:173-191: GetConfigurationOptions is answered as GetConfigurations);
  faults go out with HTTP 200 and refused tokens with 401 (http.py:161-197); its WS-Security check
  finds the token's fields by regular expression anywhere in the body and lets a nonce be replayed
  (onvif.py:31-112): the SOAP service, its answers and the UsernameToken check are this package's,
  routed by the qualified name of the Body's child.
* Moves are instant and out-of-range positions clipped without a fault (ptz.py:361-380);
  ContinuousMove's Timeout is ignored (onvif.py:432-440); presets go to ./ptz_presets.json
  (ptz.py:469-489): the PTZ service is this package's, in the model's units, presets in memory or in
  the file the camera is given.
* ``IPCameraHTTPHandler.camera`` is a class attribute (camera.py:130): each camera gets its own handler
  class, which also shuts the web UI and REST API (they write ./camera_config.json and take uploads,
  http.py:98-148); its HTTP authentication is Basic only (http.py:34-70): Digest is added.
* A client that goes away mid-answer leaves socketserver's traceback on stderr (the snapshot's
  http.py:396 and the SOAP answer's writes are unguarded): the server logs one debug line instead.
* RTSP over UDP binds ('', 0) (rtsp.py:740) and has ffmpeg send from 0.0.0.0 straight to the client
  (rtsp.py:1081): UDP sessions are relayed like TCP-interleaved ones, through sockets on 127.0.0.1.
* ffmpeg's progress lines go to a pipe read only once it exits (rtsp.py:923-928): at ~200 bytes/s the
  pipe fills in minutes and the encoder stalls; ffmpeg is run with ``-nostats -loglevel error``.
* An RTSP connection silent for 30 s ends its session (rtsp.py:283, 400-403) though SETUP gives a
  60 s session timeout: the connection waits 65 s.
* Closing a session sends SIGTERM to an ffmpeg blocked on its still open input, gives up after 1 s and
  kills it without reaping it (rtsp.py:1197-1208): a zombie. The session's encoder thread, which
  closes the input first and waits (rtsp.py:1017-1025), is let end it before.
* ``NativeRTSPServer.stop`` leaves client connections open and joins no thread: stop() here closes
  them and joins.

RTSP has no authentication (ipycam's server has none); it listens on 127.0.0.1 only.
"""

import logging
import shutil
import threading
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ptztrack.camera.onvif_spaces import AxisSpeeds, CameraSpaces
from ptztrack.virtual_onvif.head import MOVE_LATENCY_S, Head, head_axes
from ptztrack.virtual_onvif.http import SNAPSHOT_PATH, HTTPAuth, HTTPServer, Served, make_server
from ptztrack.virtual_onvif.media import DeviceMediaService, MediaSettings
from ptztrack.virtual_onvif.ptz import PTZService
from ptztrack.virtual_onvif.rtsp import HOST, RTSPServer
from ptztrack.virtual_onvif.soap import TDS, SOAPService, UsernameTokens

log = logging.getLogger("ptztrack.onvif_server")

_STREAM = "video_main"
_BITRATE_KBPS = 1000
# ONVIF Core's PRE_AUTH operations that the camera has: clients read its clock and find its services
# before they sign.
_PRE_AUTH = [
    (TDS, name) for name in ("GetSystemDateAndTime", "GetCapabilities", "GetServices", "GetServiceCapabilities")
]
# What stop() waits for each thread.
_JOIN_S = 5.0


class VirtualONVIFCamera:
    """An ONVIF PTZ camera on 127.0.0.1 whose images come from ``render(pose, elapsed_s) -> (h, w, 3) uint8 BGR``.

    render : the image (h, w, 3) uint8 BGR at pose (3,) (pan_deg, tilt_deg, zoom), ``elapsed_s`` after start().
    spaces : the mapping of the ONVIF normalised spaces to poses; the head's limits are its ends.
    speeds : the axes' full speeds; start_pose : (3,) the pose at start, and the home position.
    image_size_px : (width, height) of the images render() returns.
    port : the ONVIF (HTTP) port, 0 for any free one; username, password : both, or neither for no
        authentication (WS-Security UsernameToken for ONVIF, HTTP Basic or Digest for the snapshot and MJPEG).
    frame_rate_hz : how often an image is rendered; rtsp : stream H.264 over RTSP if ffmpeg is on the PATH.
    f_min_px : the focal length in pixels at zoom 1 of the model that renders the images; with it the
        PTZ node offers RelativeMove in the FOV translation space (:mod:`~ptztrack.virtual_onvif.ptz`).
    move_latency_s : how long after its command a move starts (:mod:`~ptztrack.virtual_onvif.head`).
    positions : GetStatus and GetPresets give positions; absolute_moves : the node has absolute position
        spaces and AbsoluteMove; presets_path : the JSON file that keeps the presets across restarts
        (read now, written on every change), None for presets in memory only
        (:class:`~ptztrack.virtual_onvif.ptz.PTZService`; a file that is not one raises an InputError
        naming it).

    After start(), ``onvif_port`` and ``rtsp_port`` (None without RTSP) are the ports in use.
    """

    def __init__(
        self,
        render: Callable[[np.ndarray, float], np.ndarray],
        spaces: CameraSpaces,
        speeds: AxisSpeeds,
        start_pose,
        image_size_px: tuple[int, int],
        port: int = 0,
        username: str = "",
        password: str = "",
        frame_rate_hz: float = 10.0,
        rtsp: bool = True,
        f_min_px: float | None = None,
        move_latency_s: float = MOVE_LATENCY_S,
        positions: bool = True,
        absolute_moves: bool = True,
        presets_path: Path | None = None,
    ):
        width_px, height_px = (int(size) for size in image_size_px)
        limits, rates_per_s = head_axes(spaces, speeds)
        start_pose = np.asarray(start_pose, dtype=float)
        if width_px <= 0 or height_px <= 0 or not frame_rate_hz > 0 or not np.all(rates_per_s > 0):
            raise ValueError("the image size, the frame rate and the axes' speeds must be positive")
        if f_min_px is not None and not f_min_px > 0:
            raise ValueError(f"f_min_px {f_min_px} must be positive")
        if start_pose.shape != (3,) or not np.all((limits[:, 0] <= start_pose) & (start_pose <= limits[:, 1])):
            raise ValueError(f"start_pose {start_pose} is not a pose within the spaces' limits {limits.tolist()}")
        if bool(username) != bool(password):
            raise ValueError("give both a user name and a password, or neither (no authentication)")
        self._render, self.spaces, self.start_pose = render, spaces, start_pose
        self.image_size_px, self.f_min_px = (width_px, height_px), f_min_px
        self.frame_rate_hz, self.rtsp = frame_rate_hz, rtsp
        self._port, self._credentials = port, (username, password)
        self._head = Head(start_pose, limits, rates_per_s, move_latency_s)
        self._ptz = PTZService(
            self._head, spaces, start_pose, self.image_size_px, f_min_px, positions, absolute_moves, presets_path
        )
        self.onvif_port: int | None = None
        self.rtsp_port: int | None = None
        self._served: Served | None = None
        self._rtsp_server: RTSPServer | None = None
        self._http: HTTPServer | None = None
        self._threads: list[threading.Thread] = []
        self._stopping = threading.Event()
        self._truth_lock = threading.Lock()
        self._elapsed_s: list[float] = []
        self._poses: list[np.ndarray] = []
        self._start_s = 0.0

    def start(self) -> None:
        """Bind the ports, render the first image and start serving; a camera starts once."""
        if self._stopping.is_set() or self._served is not None:
            raise RuntimeError("a VirtualONVIFCamera starts once")
        username, password = self._credentials
        name = "ptztrack virtual PTZ"
        self._served = served = Served(HTTPAuth(username, password, realm=name) if username else None)
        try:
            self._http = make_server(HOST, self._port, served)
            self.onvif_port = port = self._http.server_address[1]
            stream_uri = self._start_rtsp()
            settings = MediaSettings(
                name=name,
                service_uri=f"http://{HOST}:{port}/onvif/device_service",
                width_px=self.image_size_px[0],
                height_px=self.image_size_px[1],
                # ffmpeg takes the exact rate; the profile's FrameRateLimit is a whole number.
                frame_rate_hz=max(1, round(self.frame_rate_hz)),
                bitrate_kbps=_BITRATE_KBPS,
                snapshot_uri=f"http://{HOST}:{port}{SNAPSHOT_PATH}",
                stream_uri=stream_uri,
            )
            tokens = UsernameTokens(username, password) if username else None
            operations = DeviceMediaService(settings, self._ptz).operations() | self._ptz.operations()
            served.soap = SOAPService(operations, tokens, _PRE_AUTH)
            served.mjpeg_streamer.start()
            self._start_s = time.monotonic()
            self._render_one()  # the first image before any request, and a failing render() fails here
            for target, thread_name in (
                (self._http.serve_forever, "onvif-http"),
                (self._render_frames, "onvif-frames"),
            ):
                thread = threading.Thread(target=target, name=thread_name, daemon=True)
                thread.start()
                self._threads.append(thread)  # only once started: stop() waits for serve_forever() to end
        except BaseException:
            self.stop()
            raise
        log.info("virtual ONVIF camera on %s: ONVIF port %d, RTSP port %s", HOST, port, self.rtsp_port)

    def _start_rtsp(self) -> str | None:
        """Start the RTSP server if asked for and ffmpeg is there; its stream's URI, or None."""
        if not self.rtsp:
            return None
        if not shutil.which("ffmpeg"):
            log.info("ffmpeg is not on the PATH: no RTSP stream")
            return None
        self._rtsp_server = rtsp_server = RTSPServer()
        width_px, height_px = self.image_size_px
        rtsp_server.add_stream(_STREAM, width_px, height_px, self.frame_rate_hz, f"{_BITRATE_KBPS}k")
        if not rtsp_server.start():
            raise OSError(f"the RTSP server could not listen on {HOST}")
        self.rtsp_port = rtsp_server.port
        return f"rtsp://{HOST}:{rtsp_server.port}/{_STREAM}"

    def stop(self) -> None:
        """Stop rendering, close every connection and port, end ffmpeg, join the threads; idempotent."""
        self._stopping.set()
        http, served, rtsp_server = self._http, self._served, self._rtsp_server
        self._http = self._served = self._rtsp_server = None
        if http is not None and self._threads:
            http.shutdown()  # ends serve_forever()
        for thread in self._threads:
            thread.join(_JOIN_S)
        self._threads = []
        if served is not None:
            served.mjpeg_streamer.stop()  # ends the MJPEG clients' request threads, joined below
        if rtsp_server is not None:
            rtsp_server.stop()
        if http is not None:
            http.server_close()  # closes the port and joins the request threads
            log.info("virtual ONVIF camera on %s:%d stopped", HOST, self.onvif_port)

    def __enter__(self) -> "VirtualONVIFCamera":
        self.start()
        return self

    def __exit__(self, *exc_info) -> None:
        self.stop()

    def truth(self) -> tuple[np.ndarray, np.ndarray]:
        """(T,) seconds after start() and (T, 3) true poses (pan_deg, tilt_deg, zoom) of every image rendered."""
        with self._truth_lock:
            return np.array(self._elapsed_s), np.array(self._poses).reshape(-1, 3)

    def _render_one(self) -> None:
        t_s, pose, _ = self._head.now()
        elapsed_s = t_s - self._start_s
        frame = np.array(self._render(pose.copy(), elapsed_s), copy=True)
        width_px, height_px = self.image_size_px
        if frame.shape != (height_px, width_px, 3) or frame.dtype != np.uint8:
            raise ValueError(
                f"render() gave a {frame.dtype} {frame.shape} image, not uint8 ({height_px}, {width_px}, 3)"
            )
        frame.flags.writeable = False
        with self._truth_lock:
            self._elapsed_s.append(elapsed_s)
            self._poses.append(pose)
        served, rtsp_server = self._served, self._rtsp_server
        if served is not None:
            served.publish(frame)
        if rtsp_server is not None:
            rtsp_server.stream_frame(_STREAM, frame)

    def _render_frames(self) -> None:
        period_s = 1.0 / self.frame_rate_hz
        next_s = time.monotonic() + period_s
        while not self._stopping.wait(max(0.0, next_s - time.monotonic())):
            try:
                self._render_one()
            except Exception:
                log.exception("render() failed: the camera serves its last image from now on")
                return
            # A late image delays the next one rather than bunching the following ones.
            next_s = max(next_s + period_s, time.monotonic())
