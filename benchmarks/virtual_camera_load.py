"""GetStatus under load: many clients polling the virtual ONVIF camera at once.

The virtual camera of ``ptztrack serve-camera`` (PETS S2.L1, 25 pictures per second rendered and
streamed, WS-Security required) runs in this process, on any free port of 127.0.0.1; ``--clients``
threads each send GetStatus as a plain HTTP SOAP 1.2 request, signed with a fresh UsernameToken,
one after the other for ``--seconds``, a new connection for each (the camera answers HTTP/1.0 and
closes). A request's time is from opening its connection to its answer read whole; a request
refused, reset, timed out (5 s) or answered with anything but HTTP 200 is an error. It prints, and
writes to ``--json``: ``getstatus_p50_ms`` and ``getstatus_p99_ms`` (over the requests answered),
``clients``, ``requests`` (answered) and ``errors``.

    python benchmarks/virtual_camera_load.py [--clients 20] [--seconds 10] [--json PATH]
"""

import argparse
import base64
import hashlib
import http.client
import secrets
import threading
import time
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from ptztrack.builders.recording import pets_scenario
from ptztrack.builders.virtual_camera import virtual_onvif_camera
from ptztrack.files import write_json

USER, PASSWORD = "bench", "bench-pass"
TIMEOUT_S = 5.0
WSSE = "http://docs.oasis-open.org/wss/2004/01/oasis-200401-wss-wssecurity-secext-1.0.xsd"
WSU = "http://docs.oasis-open.org/wss/2004/01/oasis-200401-wss-wssecurity-utility-1.0.xsd"
DIGEST = "http://docs.oasis-open.org/wss/2004/01/oasis-200401-wss-username-token-profile-1.0#PasswordDigest"


def get_status_request() -> bytes:
    """A GetStatus envelope with a new UsernameToken: PasswordDigest = Base64(SHA-1(nonce + Created + password))."""
    nonce = secrets.token_bytes(16)
    created = datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
    digest = base64.b64encode(hashlib.sha1(nonce + created.encode() + PASSWORD.encode()).digest()).decode()
    return (
        '<s:Envelope xmlns:s="http://www.w3.org/2003/05/soap-envelope" '
        'xmlns:tptz="http://www.onvif.org/ver20/ptz/wsdl">'
        f'<s:Header><wsse:Security xmlns:wsse="{WSSE}" xmlns:wsu="{WSU}"><wsse:UsernameToken>'
        f'<wsse:Username>{USER}</wsse:Username><wsse:Password Type="{DIGEST}">{digest}</wsse:Password>'
        f"<wsse:Nonce>{base64.b64encode(nonce).decode()}</wsse:Nonce><wsu:Created>{created}</wsu:Created>"
        "</wsse:UsernameToken></wsse:Security></s:Header>"
        "<s:Body><tptz:GetStatus><tptz:ProfileToken>Profile_Main</tptz:ProfileToken></tptz:GetStatus></s:Body>"
        "</s:Envelope>"
    ).encode()


def poll(port: int, until_s: float, times_s: list[float], errors: list[str]) -> None:
    """Send GetStatus until ``until_s`` (monotonic), appending each answered request's seconds to
    ``times_s`` and each failure's reason to ``errors``."""
    while time.monotonic() < until_s:
        body = get_status_request()
        started_s = time.perf_counter()
        connection = http.client.HTTPConnection("127.0.0.1", port, timeout=TIMEOUT_S)
        try:
            connection.request("POST", "/onvif/ptz_service", body, {"Content-Type": "application/soap+xml"})
            response = connection.getresponse()
            answer = response.read()
            if response.status != 200 or b"GetStatusResponse" not in answer:
                errors.append(f"HTTP {response.status}")
            else:
                times_s.append(time.perf_counter() - started_s)
        except OSError as error:
            errors.append(type(error).__name__)
        finally:
            connection.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clients", type=int, default=20)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    camera, _ = virtual_onvif_camera(pets_scenario("hog"), 1.0, 0, USER, PASSWORD)
    times_s: list[float] = []
    errors: list[str] = []
    with camera:
        until_s = time.monotonic() + args.seconds
        threads = [
            threading.Thread(target=poll, args=(camera.onvif_port, until_s, times_s, errors))
            for _ in range(args.clients)
        ]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
    milliseconds = 1e3 * np.asarray(times_s)
    row = {
        "getstatus_p50_ms": float(np.percentile(milliseconds, 50)) if len(milliseconds) else float("nan"),
        "getstatus_p99_ms": float(np.percentile(milliseconds, 99)) if len(milliseconds) else float("nan"),
        "clients": args.clients,
        "requests": len(times_s),
        "errors": len(errors),
    }
    width = max(map(len, row))
    for key, value in row.items():
        print(f"{key:>{width}}  {value:.4g}" if isinstance(value, float) else f"{key:>{width}}  {value}")
    if errors:
        kinds, counts = np.unique(errors, return_counts=True)
        print("errors: " + ", ".join(f"{kind} x{count}" for kind, count in zip(kinds, counts, strict=True)))
    if args.json is not None:
        write_json(args.json, row)


if __name__ == "__main__":
    main()
