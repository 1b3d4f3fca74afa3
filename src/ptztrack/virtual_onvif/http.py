"""HTTP for the virtual ONVIF camera: SOAP on POST /onvif/..., the JPEG snapshot and MJPEG on GET.

SOAP requests authenticate inside the envelope (WS-Security, :mod:`ptztrack.virtual_onvif.soap`) and
are answered with the status of SOAP 1.2's HTTP binding. The snapshot and the MJPEG stream take HTTP
Basic (RFC 7617) or Digest (RFC 7616) authentication. Unauthenticated, they answer 401 with three
challenges, strongest first (RFC 7616 3.7): Digest SHA-256, Digest MD5, Basic.
Digest with qop=auth:

    HA1 = H(username ":" realm ":" password),   HA2 = H(method ":" request-target),
    response = H(HA1 ":" nonce ":" nc ":" cnonce ":" "auth" ":" HA2)

H being the hex digest of the challenge's algorithm. A nonce is ``t.HMAC-SHA256(secret, t)`` (t the
camera's monotonic clock in whole seconds when issued, the secret drawn at start) and is honoured
``nonce_lifetime_s`` after t; a right answer with an older nonce is challenged again with
``stale=true``, so the client retries with a fresh nonce without asking the user.

A client that goes away mid-answer (BrokenPipeError, ConnectionResetError) costs one debug line.
"""

import base64
import hashlib
import hmac
import logging
import re
import secrets
import socketserver
import sys
import threading
import time
from collections.abc import Callable
from enum import Enum

import numpy as np
from ipycam import IPCameraHTTPHandler, MJPEGStreamer

from ptztrack.virtual_onvif.soap import SOAPService

log = logging.getLogger("ptztrack.onvif_server")

SNAPSHOT_PATH, MJPEG_PATH = "/snapshot.jpg", "/stream.mjpeg"
_DIGESTS: dict[str, Callable[[bytes], str]] = {
    "SHA-256": lambda data: hashlib.sha256(data).hexdigest(),
    "MD5": lambda data: hashlib.md5(data).hexdigest(),
}
# An auth-param of an Authorization header: name=token or name="quoted string" (RFC 9110 11.2).
_PARAM = re.compile(r'\s*([!#$%&\'*+.^_`|~0-9A-Za-z-]+)\s*=\s*("(?:[^"\\]|\\.)*"|[^\s,]*)\s*(?:,|$)')
_DISCONNECTS = (BrokenPipeError, ConnectionResetError, ConnectionAbortedError)
# The largest SOAP request read: ONVIF requests are a few kilobytes.
_MAX_REQUEST_BYTES = 1 << 20


class Verdict(Enum):
    """What an Authorization header is worth."""

    ACCEPTED = "accepted"
    REFUSED = "refused"
    STALE = "stale"  # a right Digest answer to an expired nonce


class HTTPAuth:
    """HTTP Basic and Digest authentication of one user (module docstring).

    realm : the protection space's name; nonce_lifetime_s : how long a Digest nonce is honoured;
    clock : monotonic seconds now.
    """

    def __init__(
        self,
        username: str,
        password: str,
        realm: str,
        nonce_lifetime_s: float = 300.0,
        clock: Callable[[], float] = time.monotonic,
    ):
        self._username, self._password, self.realm = username, password, realm
        self.nonce_lifetime_s, self._clock = nonce_lifetime_s, clock
        self._secret = secrets.token_bytes(32)

    def challenges(self, stale: bool = False) -> list[str]:
        """The WWW-Authenticate values of a 401, strongest first."""
        nonce = self._nonce()
        extra = ", stale=true" if stale else ""
        return [
            f'Digest realm="{self.realm}", qop="auth", algorithm={algorithm}, nonce="{nonce}"{extra}'
            for algorithm in _DIGESTS
        ] + [f'Basic realm="{self.realm}", charset="UTF-8"']

    def check(self, method: str, target: str, authorization: str) -> Verdict:
        """The verdict on the Authorization header ``authorization`` of a ``method`` request for ``target``."""
        scheme, _, credentials = authorization.strip().partition(" ")
        if scheme.lower() == "basic":
            return self._basic(credentials)
        if scheme.lower() == "digest":
            return self._digest(method, target, credentials)
        return Verdict.REFUSED

    def _basic(self, credentials: str) -> Verdict:
        try:
            user, separator, password = base64.b64decode(credentials.strip(), validate=True).decode().partition(":")
        except (ValueError, UnicodeDecodeError):
            return Verdict.REFUSED
        user_ok = hmac.compare_digest(user.encode(), self._username.encode())
        password_ok = hmac.compare_digest(password.encode(), self._password.encode())
        return Verdict.ACCEPTED if separator and user_ok and password_ok else Verdict.REFUSED

    def _digest(self, method: str, target: str, credentials: str) -> Verdict:
        params = {
            name.lower(): re.sub(r"\\(.)", r"\1", value[1:-1]) if value.startswith('"') else value
            for name, value in _PARAM.findall(credentials)
        }
        digest = _DIGESTS.get(params.get("algorithm", "MD5").upper())
        wanted = ("username", "realm", "nonce", "uri", "response", "qop", "nc", "cnonce")
        if digest is None or not all(name in params for name in wanted) or params["qop"] != "auth":
            return Verdict.REFUSED
        if params["realm"] != self.realm or params["uri"] != target:
            return Verdict.REFUSED
        ha1 = digest(f"{self._username}:{self.realm}:{self._password}".encode())
        ha2 = digest(f"{method}:{target}".encode())
        fields = (ha1, params["nonce"], params["nc"], params["cnonce"], "auth", ha2)
        expected = digest(":".join(fields).encode())
        user_ok = hmac.compare_digest(params["username"].encode(), self._username.encode())
        if not (user_ok and hmac.compare_digest(params["response"].encode(), expected.encode())):
            return Verdict.REFUSED
        issued_s = self._issued_s(params["nonce"])
        if issued_s is None:
            return Verdict.REFUSED
        return Verdict.ACCEPTED if self._clock() - issued_s <= self.nonce_lifetime_s else Verdict.STALE

    def _nonce(self) -> str:
        issued = str(int(self._clock()))
        return f"{issued}.{hmac.new(self._secret, issued.encode(), hashlib.sha256).hexdigest()}"

    def _issued_s(self, nonce: str) -> float | None:
        """When the nonce was issued (the clock's seconds), None if this camera did not issue it."""
        issued, _, signature = nonce.partition(".")
        expected = hmac.new(self._secret, issued.encode(), hashlib.sha256).hexdigest()
        if not issued.isdigit() or not hmac.compare_digest(signature.encode(), expected.encode()):
            return None
        return float(issued)


