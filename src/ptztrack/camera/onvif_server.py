"""A virtual ONVIF PTZ camera on 127.0.0.1, for testing the live loop without a camera.

:class:`VirtualONVIFCamera` answers ONVIF (device, media and PTZ services,
SOAP over HTTP), serves JPEG snapshots and MJPEG (HTTP Basic), and streams
H.264 over RTSP (when ffmpeg is on the PATH). Its images come from a
``render(pose, elapsed_s)`` callable, rendered at a fixed rate with the pose
of that instant. The head moves like a real one: each axis travels towards
its target at its speed, so a move takes time and GetStatus reports it
MOVING until it arrives. The pose of every rendered image is kept
(:meth:`VirtualONVIFCamera.truth`), to compare with what a client believes.

The transport is ipycam 1.3.0 (SOAP templates, WS-Security UsernameToken,
HTTP Basic, MJPEG, the ffmpeg-backed RTSP server); its ``IPCamera`` is not
used. Its defects, and what this module does about them (ipycam file:line):

* ``IPCamera.start`` always starts WS-Discovery, which binds UDP 3702 on every
  interface, joins 239.255.255.250 and multicasts (camera.py:125-126,
  discovery.py:36-49): ``IPCamera`` is not used, so nothing is discovered.
* HTTP binds every interface (camera.py:131-133), RTSP 0.0.0.0
  (rtsp.py:94, camera.py:211): both bind 127.0.0.1 here.
* URIs are built from ``config.local_ip``, else found by a UDP connect towards
  10.255.255.255 (config.py:21-31, 189-190): it is set to 127.0.0.1.
* The envelope declares s, tds, tt and trt only (static/soap/envelope.xml) while
  the PTZ templates use ``ptz:`` (GetStatus, GetConfigurations, GetPresets,
  SetPreset fail in zeep): the envelope declares every prefix, and the PTZ
  answers are written here.
* GetStatus leaves its MoveStatus and UtcTime placeholders unfilled
  (onvif.py:428-429, static/soap/ptz_get_status.xml:8-11); moves are instant
  and out-of-range positions clipped without a fault (ptz.py:361-380);
  ContinuousMove's Timeout is ignored (onvif.py:432-440); presets go to
  ./ptz_presets.json (ptz.py:469-489): the PTZ service is this module's, in
  the model's units, presets in memory.
* Operations are routed by substring of the SOAPAction or body
  (onvif.py:176-178, http.py:173-191), so GetConfigurationOptions is answered
  as GetConfigurations and the device's GetServiceCapabilities as the PTZ's;
  GetStreamUri picks the sub stream if "Sub" occurs anywhere in the body
  (onvif.py:264), WS-Security nonce included: routing is by the qualified name
  of the Body's child.
* ``IPCameraHTTPHandler.camera`` is a class attribute (camera.py:130): each
  camera gets its own handler class, which also shuts the web UI and REST API
  (they write ./camera_config.json and take uploads, http.py:98-148).
* RTSP over UDP binds ('', 0) (rtsp.py:740) and sends from ffmpeg bound to
  0.0.0.0 (rtsp.py:1095): UDP transport is refused (461), ffmpeg's RTP socket
  binds 127.0.0.1 (``localaddr``).
* ffmpeg's progress lines go to a pipe read only once it exits (rtsp.py:923-928):
  at ~200 bytes/s the pipe fills in minutes and the encoder stalls; ffmpeg is
  run with ``-nostats -loglevel error``.
* Closing a session sends SIGTERM to an ffmpeg blocked on its still open input,
  gives up after 1 s and kills it without reaping it (rtsp.py:1197-1208): a
  zombie. The session's encoder thread, which closes the input first and waits
  (rtsp.py:1017-1025), is let end it before.
* ``NativeRTSPServer.stop`` leaves client connections open (30 s recv timeout,
  rtsp.py:283) and joins no thread: stop() here closes them and joins.

RTSP has no authentication (ipycam's server has none); it listens on
127.0.0.1 only.
"""

import contextlib
import logging
import re
import shutil
import socket
import socketserver
import threading
import time
import xml.etree.ElementTree as ElementTree
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from xml.sax.saxutils import escape, quoteattr

import numpy as np
from ipycam import (
    CameraConfig,
    IPCameraHTTPHandler,
    MJPEGStreamer,
    NativeRTSPServer,
    ONVIFService,
)
from ipycam.rtsp import RTSPState

from ptztrack.camera.onvif_spaces import AxisSpeeds, CameraSpaces

log = logging.getLogger("ptztrack.onvif_server")

HOST = "127.0.0.1"

_NAMESPACES = {
    "s": "http://www.w3.org/2003/05/soap-envelope",
    "tds": "http://www.onvif.org/ver10/device/wsdl",
    "trt": "http://www.onvif.org/ver10/media/wsdl",
    "tptz": "http://www.onvif.org/ver20/ptz/wsdl",
    "tt": "http://www.onvif.org/ver10/schema",
    "ter": "http://www.onvif.org/ver10/error",
}
_TDS, _TRT, _TPTZ = _NAMESPACES["tds"], _NAMESPACES["trt"], _NAMESPACES["tptz"]

_SPACES = "http://www.onvif.org/ver10/tptz/"
_PAN_TILT_POSITION = _SPACES + "PanTiltSpaces/PositionGenericSpace"
_ZOOM_POSITION = _SPACES + "ZoomSpaces/PositionGenericSpace"
_PAN_TILT_TRANSLATION = _SPACES + "PanTiltSpaces/TranslationGenericSpace"
_ZOOM_TRANSLATION = _SPACES + "ZoomSpaces/TranslationGenericSpace"
_PAN_TILT_VELOCITY = _SPACES + "PanTiltSpaces/VelocityGenericSpace"
_ZOOM_VELOCITY = _SPACES + "ZoomSpaces/VelocityGenericSpace"
_PAN_TILT_SPEED = _SPACES + "PanTiltSpaces/GenericSpeedSpace"
_ZOOM_SPEED = _SPACES + "ZoomSpaces/ZoomGenericSpeedSpace"

