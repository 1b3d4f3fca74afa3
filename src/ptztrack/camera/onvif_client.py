"""A real (or virtual) ONVIF PTZ camera driven from synchronous code, with a timeout on every call.

The client is onvif-zeep-async (the ONVIF client of Home Assistant and
Frigate), which is asynchronous; the closed loop is not. So the client runs
its own event loop in a daemon thread and every call here waits for one
coroutine there, at most ``timeout_s`` (the library's own timeouts are 30-90
s). Its WSDL folder is passed explicitly, services are made with the
``create_*_service()`` coroutines, and the client is closed at the end.

Failures become :class:`CameraError`, one line that names the camera
(``host:port``) and never its password: a refused connection, a wrong
user name or password, no answer within the timeout, a fault from the
camera, an image that does not decode.
"""

import asyncio
import logging
import os
import threading
import time
from collections.abc import Coroutine
from dataclasses import dataclass, field
from typing import Any
from urllib.parse import quote, unquote, urlsplit

import cv2
import numpy as np

from ptztrack.names import PASSWORD_VARIABLE

# Connecting also parses the ONVIF WSDLs, local work that a loaded machine slows and that is not the
# camera's answer time, which ``timeout_s`` bounds.
CONNECT_TIMEOUT_S = 15.0
USER_VARIABLE = "PTZTRACK_CAMERA_USER"
DEFAULT_ONVIF_PORT = 80
POLL_S = 0.02


class CameraError(RuntimeError):
    """A camera that cannot be reached, refuses the credentials, times out or answers with a fault."""


@dataclass(frozen=True)
class CameraAddress:
    """Where a camera answers ONVIF, and as whom; the password never shows in a repr or a message."""

    host: str
    port: int
    username: str = ""
    password: str = field(default="", repr=False)

    def __str__(self) -> str:
        return f"{self.host}:{self.port}"


def camera_address(url: str, credentials: dict | None = None, environ=os.environ) -> CameraAddress:
    """The address in ``url`` (``onvif://[user[:password]@]host[:port]``, or ``host[:port]``; the port
    defaults to 80), the user name and password taken from the URL, else from ``credentials`` (a
    mapping with ``username`` and ``password``, read from a file), else from the environment
    variables ``PTZTRACK_CAMERA_USER`` and ``PTZTRACK_CAMERA_PASSWORD``."""
    parts = urlsplit(url if "://" in url else f"onvif://{url}")
    if parts.scheme != "onvif" or not parts.hostname:
        raise CameraError(f"--camera {_without_password(url)}: expected onvif://[user[:password]@]host[:port]")
    try:
        port = DEFAULT_ONVIF_PORT if parts.port is None else parts.port
    except ValueError:
        port = 0
    if not 1 <= port <= 65535:
        raise CameraError(f"--camera {_without_password(url)}: the port is not a number from 1 to 65535")
    credentials = credentials or {}
    username = unquote(parts.username or "") or credentials.get("username") or environ.get(USER_VARIABLE, "")
    password = unquote(parts.password or "") or credentials.get("password") or environ.get(PASSWORD_VARIABLE, "")
    return CameraAddress(parts.hostname, port, str(username), str(password))


def _without_password(url: str) -> str:
    parts = urlsplit(url if "://" in url else f"onvif://{url}")
    if parts.password is None:
        return url
    return url.replace(f":{parts.password}@", ":***@", 1)


@dataclass(frozen=True)
class CameraStatus:
    """GetStatus: position (3,) in the normalised spaces (pan, tilt in [-1, 1], zoom in [0, 1]; NaN where
    the camera reports none), and whether any axis is still moving."""

    position: np.ndarray
    moving: bool


# ONVIF's generic relative pan/tilt space, in which :meth:`ONVIFClient.relative_move` translates.
GENERIC_TRANSLATION_SPACE = "http://www.onvif.org/ver10/tptz/PanTiltSpaces/TranslationGenericSpace"


@dataclass(frozen=True)
class PTZMoves:
    """The moves a camera's PTZ node offers (GetNodes' SupportedPTZSpaces): AbsoluteMove (an absolute
    pan/tilt position space), RelativeMove in the generic translation space, ContinuousMove (a pan/tilt
    velocity space)."""

    absolute: bool
    relative: bool
    continuous: bool


