"""The web view: the server listens on 127.0.0.1 only, a run that nobody watches builds no state, and a
real browser draws a run, a replay of its --out folder and the follow camera, step by step."""

import json
import os
import re
import shutil
import subprocess
import sys
import threading
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import psutil
import pytest
from websockets.sync.client import connect

from ptztrack.builders.episode import episode_world, make_policy, run_episode
from ptztrack.cli import main
from ptztrack.config import scenario_from_dict
from ptztrack.names import VIEW_STATES_FILE
from ptztrack.view.video import view_renderer
from ptztrack.view.view_state import NetworkViewState, ViewState
from ptztrack.view.web_view import ViewHub, ViewServer

CHROMIUM = Path("/usr/bin/chromium")  # Debian's (apt-get install chromium); Playwright's own is not downloadable here
# Where the screenshots are kept for CI to publish (else in the test's temporary folder only).
ARTEFACTS = os.environ.get("PTZTRACK_TEST_ARTEFACTS")
EXCERPT = Path(__file__).parent / "data" / "pets_s2l1_excerpt"
RECORDING = ["--video", str(EXCERPT / "View_001.avi"), "--gt", str(EXCERPT / "gt_mot15.txt")]
RECORDING += ["--calibration", str(EXCERPT / "pinhole.json")]
FRAMES = 30
TIMEOUT_MS = 120_000  # generous: the machine may be loaded


def view_run(frames: int = FRAMES, seed: int = 0):
    """A synthetic smpl run's scenario, world, policy, and a paused hub with the run's observer."""
    scenario = scenario_from_dict({"frames": frames})
    world = episode_world(scenario, seed)
    policy = make_policy("smpl", scenario, world)
    hub = ViewHub(paused=True)
    observer = ViewState(world, policy, frames, "smpl", view_renderer(world)).observer(hub.after_step)
    return scenario, world, policy, hub, observer


def test_the_view_listens_on_127_0_0_1_only():
    *_, hub, _ = view_run()
    with ViewServer(hub) as server:
        listening = [
            c for c in psutil.Process().net_connections(kind="inet") if c.status == psutil.CONN_LISTEN and c.laddr
        ]
        ours = [c for c in listening if c.laddr.port == server.port]
        assert ours and all(c.laddr.ip == "127.0.0.1" for c in ours)
        assert server.address == f"http://127.0.0.1:{server.port}/"


def test_without_a_page_no_state_is_taken_but_the_last():
    hub, taken = ViewHub(), []
    for step in range(50):
        hub.after_step(step, step == 49, lambda step=step: taken.append(step) or (lambda: "{}"))
    assert taken == [49]


def test_a_run_cut_short_sends_its_newest_state_as_the_final_one():
    hub = ViewHub()
    server = ViewServer(hub).__enter__()
    with connect(f"ws://127.0.0.1:{server.port}/ws") as socket:
        deadline = time.monotonic() + 10
        while hub.pages == 0 and time.monotonic() < deadline:
            time.sleep(0.01)
        hub.after_step(0, False, lambda: lambda: '{"step": 0}')
        assert json.loads(socket.recv(timeout=10)) == {"paused": False, "finished": False, "state": {"step": 0}}
        # The run stops here (Ctrl-C of a live run): leaving the server sends the same state as the final one.
        server.__exit__(None, None, None)
        assert json.loads(socket.recv(timeout=10)) == {"paused": False, "finished": True, "state": {"step": 0}}