_PROFILE, _CONFIGURATION, _NODE = "Profile_Main", "PTZ_Config_1", "PTZ_Node_1"
_STREAM = "video_main"
_MAX_PRESETS = 32
# ContinuousMove without a Timeout runs for the configuration's DefaultPTZTimeout; longer ones are refused.
_DEFAULT_TIMEOUT_S, _MAX_TIMEOUT_S = 10.0, 60.0
# What stop() waits for each thread: the longest is an ffmpeg encoder's exit (rtsp.py:1025 waits 2 s).
_JOIN_S = 5.0
# xs:duration from days to seconds (years and months have no fixed length): P1D, PT10S, PT0.5S, PT1M30S.
_DURATION = re.compile(r"P(?=\d|T\d)(?:(\d+)D)?(?:T(?=\d)(?:(\d+)H)?(?:(\d+)M)?(?:(\d+(?:\.\d+)?)S)?)?")


@dataclass(frozen=True)
class _Ramp:
    """One axis's motion: from ``start`` at ``start_s`` linearly to ``end`` at ``end_s`` (monotonic
    seconds), still before and after."""

    start_s: float
    start: float
    end_s: float
    end: float

    def at(self, t_s: float) -> float:
        if t_s >= self.end_s:
            return self.end
        return self.start + (self.end - self.start) * max(t_s - self.start_s, 0.0) / (self.end_s - self.start_s)

    def moving(self, t_s: float) -> bool:
        return t_s < self.end_s


def _ramp(t_s: float, here: float, there: float, rate_per_s: float) -> _Ramp:
    return _Ramp(t_s, here, t_s + abs(there - here) / rate_per_s, there)


class _Head:
    """The PTZ head in the model's units, axes (pan_deg, tilt_deg, zoom), each on its own ramp.

    limits : (3, 2) lowest and highest value of each axis; rates_per_s : (3,) each axis's full speed.
    """

    def __init__(self, pose: np.ndarray, limits: np.ndarray, rates_per_s: np.ndarray):
        self.limits, self.rates_per_s = limits, rates_per_s
        self._lock = threading.Lock()
        now_s = time.monotonic()
        self._ramps = [_Ramp(now_s, float(value), now_s, float(value)) for value in pose]

    def now(self) -> tuple[float, np.ndarray, list[bool]]:
        """The monotonic time, the pose (3,) then and whether each axis is moving."""
        with self._lock:
            t_s = time.monotonic()
            return t_s, np.array([ramp.at(t_s) for ramp in self._ramps]), [ramp.moving(t_s) for ramp in self._ramps]

    def move_to(self, target: Sequence[float | None], speed: Sequence[float]) -> None:
        """Each axis with a target (None: left as it is) travels to it at ``speed`` (fraction of full speed)."""
        with self._lock:
            t_s = time.monotonic()
            for axis, there in enumerate(target):
                if there is not None:
                    here = self._ramps[axis].at(t_s)
                    self._ramps[axis] = _ramp(t_s, here, there, self.rates_per_s[axis] * speed[axis])

    def run(self, velocity: Sequence[float | None], duration_s: float) -> None:
        """Each axis with a velocity (fraction of full speed, signed; None: left as it is) runs for
        ``duration_s``, or until it reaches its limit."""
        with self._lock:
            t_s = time.monotonic()
            for axis, fraction in enumerate(velocity):
                if fraction is None:
                    continue
                here = self._ramps[axis].at(t_s)
                if fraction == 0:
                    self._ramps[axis] = _Ramp(t_s, here, t_s, here)
                else:
                    there = float(np.clip(here + fraction * self.rates_per_s[axis] * duration_s, *self.limits[axis]))
                    self._ramps[axis] = _ramp(t_s, here, there, abs(fraction) * self.rates_per_s[axis])

    def stop(self, axes: Sequence[bool]) -> None:
        with self._lock:
            t_s = time.monotonic()
            for axis, stopping in enumerate(axes):
                if stopping:
                    here = self._ramps[axis].at(t_s)
                    self._ramps[axis] = _Ramp(t_s, here, t_s, here)


class _Fault(Exception):
    """A SOAP fault: code (Sender or Receiver), ONVIF subcodes (``ter:...``), reason."""

    def __init__(self, code: str, subcodes: Sequence[str], reason: str):
        super().__init__(reason)
        self.code, self.subcodes, self.reason = code, subcodes, reason


def _invalid(subcode: str, reason: str) -> _Fault:
    return _Fault("Sender", ["ter:InvalidArgVal", f"ter:{subcode}"], reason)


def _qualified_name(tag: str) -> tuple[str, str]:
    """(namespace, local name) of an ElementTree tag ``{namespace}name``."""
    namespace, _, name = tag.rpartition("}")
    return namespace.lstrip("{"), name


def _operation(body: str) -> ElementTree.Element | None:
    """The SOAP Body's child (the operation), or None if the request is not a SOAP envelope."""
    # SOAP 1.2 forbids a DTD in a message; refusing one also refuses entity tricks, whatever the parser.
    if "<!DOCTYPE" in body:
        return None
    try:
        envelope = ElementTree.fromstring(body)
    except ElementTree.ParseError:
        return None
    body_element = envelope.find("s:Body", _NAMESPACES)
    return None if body_element is None or len(body_element) == 0 else body_element[0]


