"""The service's /healthz and /metrics, served on 127.0.0.1 beside the web view."""

import json
import re
import time
import urllib.error
import urllib.request

from ptztrack.service.health import METRICS, CameraHealth, health_routes
from ptztrack.view.web_view import ViewHub, ViewServer

# A sample of the Prometheus text format: name{label="value"} value.
SAMPLE = re.compile(r'^(ptztrack_[a-z_]+)\{camera="([a-z]+)"\} (-?[0-9.]+|NaN)$')


def _get(url: str) -> tuple[int, str, str]:
    try:
        with urllib.request.urlopen(url, timeout=5) as answer:
            return answer.status, answer.headers["content-type"], answer.read().decode()
    except urllib.error.HTTPError as error:
        return error.code, error.headers["content-type"], error.read().decode()


def test_healthz_reports_each_camera_and_is_503_while_one_is_not_running_with_a_fresh_picture():
    front, side = CameraHealth("front", status="running"), CameraHealth("side", status="offline", outages=1)
    for _ in range(5):
        front.stepped(time.time())
    with ViewServer(ViewHub(), 0, health_routes([front, side])) as server:
        status, kind, body = _get(f"{server.address}healthz")
        assert status == 503 and kind == "application/json"
        report = json.loads(body)
        assert not report["ok"] and report["cameras"]["side"]["status"] == "offline"
        assert report["cameras"]["front"]["steps"] == 5 and 0 <= report["cameras"]["front"]["last_picture_age_s"] < 5
        assert report["cameras"]["front"]["steps_per_s"] == 0.5  # five in the last 10 s
        side.status = "running"
        side.stepped(time.time())
        status, _, body = _get(f"{server.address}healthz")
        assert status == 200 and json.loads(body)["ok"]


def test_metrics_are_the_prometheus_text_format_one_sample_per_camera_after_help_and_type():
    front = CameraHealth("front", status="running", reconnects=2)
    front.stepped(time.time())
    cameras = [front, CameraHealth("side")]
    with ViewServer(ViewHub(), 0, health_routes(cameras)) as server:
        status, kind, body = _get(f"{server.address}metrics")
    assert status == 200 and kind.startswith("text/plain") and "version=0.0.4" in kind
    lines = body.splitlines()
    assert body.endswith("\n") and len(lines) == len(METRICS) * 4
    samples = {}
    for at in range(0, len(lines), 4):
        help_line, type_line, *sample_lines = lines[at : at + 4]
        name = help_line.split()[2]
        assert help_line.startswith(f"# HELP {name} ")
        assert type_line in (f"# TYPE {name} counter", f"# TYPE {name} gauge")
        for line in sample_lines:
            found = SAMPLE.match(line)
            assert found and found.group(1) == name, line
            samples[(name, found.group(2))] = found.group(3)
    assert samples[("ptztrack_steps_total", "front")] == "1" and samples[("ptztrack_steps_total", "side")] == "0"
    assert samples[("ptztrack_reconnects_total", "front")] == "2"
    assert samples[("ptztrack_up", "front")] == "1" and samples[("ptztrack_up", "side")] == "0"
    assert samples[("ptztrack_last_picture_age_seconds", "side")] == "NaN"  # no picture yet