class ONVIFClient:
    """One ONVIF PTZ camera: its first media profile's PTZ and snapshot, each call within ``timeout_s``,
    the connection within ``connect_timeout_s``."""

    def __init__(self, address: CameraAddress, timeout_s: float = 5.0, connect_timeout_s: float = CONNECT_TIMEOUT_S):
        self.address = address
        self.timeout_s = timeout_s
        self.connect_timeout_s = connect_timeout_s
        self._loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._loop.run_forever, name="onvif-client", daemon=True)
        self._thread.start()
        self._camera: Any = None
        self._media: Any = None
        self._ptz: Any = None
        self._profile = ""

    def connect(self) -> None:
        """Connect, read the services and the first profile; a :class:`CameraError` if the camera cannot be used."""
        self._call(self._connect(), self.connect_timeout_s)

    def status(self) -> CameraStatus:
        status = self._call(self._ptz.GetStatus({"ProfileToken": self._profile}))
        # Position is optional in PTZStatus: a camera that reports none gives NaN.
        position = getattr(status, "Position", None)
        pan_tilt, zoom = getattr(position, "PanTilt", None), getattr(position, "Zoom", None)
        moving = any(str(getattr(status.MoveStatus, axis, "IDLE")) == "MOVING" for axis in ("PanTilt", "Zoom"))
        xyz = [getattr(pan_tilt, "x", None), getattr(pan_tilt, "y", None), getattr(zoom, "x", None)]
        return CameraStatus(np.array([np.nan if value is None else value for value in xyz], dtype=float), moving)

    def wait_still(self, until_s: float) -> CameraStatus:
        """GetStatus every ``POLL_S`` until the camera stands still or ``until_s`` passes (on
        ``time.monotonic``'s clock); the last status."""
        status = self.status()
        while status.moving and time.monotonic() < until_s:
            time.sleep(POLL_S)
            status = self.status()
        return status

    def move_to(self, position) -> None:
        """AbsoluteMove to ``position`` (3,) in the normalised spaces, at full speed."""
        x, y, zoom = (float(value) for value in position)
        request = {
            "ProfileToken": self._profile,
            "Position": {"PanTilt": {"x": x, "y": y}, "Zoom": {"x": zoom}},
            "Speed": {"PanTilt": {"x": 1.0, "y": 1.0}, "Zoom": {"x": 1.0}},
        }
        self._call(self._ptz.AbsoluteMove(request))

    def relative_move(self, translation) -> None:
        """RelativeMove by ``translation`` (3,) in the generic translation spaces."""
        x, y, zoom = (float(value) for value in translation)
        request = {"ProfileToken": self._profile, "Translation": {"PanTilt": {"x": x, "y": y}, "Zoom": {"x": zoom}}}
        self._call(self._ptz.RelativeMove(request))

    def continuous_move(self, velocity, duration_s: float) -> None:
        """ContinuousMove at ``velocity`` (3,) (fractions of each axis' top speed) for ``duration_s``."""
        x, y, zoom = (float(value) for value in velocity)
        request = {
            "ProfileToken": self._profile,
            "Velocity": {"PanTilt": {"x": x, "y": y}, "Zoom": {"x": zoom}},
            "Timeout": f"PT{duration_s:.3f}S",
        }
        self._call(self._ptz.ContinuousMove(request))

    def stop(self) -> None:
        """Stop every axis."""
        self._call(self._ptz.Stop({"ProfileToken": self._profile, "PanTilt": True, "Zoom": True}))

    def set_preset(self, name: str) -> str:
        """Store the current position as a preset called ``name``; its token."""
        return str(self._call(self._ptz.SetPreset({"ProfileToken": self._profile, "PresetName": name})))

    def presets(self) -> dict[str, str]:
        """{token: name} of the camera's presets."""
        found = self._call(self._ptz.GetPresets({"ProfileToken": self._profile})) or []
        return {str(preset.token): str(preset.Name) for preset in found}

    def remove_preset(self, token: str) -> None:
        self._call(self._ptz.RemovePreset({"ProfileToken": self._profile, "PresetToken": token}))

    def goto_preset(self, token: str) -> None:
        self._call(self._ptz.GotoPreset({"ProfileToken": self._profile, "PresetToken": token}))

    def moves(self) -> PTZMoves:
        """Which of AbsoluteMove, RelativeMove (generic space) and ContinuousMove the first PTZ node offers."""
        spaces = self._call(self._ptz.GetNodes())[0].SupportedPTZSpaces

        def uris(name: str) -> list[str]:
            return [str(space.URI) for space in getattr(spaces, name, None) or []]

        return PTZMoves(
            absolute=bool(uris("AbsolutePanTiltPositionSpace")),
            relative=GENERIC_TRANSLATION_SPACE in uris("RelativePanTiltTranslationSpace"),
            continuous=bool(uris("ContinuousPanTiltVelocitySpace")),
        )

    def position_limits(self) -> np.ndarray:
        """(3, 2) [low, high] of pan, tilt and zoom in the node's absolute position spaces."""
        spaces = self._call(self._ptz.GetNodes())[0].SupportedPTZSpaces
        pan_tilt, zoom = spaces.AbsolutePanTiltPositionSpace[0], spaces.AbsoluteZoomPositionSpace[0]
        ranges = (pan_tilt.XRange, pan_tilt.YRange, zoom.XRange)
        return np.array([[float(axis.Min), float(axis.Max)] for axis in ranges])

    def stream_uri(self) -> str:
        """The RTSP URI of the profile's stream, with the client's credentials in it."""
        request = {
            "StreamSetup": {"Stream": "RTP-Unicast", "Transport": {"Protocol": "RTSP"}},
            "ProfileToken": self._profile,
        }
        uri = str(self._call(self._media.GetStreamUri(request)).Uri)
        if not self.address.username:
            return uri
        scheme, _, rest = uri.partition("://")
        credentials = f"{quote(self.address.username, safe='')}:{quote(self.address.password, safe='')}@"
        return f"{scheme}://{credentials}{rest}"

    def snapshot(self) -> np.ndarray:
        """The camera's current image, (h, w, 3) uint8 BGR, from its snapshot URI (HTTP Basic)."""
        data = self._call(self._camera.get_snapshot(self._profile, basic_auth=True))
        image = None if not data else cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
        if image is None:
            raise CameraError(f"{self.address}: the snapshot is not an image")
        return image

    def close(self) -> None:
        """Close the client and stop its thread; the camera stays where it is."""
        if self._camera is not None:
            try:
                self._call(self._camera.close())
            except CameraError:
                pass  # a camera gone already has nothing to close
            self._camera = None
        self._loop.call_soon_threadsafe(self._loop.stop)
        self._thread.join(timeout=self.timeout_s)
        self._loop.close()

    async def _connect(self) -> None:
        import onvif  # a heavy import, and only where a camera is used

        # onvif.client configures the root logger at import; ptztrack's own lines are what the user reads.
        logging.getLogger("onvif").setLevel(logging.WARNING)
        wsdl = os.path.join(os.path.dirname(onvif.__file__), "wsdl")
        address = self.address
        camera = onvif.ONVIFCamera(address.host, address.port, address.username, address.password, wsdl, no_cache=True)
        try:
            await camera.update_xaddrs()
            self._media = await camera.create_media_service()
            self._ptz = await camera.create_ptz_service()
            profiles = await self._media.GetProfiles()
        except BaseException:
            await camera.close()
            raise
        if not profiles:
            await camera.close()
            raise CameraError(f"{address}: the camera has no media profile")
        self._camera, self._profile = camera, profiles[0].token

    def _call(self, coroutine: Coroutine, timeout_s: float | None = None) -> Any:
        timeout_s = self.timeout_s if timeout_s is None else timeout_s
        future = asyncio.run_coroutine_threadsafe(asyncio.wait_for(coroutine, timeout_s), self._loop)
        try:
            return future.result(timeout_s + 1.0)
        except TimeoutError:
            future.cancel()
            raise CameraError(f"{self.address}: no answer within {timeout_s:g} s") from None
        except CameraError:
            raise
        except Exception as error:
            raise CameraError(f"{self.address}: {_reason(error)}") from None