def _range_xml(tag: str, uri: str, x: tuple[float, float], y: tuple[float, float] | None = None) -> str:
    def limits(axis: str, low_high: tuple[float, float]) -> str:
        return f"<tt:{axis}Range><tt:Min>{low_high[0]}</tt:Min><tt:Max>{low_high[1]}</tt:Max></tt:{axis}Range>"

    return f"<tt:{tag}><tt:URI>{uri}</tt:URI>{limits('X', x)}{limits('Y', y) if y else ''}</tt:{tag}>"


def _spaces_xml() -> str:
    """The generic spaces, the only ones supported: positions pan/tilt [-1, 1], zoom [0, 1]; translations
    and velocities [-1, 1]; speeds [0, 1]."""
    both, zero_one = (-1.0, 1.0), (0.0, 1.0)
    return (
        _range_xml("AbsolutePanTiltPositionSpace", _PAN_TILT_POSITION, both, both)
        + _range_xml("AbsoluteZoomPositionSpace", _ZOOM_POSITION, zero_one)
        + _range_xml("RelativePanTiltTranslationSpace", _PAN_TILT_TRANSLATION, both, both)
        + _range_xml("RelativeZoomTranslationSpace", _ZOOM_TRANSLATION, both)
        + _range_xml("ContinuousPanTiltVelocitySpace", _PAN_TILT_VELOCITY, both, both)
        + _range_xml("ContinuousZoomVelocitySpace", _ZOOM_VELOCITY, both)
        + _range_xml("PanTiltSpeedSpace", _PAN_TILT_SPEED, zero_one)
        + _range_xml("ZoomSpeedSpace", _ZOOM_SPEED, zero_one)
    )


def _configuration_xml(tag: str) -> str:
    # "PantTilt" is the ONVIF schema's own spelling.
    return (
        f'<{tag} token="{_CONFIGURATION}"><tt:Name>PTZ</tt:Name><tt:UseCount>1</tt:UseCount>'
        f"<tt:NodeToken>{_NODE}</tt:NodeToken>"
        f"<tt:DefaultAbsolutePantTiltPositionSpace>{_PAN_TILT_POSITION}</tt:DefaultAbsolutePantTiltPositionSpace>"
        f"<tt:DefaultAbsoluteZoomPositionSpace>{_ZOOM_POSITION}</tt:DefaultAbsoluteZoomPositionSpace>"
        f"<tt:DefaultRelativePanTiltTranslationSpace>{_PAN_TILT_TRANSLATION}</tt:DefaultRelativePanTiltTranslationSpace>"
        f"<tt:DefaultRelativeZoomTranslationSpace>{_ZOOM_TRANSLATION}</tt:DefaultRelativeZoomTranslationSpace>"
        f"<tt:DefaultContinuousPanTiltVelocitySpace>{_PAN_TILT_VELOCITY}</tt:DefaultContinuousPanTiltVelocitySpace>"
        f"<tt:DefaultContinuousZoomVelocitySpace>{_ZOOM_VELOCITY}</tt:DefaultContinuousZoomVelocitySpace>"
        f'<tt:DefaultPTZSpeed><tt:PanTilt x="1.0" y="1.0" space="{_PAN_TILT_SPEED}"/>'
        f'<tt:Zoom x="1.0" space="{_ZOOM_SPEED}"/></tt:DefaultPTZSpeed>'
        f"<tt:DefaultPTZTimeout>PT{_DEFAULT_TIMEOUT_S:g}S</tt:DefaultPTZTimeout>"
        f"<tt:PanTiltLimits>{_range_xml('Range', _PAN_TILT_POSITION, (-1.0, 1.0), (-1.0, 1.0))}</tt:PanTiltLimits>"
        f"<tt:ZoomLimits>{_range_xml('Range', _ZOOM_POSITION, (0.0, 1.0))}</tt:ZoomLimits></{tag}>"
    )


def _position_xml(tag: str, position: np.ndarray) -> str:
    x, y, zoom = (repr(float(value)) for value in position)
    return (
        f'<{tag}><tt:PanTilt x="{x}" y="{y}" space="{_PAN_TILT_POSITION}"/>'
        f'<tt:Zoom x="{zoom}" space="{_ZOOM_POSITION}"/></{tag}>'
    )