class Served:
    """What the HTTP handler serves: the SOAP service ``soap`` (set before serving), the snapshot (the
    latest image) and the MJPEG stream, the last two behind ``auth`` (None: open)."""

    soap: SOAPService

    def __init__(self, auth: HTTPAuth | None):
        self.auth = auth
        self.mjpeg_streamer = MJPEGStreamer(quality=80)
        self._frame: np.ndarray | None = None
        self._frame_lock = threading.Lock()

    def get_snapshot_frame(self) -> np.ndarray | None:
        """The latest image (ipycam's handler reads it for the snapshot)."""
        with self._frame_lock:
            return self._frame

    def publish(self, frame: np.ndarray) -> None:
        """Serve ``frame`` (read-only: the outputs hold it without copying) from now on."""
        with self._frame_lock:
            self._frame = frame
        if self.mjpeg_streamer.client_count > 0:
            self.mjpeg_streamer.stream_frame(frame)


class _Handler(IPCameraHTTPHandler):
    """SOAP (POST /onvif/...), the snapshot and MJPEG (GET); anything else 404, ipycam's web UI and REST
    API (which write ./camera_config.json and take uploads) included."""

    camera: Served  # set per server by make_server()
    timeout = 10.0  # s: a stalled client cannot hold stop() for longer

    def do_GET(self) -> None:
        path = self.path.partition("?")[0]
        if path not in (SNAPSHOT_PATH, MJPEG_PATH):
            self.send_error(404)
        elif self._authorised():
            if path == SNAPSHOT_PATH:
                self.serve_snapshot()
            else:
                self.serve_mjpeg_stream()

    def do_POST(self) -> None:
        if not self.path.startswith("/onvif/"):
            self.send_error(404)
            return
        try:
            length = int(self.headers.get("Content-Length", ""))
        except ValueError:
            self.send_error(411, "a SOAP request needs a Content-Length")
            return
        if not 0 <= length <= _MAX_REQUEST_BYTES:
            self.send_error(413, f"Content-Length {length} is not in [0, {_MAX_REQUEST_BYTES}]")
            return
        status, answer = self.camera.soap.answer(self.rfile.read(length))
        self.send_response(status)
        self.send_header("Content-Type", "application/soap+xml; charset=utf-8")
        self.send_header("Content-Length", str(len(answer)))
        self.end_headers()
        self.wfile.write(answer)

    def _authorised(self) -> bool:
        """Whether the request may be served; if not, its 401 has been sent."""
        auth = self.camera.auth
        if auth is None:
            return True
        verdict = auth.check(self.command, self.path, self.headers.get("Authorization", ""))
        if verdict is Verdict.ACCEPTED:
            return True
        body = b"Unauthorized"
        self.send_response(401)
        for challenge in auth.challenges(stale=verdict is Verdict.STALE):
            self.send_header("WWW-Authenticate", challenge)
        self.send_header("Content-Type", "text/plain")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)
        return False


class HTTPServer(socketserver.ThreadingTCPServer):
    """The camera's HTTP server. Request threads are not daemons, so that server_close() joins them."""

    allow_reuse_address = True  # a new camera can take the port at once, past the closed connections' TIME_WAIT
    # The listen backlog: with socketserver's 5, connections beyond it that arrive at once are reset or
    # their clients try again a second later.
    request_queue_size = 128
    daemon_threads = False
    block_on_close = True

    def handle_error(self, request, client_address) -> None:
        error = sys.exc_info()[1]
        if isinstance(error, _DISCONNECTS):
            log.debug("HTTP client %s:%d went away: %s", *client_address[:2], error)
        else:
            log.exception("HTTP request from %s:%d failed", *client_address[:2])


def make_server(host: str, port: int, served: Served) -> HTTPServer:
    """An HTTP server on (host, port) (0: any free port) serving ``served``."""
    # ipycam's handler finds its camera in a class attribute: each server gets its own handler class.
    handler = type("_CameraHandler", (_Handler,), {"camera": served})
    return HTTPServer((host, port), handler)