def test_view_of_a_folder_without_view_states_exits_2_with_one_line(tmp_path, capsys):
    assert main(["view", str(tmp_path)]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and f"no {VIEW_STATES_FILE}" in error
    (tmp_path / VIEW_STATES_FILE).write_text('{"step": 0, "scene": {}}\nnot json\n')
    assert main(["view", str(tmp_path)]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "line 2 is not a step's state" in error


def test_run_with_view_goes_to_its_end_with_no_page_and_its_help_says_so(capsys):
    """A headless server's run is not held by its view: with no page, `run --view` ends as without one;
    waiting for the first page is what --view-wait asks, as --help says."""
    command = [sys.executable, "-m", "ptztrack.cli", "run", "--frames", "3", "--policy", "fix", "--view"]
    with _served(command) as (_, run):
        try:
            rest, _ = run.communicate(timeout=120)
        except subprocess.TimeoutExpired:
            run.kill()
            raise
    assert run.returncode == 0 and "MOTA" in rest
    for command in ("run", "follow"):
        with pytest.raises(SystemExit):
            main([command, "--help"])
        shown = " ".join(capsys.readouterr().out.split())
        assert "the run does not wait for a page" in shown and "--view-wait with --view: the run waits" in shown


@pytest.mark.slow
def test_run_with_view_wait_prints_the_address_starts_when_a_page_connects_and_sends_the_final_state():
    command = [sys.executable, "-m", "ptztrack.cli", "run", "--frames", "12", "--policy", "intg"]
    command += ["--view", "--view-wait"]
    with _served(command) as (address, run):
        with connect(address.replace("http://", "ws://") + "ws", max_size=None) as socket:
            messages = [json.loads(message) for message in socket]
        rest = run.stdout.read()
    assert run.returncode == 0
    assert messages[-1]["finished"] and messages[-1]["state"]["step"] == 11
    assert all(message["state"]["image_jpeg"] for message in messages)
    assert "MOTA" in rest


@pytest.mark.onvif
@pytest.mark.slow
def test_live_with_view_never_waits_for_a_page_which_may_join_and_leave(tmp_path):
    """A live camera's run does not wait for its view: with no page it runs to its end; a page that joins
    gets the camera's frames, and the run goes on to its last step once the page has left."""
    pytest.importorskip("ipycam", reason="the virtual ONVIF camera needs ipycam (pip install --no-deps ipycam==1.3.0)")
    from ptztrack.builders.recording import pets_scenario
    from ptztrack.builders.virtual_camera import virtual_onvif_camera

    camera, _ = virtual_onvif_camera(pets_scenario("hog"), 0.5, 0)
    with camera:
        command = [sys.executable, "-m", "ptztrack.cli", "live", "--camera", f"onvif://127.0.0.1:{camera.onvif_port}"]
        command += ["--calibration", "virtual", "--time-scale", "0.5", "--view"]
        with _served([*command, "--steps", "3"]) as (_, unwatched):
            unwatched.communicate(timeout=120)
        assert unwatched.returncode == 0
        with _served([*command, "--steps", "12", "--out", str(tmp_path / "live")]) as (address, run):
            with connect(address.replace("http://", "ws://") + "ws", max_size=None) as socket:
                states = [json.loads(socket.recv(timeout=60))["state"] for _ in range(2)]
            run.communicate(timeout=120)
    assert run.returncode == 0
    assert states[-1]["truth_m"] is None and all(state["image_jpeg"] for state in states)
    # Every picture used is a step of the run, its pose known, and the run went on after the page left.
    steps = (tmp_path / "live" / "steps.csv").read_text().splitlines()
    known = [row.split(",")[steps[0].split(",").index("pose_known")] == "1" for row in steps[1:]]
    assert len(known) == 12 and all(known) and (tmp_path / "live" / "episode.mp4").stat().st_size > 0
    lines = (tmp_path / "live" / VIEW_STATES_FILE).read_text().splitlines()
    assert 1 <= len(lines) <= 12 and all(json.loads(line)["image_jpeg"] is not None for line in lines)


@contextmanager
def _served(command: list[str]):
    """A ptztrack command that serves a view: (its page's address, the process)."""
    with subprocess.Popen(command, stdout=subprocess.PIPE, text=True) as process:
        assert process.stdout is not None
        line = ""
        while not line.startswith("view at http://127.0.0.1:"):
            line = process.stdout.readline()
            assert line, "the command ended without serving a view"
        yield line.split()[2], process


@pytest.fixture(scope="module")
def chromium():
    """Debian's Chromium through Playwright's sync API, or a one-line skip."""
    if not CHROMIUM.exists():
        pytest.skip(f"no Chromium at {CHROMIUM} (apt-get install chromium)")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        pytest.skip("no Playwright for Python (pip install playwright)")
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=str(CHROMIUM), headless=True)
        yield browser
        browser.close()


@contextmanager
def _page(chromium):
    """A page, and the errors and warnings of its console (with uncaught exceptions)."""
    page = chromium.new_page(viewport={"width": 1500, "height": 1000})
    problems: list[str] = []
    page.on("console", lambda m: problems.append(m.text) if m.type in ("error", "warning") else None)
    page.on("pageerror", lambda error: problems.append(str(error)))
    try:
        yield page, problems
    finally:
        page.close()


def _wait_for_step(page, step: int) -> None:
    page.wait_for_function(f"document.getElementById('step').dataset.step === '{step}'", timeout=TIMEOUT_MS)


def _step(message: str | bytes) -> int:
    return json.loads(message)["state"]["step"]


def _wait_until_finished(page) -> None:
    page.wait_for_function("document.getElementById('status').textContent === 'run finished'", timeout=TIMEOUT_MS)


def _screenshot(page, path: Path) -> None:
    page.screenshot(path=str(path), full_page=True)
    assert path.stat().st_size > 10_000
    if ARTEFACTS:
        Path(ARTEFACTS).mkdir(parents=True, exist_ok=True)
        shutil.copyfile(path, Path(ARTEFACTS) / path.name)


@pytest.mark.browser
def test_a_browser_draws_the_run_pauses_steps_resumes_and_keeps_the_final_state(chromium, tmp_path):
    scenario, world, policy, hub, observer = view_run()
    episodes = []
    run = threading.Thread(target=lambda: episodes.append(run_episode(scenario, policy, 0, world, observer=observer)))
    with _page(chromium) as (page, problems):
        with ViewServer(hub) as server:
            run.start()  # paused: it waits after its first step
            page.goto(server.address)
            _wait_for_step(page, 0)
            assert page.locator("#status").inner_text() == "paused"
            page.click("#single")
            _wait_for_step(page, 1)
            tracks_at_1 = page.locator("#map .track").count()
            assert page.locator("#heatmaps .cell").count() == world.grid.size
            assert page.locator("#camera image").count() == 1
            page.click("#resume")
            _wait_until_finished(page)
            run.join()
        # The server is gone; the page keeps the final state, without errors.
        time.sleep(0.5)
        (episode,) = episodes
        step = page.locator("#step")
        assert step.get_attribute("data-step") == str(FRAMES - 1)
        assert step.inner_text() == f"step {FRAMES} / {FRAMES}"
        assert tracks_at_1 == len(episode.tracks[1])
        assert page.locator("#map .track").count() == len(episode.tracks[-1]) > 0
        assert page.locator("#map .truth").count() == episode.truth.present[-1].sum()
        assert page.locator("#camera .detection").count() == len(episode.detections[-1])
        assert page.locator("#heatmaps .cell").count() == world.grid.size
        chosen = page.locator("#heatmaps .cell[stroke='red']")
        assert chosen.count() == 1 and chosen.get_attribute("id") == f"cell-{episode.actions[-1]}"
        assert page.locator("#status").inner_text() == "run finished"
        # Hovering the chosen action shows its reward term by term: every predicted track's share.
        page.hover(f"#cell-{episode.actions[-1]}")
        terms, last = page.locator("#terms").inner_text(), policy.last_terms
        row = int(np.flatnonzero(last.actions == episode.actions[-1])[0])
        assert f"reward {last.total_nats[row]:.4f} nats" in terms
        shares = dict(re.findall(r"track +(\d+) +([-\d.]+)", terms))
        assert set(shares) == {str(i) for i in last.track_ids} and len(last.track_ids) > 0
        for k, track_id in enumerate(last.track_ids):
            assert float(shares[str(track_id)]) == pytest.approx(last.track_nats[row, k], abs=1e-4)
        page.mouse.move(0, 0)  # the terms stay; the chosen cell shows its red mark again
        _screenshot(page, tmp_path / "web_view.png")
    assert problems == []


@pytest.mark.browser
@pytest.mark.slow
def test_a_browser_replays_a_run_folder_with_pause_step_and_resume(chromium, tmp_path):
    out = tmp_path / "run"
    assert main(["run", "--frames", "20", "--policy", "intg", "--out", str(out)]) == 0
    lines = (out / VIEW_STATES_FILE).read_text().splitlines()
    final = json.loads(lines[-1])
    # Slow enough that the pause comes before the end on a loaded machine
    command = [sys.executable, "-m", "ptztrack.cli", "view", str(out), "--steps-per-s", "2"]
    with _served(command) as (address, replay), _page(chromium) as (page, problems):
        page.goto(address)
        # The replay starts when the page opens, and the frame counter advances (a state may be skipped:
        # a new one is due only when the page has been sent the last)
        page.wait_for_function("Number(document.getElementById('step').dataset.step) >= 2", timeout=TIMEOUT_MS)
        page.click("#pause")
        page.wait_for_function("document.getElementById('status').textContent === 'paused'", timeout=TIMEOUT_MS)
        paused_at = int(page.locator("#step").get_attribute("data-step"))
        page.click("#single")
        _wait_for_step(page, paused_at + 1)
        time.sleep(1.5)  # three steps' time: paused, it stays
        assert page.locator("#step").get_attribute("data-step") == str(paused_at + 1)
        page.click("#resume")
        _wait_until_finished(page)
        replay.communicate()
        assert page.locator("#step").get_attribute("data-step") == "19"
        assert page.locator("#map .track").count() == len(final["tracks"]) > 0
        tracks_csv = (out / "tracks.csv").read_text().splitlines()[1:]
        assert len(final["tracks"]) == sum(line.startswith("19,") for line in tracks_csv)
        assert page.locator("#heatmaps .cell").count() == len(final["decision"]["reward_nats"])
        assert (
            page.locator("#heatmaps .cell[stroke='red']").get_attribute("id") == f"cell-{final['decision']['action']}"
        )
        _screenshot(page, tmp_path / "web_view_replay.png")
    assert replay.returncode == 0
    assert problems == []


@pytest.mark.browser
@pytest.mark.slow
def test_a_browser_follows_the_follow_camera(chromium, tmp_path):
    frames = 8
    command = [sys.executable, "-m", "ptztrack.cli", "follow", "--target", "19", "--frames", str(frames)]
    command += ["--out", str(tmp_path / "follow"), "--view", "--view-wait", *RECORDING]
    with _served(command) as (address, follow), _page(chromium) as (page, problems):
        # The steps of the states the page receives (two may come within one animation frame, so the
        # counter is read from the socket, not polled)
        received: list[int] = []
        page.on("websocket", lambda socket: socket.on("framereceived", lambda m: received.append(_step(m))))
        page.goto(address)
        _wait_until_finished(page)
        follow.communicate()
        assert received[0] == 0 and received[-1] == frames - 1 and received == sorted(set(received)), received
        assert page.locator("#step").get_attribute("data-step") == str(frames - 1)
        assert page.locator("#camera image").count() == 1
        # The particle filter's box (one measurement a step), the track and where the controller wants the person
        assert page.locator("#camera .detection rect").count() == 1
        assert page.locator("#camera .track").count() == 1 and page.locator("#map .track").count() == 1
        assert page.locator("#camera .target-point").count() == 1
        assert page.locator("#heatmaps .cell").count() == 0 and page.locator("#no-grid").is_visible()
        _screenshot(page, tmp_path / "web_view_follow.png")
    assert follow.returncode == 0
    assert problems == []


@pytest.mark.slow
@pytest.mark.browser
def test_a_browser_draws_every_camera_of_a_network_beside_the_one_map(chromium, tmp_path):
    """A network's states (:class:`NetworkViewState`), replayed: every camera's picture in a panel of its
    own, the deciding camera's marked, each camera's field of view on the one map, and the decision's
    reward map. Two cameras of one synthetic run stand in for a live network's (the page draws what the
    states say; tests/test_loop_live_onvif.py checks a live network's states)."""
    frames = 6
    scenario = scenario_from_dict({"frames": frames})
    world = episode_world(scenario, 0)
    policy = make_policy("smpl", scenario, world)
    network = NetworkViewState([ViewState(world, policy, frames, "network", view_renderer(world)) for _ in range(2)])
    kept: list = []
    observe = network.observer(keep=kept)
    # The cameras take turns: camera k's pictures are the run's steps k, k + 2, ...
    run_episode(scenario, policy, 0, world, observer=lambda step, context, record: observe(
        step, context, {**record, "camera": step % 2}
    ))  # fmt: skip
    out = tmp_path / "network"
    out.mkdir()
    network.write(out / VIEW_STATES_FILE, kept)
    command = [sys.executable, "-m", "ptztrack.cli", "view", str(out), "--steps-per-s", "5"]
    with _served(command) as (address, replay), _page(chromium) as (page, problems):
        page.goto(address)
        _wait_until_finished(page)
        replay.communicate()
        assert page.locator("#camera-panel").is_hidden()
        assert page.locator(".network-camera").count() == 2
        assert page.locator(".network-camera image").count() == 2
        assert page.locator(".network-camera.deciding").count() == 1
        assert page.locator("#map .footprint").count() == 2
        assert page.locator("#heatmaps .cell").count() == world.grid.size
        _screenshot(page, tmp_path / "web_view_network.png")
    assert replay.returncode == 0
    assert problems == []