class _ONVIFService(ONVIFService):
    """ipycam's device and media answers, and a PTZ service over a :class:`_Head`.

    Positions, translations and velocities are in the generic spaces. A translation is added to the
    normalised position and clipped (a translation of 1 is half the pan range), a velocity is a
    fraction of the axis's full speed, a Speed (0, 1] scales the full speed (default 1).
    """

    def __init__(self, config, head: _Head, spaces: CameraSpaces, home_pose: np.ndarray):
        super().__init__(config)
        self.head, self.spaces, self.home_pose = head, spaces, home_pose
        self.stream_uri: str | None = None
        self._presets: dict[str, tuple[str, np.ndarray]] = {}  # token -> (name, pose (3,))
        self._presets_lock = threading.Lock()
        self._next_preset = 1

    def _wrap_envelope(self, body: str) -> str:
        declarations = " ".join(f'xmlns:{prefix}="{uri}"' for prefix, uri in _NAMESPACES.items())
        return (
            f'<?xml version="1.0" encoding="UTF-8"?>\n<s:Envelope {declarations}><s:Body>{body}</s:Body></s:Envelope>'
        )

    def _fault(self, fault: _Fault) -> str:
        code = "".join(f"<s:Subcode><s:Value>{subcode}</s:Value>" for subcode in fault.subcodes)
        code += "</s:Subcode>" * len(fault.subcodes)
        return self._wrap_envelope(
            f"<s:Fault><s:Code><s:Value>s:{fault.code}</s:Value>{code}</s:Code>"
            f'<s:Reason><s:Text xml:lang="en">{escape(fault.reason)}</s:Text></s:Reason></s:Fault>'
        )

    def fault(self, reason: str) -> str:
        """ipycam calls this only when it refuses a request's UsernameToken (http.py:161-164)."""
        return self._fault(_Fault("Sender", ["ter:NotAuthorized"], reason))

    def verify_usernametoken(self, soap_body: str) -> bool:
        operation = _operation(soap_body)
        # GetSystemDateAndTime is ONVIF's PRE_AUTH: clients read the camera's clock before they sign.
        if operation is not None and operation.tag == f"{{{_TDS}}}GetSystemDateAndTime":
            return True
        if super().verify_usernametoken(soap_body):
            return True
        name = "a request that is not SOAP" if operation is None else _qualified_name(operation.tag)[1]
        log.warning("refused %s: no valid WS-Security UsernameToken", name)
        return False

    def handle_action(self, action: str, body: str) -> str:
        """The answer to a request, routed by the qualified name of the Body's child (not by ``action``)."""
        stock: dict[tuple[str, str], Callable[[], str]] = {
            (_TDS, "GetSystemDateAndTime"): self.get_system_date_time,
            (_TDS, "GetDeviceInformation"): self.get_device_information,
            (_TDS, "GetCapabilities"): self.get_capabilities,
            (_TDS, "GetServices"): self.get_services,
            (_TDS, "GetScopes"): self.get_scopes,
            (_TRT, "GetVideoSourceConfiguration"): self.get_video_source_configuration,
            (_TRT, "GetVideoEncoderConfiguration"): self.get_video_encoder_configuration,
            (_TPTZ, "GetServiceCapabilities"): self.ptz_get_service_capabilities,
        }
        own: dict[tuple[str, str], Callable[[ElementTree.Element], str]] = {
            (_TRT, "GetProfiles"): self._get_profiles,
            (_TRT, "GetStreamUri"): self._get_stream_uri,
            (_TRT, "GetSnapshotUri"): self._get_snapshot_uri,
            (_TPTZ, "GetNodes"): self._get_nodes,
            (_TPTZ, "GetNode"): self._get_node,
            (_TPTZ, "GetConfigurations"): self._get_configurations,
            (_TPTZ, "GetConfiguration"): self._get_configuration,
            (_TPTZ, "GetConfigurationOptions"): self._get_configuration_options,
            (_TPTZ, "GetStatus"): self._get_status,
            (_TPTZ, "AbsoluteMove"): self._absolute_move,
            (_TPTZ, "RelativeMove"): self._relative_move,
            (_TPTZ, "ContinuousMove"): self._continuous_move,
            (_TPTZ, "Stop"): self._stop,
            (_TPTZ, "GotoHomePosition"): self._goto_home_position,
            (_TPTZ, "SetPreset"): self._set_preset,
            (_TPTZ, "GetPresets"): self._get_presets,
            (_TPTZ, "GotoPreset"): self._goto_preset,
            (_TPTZ, "RemovePreset"): self._remove_preset,
        }
        operation = _operation(body)
        if operation is None:
            return self._fault(_Fault("Sender", ["ter:WellFormed"], "not a SOAP 1.2 envelope"))
        namespace, name = _qualified_name(operation.tag)
        try:
            if (namespace, name) in own:
                return self._wrap_envelope(own[namespace, name](operation))
            if (namespace, name) in stock:
                return stock[namespace, name]()
            raise _Fault("Receiver", ["ter:ActionNotSupported"], f"{name} is not supported")
        except _Fault as fault:
            log.debug("fault for %s: %s", name, fault.reason)
            return self._fault(fault)

    # The request's parts.

    def _token(self, operation: ElementTree.Element, element: str, token: str, subcode: str) -> None:
        given = operation.findtext(f"{{{_qualified_name(operation.tag)[0]}}}{element}", "").strip()
        if given != token:
            raise _invalid(subcode, f"no {element} {given!r}")

    def _profile(self, operation: ElementTree.Element) -> None:
        self._token(operation, "ProfileToken", _PROFILE, "NoProfile")

    def _vector(
        self, operation: ElementTree.Element, element: str, spaces: tuple[str, str], subcode: str
    ) -> tuple[tuple[float, float] | None, float | None]:
        """(x, y) of the PanTilt and x of the Zoom of ``element`` (None where absent), in ``spaces``."""
        vector = operation.find(f"tptz:{element}", _NAMESPACES)
        pan_tilt = None if vector is None else vector.find("tt:PanTilt", _NAMESPACES)
        zoom = None if vector is None else vector.find("tt:Zoom", _NAMESPACES)
        for part, space in ((pan_tilt, spaces[0]), (zoom, spaces[1])):
            if part is not None and part.get("space", space) != space:
                raise _invalid("SpaceNotSupported", f"only {space} is supported")
        try:
            return (
                None if pan_tilt is None else (float(pan_tilt.attrib["x"]), float(pan_tilt.attrib["y"])),
                None if zoom is None else float(zoom.attrib["x"]),
            )
        except (KeyError, ValueError):
            raise _invalid(subcode, f"{element} needs numbers x (and y for PanTilt)") from None

    def _speed(self, operation: ElementTree.Element) -> list[float]:
        """The Speed's fractions (3,) of full speed, each in (0, 1], 1 where not given."""
        pan_tilt, zoom = self._vector(operation, "Speed", (_PAN_TILT_SPEED, _ZOOM_SPEED), "InvalidSpeed")
        speed = [*(pan_tilt or (1.0, 1.0)), 1.0 if zoom is None else zoom]
        if not all(0.0 < fraction <= 1.0 for fraction in speed):
            raise _invalid("InvalidSpeed", "a speed is in (0, 1]")
        return speed

    def _move_normalised(self, position: Sequence[float | None], speed: Sequence[float]) -> None:
        """Move the axes with a normalised position (None: left as it is)."""
        _, pose, _ = self.head.now()
        here = self.spaces.normalised(pose)
        target = self.spaces.pose([here[axis] if value is None else value for axis, value in enumerate(position)])
        self.head.move_to(
            [None if value is None else float(target[axis]) for axis, value in enumerate(position)], speed
        )

    # Media.

    def _get_profiles(self, operation: ElementTree.Element) -> str:
        c = self.config
        return (
            f'<trt:GetProfilesResponse><trt:Profiles token="{_PROFILE}" fixed="true"><tt:Name>Main</tt:Name>'
            '<tt:VideoSourceConfiguration token="VSC_1"><tt:Name>VideoSource_1</tt:Name><tt:UseCount>1</tt:UseCount>'
            f'<tt:SourceToken>VS_1</tt:SourceToken><tt:Bounds x="0" y="0" width="{c.main_width}" '
            f'height="{c.main_height}"/></tt:VideoSourceConfiguration>'
            '<tt:VideoEncoderConfiguration token="VEC_1"><tt:Name>H264_Main</tt:Name><tt:UseCount>1</tt:UseCount>'
            "<tt:Encoding>H264</tt:Encoding><tt:Resolution>"
            f"<tt:Width>{c.main_width}</tt:Width><tt:Height>{c.main_height}</tt:Height></tt:Resolution>"
            f"<tt:Quality>5</tt:Quality><tt:RateControl><tt:FrameRateLimit>{c.main_fps}</tt:FrameRateLimit>"
            "<tt:EncodingInterval>1</tt:EncodingInterval>"
            f"<tt:BitrateLimit>{self._bitrate_to_kbps(c.main_bitrate)}</tt:BitrateLimit></tt:RateControl>"
            f"</tt:VideoEncoderConfiguration>{_configuration_xml('tt:PTZConfiguration')}"
            "</trt:Profiles></trt:GetProfilesResponse>"
        )

    def _get_stream_uri(self, operation: ElementTree.Element) -> str:
        self._profile(operation)
        if self.stream_uri is None:
            raise _Fault("Receiver", ["ter:ActionNotSupported"], "no RTSP stream (ffmpeg is not on the PATH)")
        return self._render("get_stream_uri", stream_uri=escape(self.stream_uri))

    def _get_snapshot_uri(self, operation: ElementTree.Element) -> str:
        self._profile(operation)
        c = self.config
        return self._render("get_snapshot_uri", snapshot_uri=escape(f"http://{HOST}:{c.onvif_port}/{c.snapshot_url}"))

    # PTZ: the node and the configuration.

    def _node_xml(self) -> str:
        return (
            f'<tptz:PTZNode token="{_NODE}" FixedHomePosition="true"><tt:Name>PTZ</tt:Name>'
            f"<tt:SupportedPTZSpaces>{_spaces_xml()}</tt:SupportedPTZSpaces>"
            f"<tt:MaximumNumberOfPresets>{_MAX_PRESETS}</tt:MaximumNumberOfPresets>"
            "<tt:HomeSupported>true</tt:HomeSupported></tptz:PTZNode>"
        )

    def _get_nodes(self, operation: ElementTree.Element) -> str:
        return f"<tptz:GetNodesResponse>{self._node_xml()}</tptz:GetNodesResponse>"

    def _get_node(self, operation: ElementTree.Element) -> str:
        self._token(operation, "NodeToken", _NODE, "NoEntity")
        return f"<tptz:GetNodeResponse>{self._node_xml()}</tptz:GetNodeResponse>"

    def _get_configurations(self, operation: ElementTree.Element) -> str:
        configuration = _configuration_xml("tptz:PTZConfiguration")
        return f"<tptz:GetConfigurationsResponse>{configuration}</tptz:GetConfigurationsResponse>"

    def _get_configuration(self, operation: ElementTree.Element) -> str:
        self._token(operation, "PTZConfigurationToken", _CONFIGURATION, "NoConfig")
        configuration = _configuration_xml("tptz:PTZConfiguration")
        return f"<tptz:GetConfigurationResponse>{configuration}</tptz:GetConfigurationResponse>"

    def _get_configuration_options(self, operation: ElementTree.Element) -> str:
        self._token(operation, "ConfigurationToken", _CONFIGURATION, "NoConfig")
        return (
            "<tptz:GetConfigurationOptionsResponse><tptz:PTZConfigurationOptions>"
            f"<tt:Spaces>{_spaces_xml()}</tt:Spaces>"
            f"<tt:PTZTimeout><tt:Min>PT0S</tt:Min><tt:Max>PT{_MAX_TIMEOUT_S:g}S</tt:Max></tt:PTZTimeout>"
            "</tptz:PTZConfigurationOptions></tptz:GetConfigurationOptionsResponse>"
        )

    # PTZ: status and moves.

    def _get_status(self, operation: ElementTree.Element) -> str:
        self._profile(operation)
        _, pose, moving = self.head.now()
        pan_tilt, zoom = ("MOVING" if axes else "IDLE" for axes in (moving[0] or moving[1], moving[2]))
        utc = datetime.now(UTC).isoformat(timespec="milliseconds").replace("+00:00", "Z")
        return (
            f"<tptz:GetStatusResponse><tptz:PTZStatus>{_position_xml('tt:Position', self.spaces.normalised(pose))}"
            f"<tt:MoveStatus><tt:PanTilt>{pan_tilt}</tt:PanTilt><tt:Zoom>{zoom}</tt:Zoom></tt:MoveStatus>"
            f"<tt:UtcTime>{utc}</tt:UtcTime></tptz:PTZStatus></tptz:GetStatusResponse>"
        )

    def _absolute_move(self, operation: ElementTree.Element) -> str:
        self._profile(operation)
        pan_tilt, zoom = self._vector(operation, "Position", (_PAN_TILT_POSITION, _ZOOM_POSITION), "InvalidPosition")
        if not all(-1.0 <= value <= 1.0 for value in pan_tilt or ()) or not 0.0 <= (zoom or 0.0) <= 1.0:
            raise _invalid("InvalidPosition", "a position is in [-1, 1] (pan, tilt) and [0, 1] (zoom)")
        speed = self._speed(operation)
        self._move_normalised([*(pan_tilt or (None, None)), zoom], speed)
        return "<tptz:AbsoluteMoveResponse/>"

    def _relative_move(self, operation: ElementTree.Element) -> str:
        self._profile(operation)
        spaces = (_PAN_TILT_TRANSLATION, _ZOOM_TRANSLATION)
        pan_tilt, zoom = self._vector(operation, "Translation", spaces, "InvalidTranslation")
        translation = [*(pan_tilt or (None, None)), zoom]
        if not all(-1.0 <= value <= 1.0 for value in translation if value is not None):
            raise _invalid("InvalidTranslation", "a translation is in [-1, 1]")
        speed = self._speed(operation)
        _, pose, _ = self.head.now()
        here = self.spaces.normalised(pose)
        lowest, highest = (-1.0, -1.0, 0.0), (1.0, 1.0, 1.0)
        self._move_normalised(
            [
                None if step is None else float(np.clip(here[axis] + step, lowest[axis], highest[axis]))
                for axis, step in enumerate(translation)
            ],
            speed,
        )
        return "<tptz:RelativeMoveResponse/>"

    def _continuous_move(self, operation: ElementTree.Element) -> str:
        self._profile(operation)
        spaces = (_PAN_TILT_VELOCITY, _ZOOM_VELOCITY)
        pan_tilt, zoom = self._vector(operation, "Velocity", spaces, "InvalidVelocity")
        velocity = [*(pan_tilt or (None, None)), zoom]
        if not all(-1.0 <= value <= 1.0 for value in velocity if value is not None):
            raise _invalid("InvalidVelocity", "a velocity is in [-1, 1]")
        self.head.run(velocity, self._timeout_s(operation))
        return "<tptz:ContinuousMoveResponse/>"

    def _timeout_s(self, operation: ElementTree.Element) -> float:
        """The Timeout (xs:duration, days to seconds) in seconds, the default if not given."""
        text = operation.findtext("tptz:Timeout", None, _NAMESPACES)
        if text is None:
            return _DEFAULT_TIMEOUT_S
        match = _DURATION.fullmatch(text.strip())
        if match is None:
            raise _invalid("TimeoutNotSupported", f"Timeout {text.strip()!r} is not an xs:duration of days to seconds")
        days, hours, minutes, seconds = (float(part or 0.0) for part in match.groups())
        timeout_s = ((days * 24.0 + hours) * 60.0 + minutes) * 60.0 + seconds
        if timeout_s > _MAX_TIMEOUT_S:
            raise _invalid("TimeoutNotSupported", f"Timeout is at most PT{_MAX_TIMEOUT_S:g}S")
        return timeout_s

    def _stop(self, operation: ElementTree.Element) -> str:
        self._profile(operation)
        flags = [operation.findtext(f"tptz:{axis}", "true", _NAMESPACES).strip() for axis in ("PanTilt", "Zoom")]
        pan_tilt, zoom = (flag in ("true", "1") for flag in flags)
        self.head.stop([pan_tilt, pan_tilt, zoom])
        return "<tptz:StopResponse/>"

    def _goto_home_position(self, operation: ElementTree.Element) -> str:
        self._profile(operation)
        self.head.move_to(list(self.home_pose), self._speed(operation))
        return "<tptz:GotoHomePositionResponse/>"

    # PTZ: presets, in memory.

    def _set_preset(self, operation: ElementTree.Element) -> str:
        self._profile(operation)
        token = operation.findtext("tptz:PresetToken", "", _NAMESPACES).strip()
        name = operation.findtext("tptz:PresetName", "", _NAMESPACES).strip()
        _, pose, _ = self.head.now()
        with self._presets_lock:
            if token and token not in self._presets:
                raise _invalid("NoToken", f"no preset {token!r}")
            if not token:
                if len(self._presets) >= _MAX_PRESETS:
                    raise _Fault("Receiver", ["ter:Action", "ter:TooManyPresets"], f"at most {_MAX_PRESETS} presets")
                token, self._next_preset = str(self._next_preset), self._next_preset + 1
            self._presets[token] = (name or token, pose)
        return f"<tptz:SetPresetResponse><tptz:PresetToken>{escape(token)}</tptz:PresetToken></tptz:SetPresetResponse>"

    def _get_presets(self, operation: ElementTree.Element) -> str:
        self._profile(operation)
        with self._presets_lock:
            presets = list(self._presets.items())
        return (
            "<tptz:GetPresetsResponse>"
            + "".join(
                f"<tptz:Preset token={quoteattr(token)}><tt:Name>{escape(name)}</tt:Name>"
                f"{_position_xml('tt:PTZPosition', self.spaces.normalised(pose))}</tptz:Preset>"
                for token, (name, pose) in presets
            )
            + "</tptz:GetPresetsResponse>"
        )

    def _preset(self, operation: ElementTree.Element) -> str:
        token = operation.findtext("tptz:PresetToken", "", _NAMESPACES).strip()
        if token not in self._presets:
            raise _invalid("NoToken", f"no preset {token!r}")
        return token

    def _goto_preset(self, operation: ElementTree.Element) -> str:
        self._profile(operation)
        with self._presets_lock:
            _, pose = self._presets[self._preset(operation)]
        self.head.move_to(list(pose), self._speed(operation))
        return "<tptz:GotoPresetResponse/>"

    def _remove_preset(self, operation: ElementTree.Element) -> str:
        self._profile(operation)
        with self._presets_lock:
            del self._presets[self._preset(operation)]
        return "<tptz:RemovePresetResponse/>"


