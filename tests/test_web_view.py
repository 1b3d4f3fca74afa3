"""The live web view: the server listens on 127.0.0.1 only, and a real browser draws a run, step by step."""

import os
import shutil
import threading
import time
from pathlib import Path

import psutil
import pytest

from ptztrack.builders.episode import episode_world, make_policy, run_episode
from ptztrack.config import scenario_from_dict
from ptztrack.evaluate.view_state import ViewState
from ptztrack.evaluate.web_view import ViewHub, ViewServer

CHROMIUM = Path("/usr/bin/chromium")  # Debian's (apt-get install chromium); Playwright's own is not downloadable here
SCREENSHOT_COPY = Path(os.environ.get("PTZTRACK_VIEW_SCREENSHOT", "/work/t19/screenshot.png"))
FRAMES = 30
TIMEOUT_MS = 60_000


def view_run(frames: int = FRAMES, seed: int = 0, paused: bool = True):
    """A synthetic smpl run's world, policy and hub (not started)."""
    scenario = scenario_from_dict({"frames": frames})
    world = episode_world(scenario, seed)
    policy = make_policy("smpl", scenario, world)
    return scenario, world, policy, ViewHub(ViewState(world, policy, frames, "smpl"), paused=paused)


def test_the_view_listens_on_127_0_0_1_only():
    *_, hub = view_run()
    with ViewServer(hub) as server:
        listening = [
            c for c in psutil.Process().net_connections(kind="inet") if c.status == psutil.CONN_LISTEN and c.laddr
        ]
        ours = [c for c in listening if c.laddr.port == server.port]
        assert ours and all(c.laddr.ip == "127.0.0.1" for c in ours)
        assert server.address == f"http://127.0.0.1:{server.port}/"


def _browser():
    """Playwright's sync API and Debian's Chromium, or a one-line skip."""
    if not CHROMIUM.exists():
        pytest.skip(f"no Chromium at {CHROMIUM} (apt-get install chromium)")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        pytest.skip("no Playwright for Python (pip install playwright)")
    return sync_playwright


@pytest.mark.browser
def test_a_browser_draws_the_run_pauses_steps_resumes_and_keeps_the_final_state(tmp_path):
    sync_playwright = _browser()
    scenario, world, policy, hub = view_run()
    episodes = []
    run = threading.Thread(target=lambda: episodes.append(run_episode(scenario, policy, 0, world, observer=hub)))
    problems: list[str] = []
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=str(CHROMIUM), headless=True)
        page = browser.new_page(viewport={"width": 1500, "height": 1000})
        page.on("console", lambda m: problems.append(m.text) if m.type in ("error", "warning") else None)
        page.on("pageerror", lambda error: problems.append(str(error)))
        with ViewServer(hub) as server:
            run.start()  # paused: it waits after its first step
            page.goto(server.address)
            step = page.locator("#step")
            page.wait_for_function("document.getElementById('step').dataset.step === '0'", timeout=TIMEOUT_MS)
            assert page.locator("#status").inner_text() == "paused"
            page.click("#single")
            page.wait_for_function("document.getElementById('step').dataset.step === '1'", timeout=TIMEOUT_MS)
            tracks_at_1 = page.locator("#map .track").count()
            assert page.locator("#heatmaps .cell").count() == world.grid.size
            assert page.locator("#camera image").count() == 1
            page.click("#resume")
            page.wait_for_function(
                "document.getElementById('status').textContent === 'run finished'", timeout=TIMEOUT_MS
            )
            run.join()
        # The server is gone; the page keeps the final state, without errors.
        time.sleep(0.5)
        (episode,) = episodes
        assert step.get_attribute("data-step") == str(FRAMES - 1)
        assert step.inner_text() == f"step {FRAMES} / {FRAMES}"
        assert tracks_at_1 == len(episode.tracks[1])
        assert page.locator("#map .track").count() == len(episode.tracks[-1]) > 0
        assert page.locator("#map .truth").count() == episode.truth.present[-1].sum()
        assert page.locator("#heatmaps .cell").count() == world.grid.size
        chosen = page.locator("#heatmaps .cell[stroke='red']")
        assert chosen.count() == 1 and chosen.get_attribute("id") == f"cell-{episode.actions[-1]}"
        assert page.locator("#status").inner_text() == "run finished"
        screenshot = tmp_path / "web_view.png"
        page.screenshot(path=str(screenshot), full_page=True)
        browser.close()
    assert problems == []
    assert screenshot.stat().st_size > 10_000
    SCREENSHOT_COPY.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(screenshot, SCREENSHOT_COPY)


def test_run_with_view_prints_the_address_starts_when_a_page_connects_and_sends_the_final_state():
    import json
    import subprocess
    import sys

    from websockets.sync.client import connect

    command = [sys.executable, "-m", "ptztrack.cli", "run", "--frames", "12", "--policy", "intg", "--view"]
    with subprocess.Popen(command, stdout=subprocess.PIPE, text=True) as run:
        assert run.stdout is not None
        line = run.stdout.readline()
        assert line.startswith("view at http://127.0.0.1:")
        address = line.split()[2]
        with connect(address.replace("http://", "ws://") + "ws", max_size=None) as socket:
            states = [json.loads(message) for message in socket]
        rest = run.stdout.read()
    assert run.returncode == 0
    assert states[-1]["finished"] and states[-1]["step"] == 11
    assert "MOTA" in rest