def _reason(error: Exception) -> str:
    """What went wrong, in a few words, never with the request (which may carry credentials)."""
    from zeep.exceptions import Fault, TransportError, XMLSyntaxError

    # zeep makes a fault without a code of an answer that is not a SOAP fault (an HTTP error page).
    if isinstance(error, XMLSyntaxError | TransportError) or isinstance(error, Fault) and error.code is None:
        status = getattr(error, "status_code", None)
        if status in (401, 403):
            return f"the camera refused the user name or password (HTTP {status})"
        answer = f"HTTP {status}" if status else "an answer that is not SOAP"
        return f"not an ONVIF camera ({answer} where ONVIF's device service should answer)"
    if isinstance(error, Fault):
        message = str(error.message or "")
        if "authori" in message.lower() or "auth" in message.lower():
            return "the camera refused the user name or password"
        return f"the camera answered with a fault ({message[:80]})"
    if isinstance(error, OSError):
        # aiohttp wraps the socket's error (ConnectionRefusedError, a timeout, no route) in its own.
        cause = getattr(error, "os_error", None) or error
        if isinstance(cause, ConnectionRefusedError):
            return "cannot connect (connection refused)"
        return f"cannot connect ({cause.strerror or type(cause).__name__})"
    return f"{type(error).__name__}: {str(error)[:80]}"