class _RTSPServer(NativeRTSPServer):
    """ipycam's RTSP server on 127.0.0.1: RTP over the RTSP connection only, and a stop() that ends it all."""

    def __init__(self) -> None:
        super().__init__(port=0, host=HOST)
        self._threads_lock = threading.Lock()
        self._clients: set[tuple[threading.Thread, socket.socket]] = set()
        self._forwarders: set[threading.Thread] = set()

    def start(self) -> bool:
        started = super().start()
        if started:
            self.port = self._server_socket.getsockname()[1]
        return started

    def _handle_setup(self, uri, stream_name, headers, cseq, client_socket, client_address, session_id):
        # The UDP transport would bind ('', 0) (rtsp.py:740): only TCP-interleaved (as rtsp.py:706 tells them).
        transport = headers.get("Transport", "")
        if "TCP" not in transport and "interleaved" not in transport:
            return self._error_response(461, "Unsupported Transport", cseq), session_id
        return super()._handle_setup(uri, stream_name, headers, cseq, client_socket, client_address, session_id)

    def _build_ffmpeg_rtp_cmd_tcp_local(self, stream_info, local_port, rtcp_port=None):
        command = super()._build_ffmpeg_rtp_cmd_tcp_local(stream_info, local_port, rtcp_port)
        command[1:1] = ["-nostats", "-loglevel", "error"]
        command[-1] += ("&" if "?" in command[-1] else "?") + f"localaddr={HOST}"
        return command

    def _handle_client(self, client_socket, client_address):
        client = (threading.current_thread(), client_socket)
        with self._threads_lock:
            self._clients.add(client)
        try:
            super()._handle_client(client_socket, client_address)
        finally:
            with self._threads_lock:
                self._clients.discard(client)

    def _tcp_rtp_forwarder(self, local_socket, session, channel=None):
        with self._threads_lock:
            self._forwarders.add(threading.current_thread())
        try:
            super()._tcp_rtp_forwarder(local_socket, session, channel)
        finally:
            with self._threads_lock:
                self._forwarders.discard(threading.current_thread())

    def _close_session(self, session) -> None:
        session.state = RTSPState.TEARDOWN  # ends the session's encoder loop, which then ends its ffmpeg
        for key, thread in list(self._rtp_threads.items()):
            if key.startswith(session.session_id):
                thread.join(_JOIN_S)
        super()._close_session(session)

    def stop(self) -> None:
        # Not running first, so that the accept loop takes the shutdown below for the end (rtsp.py:294-297).
        self._is_running = False
        if self._server_socket is not None:
            with contextlib.suppress(OSError):
                self._server_socket.shutdown(socket.SHUT_RDWR)  # wakes accept() at once, not after its 1 s poll
        super().stop()  # ends the sessions and their ffmpeg encoders, closes the listening socket
        with self._threads_lock:
            clients, forwarders = list(self._clients), list(self._forwarders)
        for _, client_socket in clients:
            with contextlib.suppress(OSError):
                client_socket.shutdown(socket.SHUT_RDWR)  # wakes its thread's recv() (30 s timeout)
        for thread in [
            self._accept_thread,
            *(thread for thread, _ in clients),
            *self._rtp_threads.values(),
            *forwarders,
        ]:
            if thread is not None:
                thread.join(_JOIN_S)


class _HTTPServer(socketserver.ThreadingTCPServer):
    """Request threads are not daemons, so that server_close() joins them."""

    allow_reuse_address = True  # a new camera can take the port at once, past the closed connections' TIME_WAIT
    daemon_threads = False
    block_on_close = True


class _Handler(IPCameraHTTPHandler):
    """ONVIF (POST /onvif/...), the snapshot and MJPEG; ipycam's web UI and REST API answer 404."""

    timeout = 10.0  # s: a stalled client cannot hold stop() for longer

    def do_GET(self) -> None:
        config = self.camera.config
        if self.path.partition("?")[0] in (f"/{config.snapshot_url}", f"/{config.mjpeg_url}"):
            super().do_GET()
        else:
            self.send_error(404)

    def do_POST(self) -> None:
        if self.path.startswith("/onvif/"):
            super().do_POST()
        else:
            self.send_error(404)


class _Served:
    """What ipycam's HTTP handler reads of its camera (http.py:44, 110-113, 161, 193, 379, 422-448),
    and the frames' way out to the snapshot, MJPEG and RTSP."""

    def __init__(self, config, onvif: _ONVIFService):
        self.config, self.onvif = config, onvif
        self.mjpeg_streamer = MJPEGStreamer(quality=80)
        self.rtsp_server: _RTSPServer | None = None
        self._frame: np.ndarray | None = None
        self._frame_lock = threading.Lock()

    def get_snapshot_frame(self) -> np.ndarray | None:
        with self._frame_lock:
            return self._frame

    def publish(self, frame: np.ndarray) -> None:
        """Serve ``frame`` (read-only: the outputs hold it without copying) from now on."""
        with self._frame_lock:
            self._frame = frame
        if self.mjpeg_streamer.client_count > 0:
            self.mjpeg_streamer.stream_frame(frame)
        if self.rtsp_server is not None:
            self.rtsp_server.stream_frame(_STREAM, frame)


class VirtualONVIFCamera:
    """An ONVIF PTZ camera on 127.0.0.1 whose images come from ``render(pose, elapsed_s) -> (h, w, 3) uint8 BGR``.

    render : the image (h, w, 3) uint8 BGR at pose (3,) (pan_deg, tilt_deg, zoom), ``elapsed_s`` after start().
    spaces : the mapping of the ONVIF normalised spaces to poses; the head's limits are its ends.
    speeds : the axes' full speeds; start_pose : (3,) the pose at start, and the home position.
    image_size_px : (width, height) of the images render() returns.
    port : the ONVIF (HTTP) port, 0 for any free one; username, password : both, or neither for no
        authentication (WS-Security UsernameToken for ONVIF, HTTP Basic for the snapshot and MJPEG).
    frame_rate_hz : how often an image is rendered; rtsp : stream H.264 over RTSP if ffmpeg is on the PATH.

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
    ):
        width_px, height_px = (int(size) for size in image_size_px)
        zoom_factors = [zoom for _, zoom in spaces.zoom_curve]
        limits = np.array([sorted(spaces.pan_deg), sorted(spaces.tilt_deg), [zoom_factors[0], zoom_factors[-1]]])
        start_pose = np.asarray(start_pose, dtype=float)
        rates_per_s = np.array([speeds.pan_deg_s, speeds.tilt_deg_s, speeds.zoom_per_s], dtype=float)
        if width_px <= 0 or height_px <= 0 or not frame_rate_hz > 0 or not np.all(rates_per_s > 0):
            raise ValueError("the image size, the frame rate and the axes' speeds must be positive")
        if start_pose.shape != (3,) or not np.all((limits[:, 0] <= start_pose) & (start_pose <= limits[:, 1])):
            raise ValueError(f"start_pose {start_pose} is not a pose within the spaces' limits {limits.tolist()}")
        if bool(username) != bool(password):
            raise ValueError("give both a user name and a password, or neither (no authentication)")
        self._render, self.spaces, self.start_pose = render, spaces, start_pose
        self.image_size_px = (width_px, height_px)
        self.frame_rate_hz, self.rtsp = frame_rate_hz, rtsp
        self._port, self._credentials = port, (username, password)
        self._head = _Head(start_pose, limits, rates_per_s)
        self.onvif_port: int | None = None
        self.rtsp_port: int | None = None
        self._served: _Served | None = None
        self._http: _HTTPServer | None = None
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
        width_px, height_px = self.image_size_px
        config = CameraConfig(
            name="ptztrack virtual PTZ",
            manufacturer="ptztrack",
            model="VirtualONVIFCamera",
            local_ip=HOST,
            username=username,
            password=password,
            main_width=width_px,
            main_height=height_px,
            main_fps=max(1, round(self.frame_rate_hz)),
            main_bitrate="1M",
        )
        onvif = _ONVIFService(config, self._head, self.spaces, self.start_pose)
        self._served = served = _Served(config, onvif)
        try:
            handler = type("_CameraHandler", (_Handler,), {"camera": served})
            self._http = _HTTPServer((HOST, self._port), handler)
            self.onvif_port = config.onvif_port = self._http.server_address[1]
            if self.rtsp and shutil.which("ffmpeg"):
                rtsp_server = _RTSPServer()
                # ffmpeg takes the exact rate (the profile's FrameRateLimit is a whole number).
                rtsp_server.add_stream(_STREAM, width_px, height_px, self.frame_rate_hz, config.main_bitrate)
                if not rtsp_server.start():
                    raise OSError(f"the RTSP server could not listen on {HOST}")
                served.rtsp_server, self.rtsp_port = rtsp_server, rtsp_server.port
                config.rtsp_port = rtsp_server.port
                onvif.stream_uri = config.main_stream_rtsp
            elif self.rtsp:
                log.info("ffmpeg is not on the PATH: no RTSP stream")
            served.mjpeg_streamer.start()
            self._start_s = time.monotonic()
            self._render_one()  # the first image before any request, and a failing render() fails here
            for target, name in ((self._http.serve_forever, "onvif-http"), (self._render_frames, "onvif-frames")):
                thread = threading.Thread(target=target, name=name, daemon=True)
                thread.start()
                self._threads.append(thread)  # only once started: stop() waits for serve_forever() to end
        except BaseException:
            self.stop()
            raise
        log.info("virtual ONVIF camera on %s: ONVIF port %d, RTSP port %s", HOST, self.onvif_port, self.rtsp_port)

    def stop(self) -> None:
        """Stop rendering, close every connection and port, end ffmpeg, join the threads; idempotent."""
        self._stopping.set()
        http, served = self._http, self._served
        self._http = self._served = None
        if http is not None and self._threads:
            http.shutdown()  # ends serve_forever()
        for thread in self._threads:
            thread.join(_JOIN_S)
        self._threads = []
        if served is not None:
            served.mjpeg_streamer.stop()  # ends the MJPEG clients' request threads, joined below
            if served.rtsp_server is not None:
                served.rtsp_server.stop()
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
        served = self._served
        if served is not None:
            served.publish(frame)

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
