"""What the live web view costs a run: steps per second with and without it, in one process.

The same synthetic episode (``--policy``, ``--frames``, seed 0) runs
``--repeats`` times alternately without a view and with one, served on
127.0.0.1 with a page connected in another process (as a browser is):
``--page websocket``, a client that parses every state it is sent, or
``--page chromium``, Debian's Chromium drawing them. Both
are timed from the end of the first step (the viewed run waits there for
its page) to the last, in wall time and in this process's CPU time (the
server's thread included). It prints the best of each and the slowdown;
the issue asks for less than 10 %.

    python benchmarks/view_overhead.py [--policy smpl] [--frames 200] [--repeats 5] [--page websocket|chromium]
"""

import argparse
import subprocess
import sys
import time

from ptztrack.builders.episode import episode_world, make_policy, run_episode
from ptztrack.config import scenario_from_dict
from ptztrack.view.video import view_renderer
from ptztrack.view.view_state import ViewState
from ptztrack.view.web_view import ViewHub, ViewServer

# The page, in another process as a browser is: a WebSocket client that parses every state, or Debian's
# Chromium through Playwright drawing them (its driver in that process too, away from the run's GIL).
PAGES = {
    "websocket": """
import json, sys
from websockets.sync.client import connect
with connect(sys.argv[1].replace("http://", "ws://") + "ws", max_size=None) as socket:
    for message in socket:
        json.loads(message)
""",
    "chromium": """
import sys
from playwright.sync_api import sync_playwright
with sync_playwright() as playwright:
    browser = playwright.chromium.launch(executable_path="/usr/bin/chromium", headless=True)
    page = browser.new_page(viewport={"width": 1500, "height": 1000})
    page.goto(sys.argv[1])
    # Polled every 250 ms: Playwright's default polls every animation frame, which keeps Chromium drawing
    page.wait_for_function(
        "document.getElementById('status').textContent === 'run finished'", polling=250, timeout=600_000
    )
    browser.close()
""",
}


def timed_run(scenario, policy_name: str, page: str | None) -> tuple[float, float, int]:
    """(wall s, CPU s, states published) from the end of the first step to the end of the run, with
    ``page`` (a key of PAGES) watching, or without a view."""
    world = episode_world(scenario, 0)
    policy = make_policy(policy_name, scenario, world)
    started = [0.0, 0.0]

    def mark(step: int) -> None:
        if step == 0:
            started[:] = time.perf_counter(), time.process_time()

    if page is None:
        run_episode(scenario, policy, 0, world, observer=lambda step, context, record: mark(step))
        return time.perf_counter() - started[0], time.process_time() - started[1], 0
    hub = ViewHub(paused=True, resume_on_connect=True)
    observe = ViewState(world, policy, scenario.frames, policy_name, view_renderer(world)).observer(hub.after_step)

    def observer(step, context, record):
        observe(step, context, record)
        mark(step)

    with ViewServer(hub) as server, subprocess.Popen([sys.executable, "-c", PAGES[page], server.address]):
        run_episode(scenario, policy, 0, world, observer=observer)
        wall_s, cpu_s = time.perf_counter() - started[0], time.process_time() - started[1]
    return wall_s, cpu_s, hub.published


def main() -> None:
    arguments = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    arguments.add_argument("--policy", default="smpl")
    arguments.add_argument("--frames", type=int, default=200)
    arguments.add_argument("--repeats", type=int, default=5)
    arguments.add_argument("--page", choices=PAGES, default="websocket")
    args = arguments.parse_args()
    scenario = scenario_from_dict({"frames": args.frames})
    timed_run(scenario, args.policy, None)  # compile numba's functions before timing
    plain, viewed = [], []
    for _ in range(args.repeats):
        plain.append(timed_run(scenario, args.policy, None))
        viewed.append(timed_run(scenario, args.policy, args.page))
    steps = args.frames - 1
    for name, runs in (("without", plain), ("with", viewed)):
        print(f"{name:<8} steps/s " + " ".join(f"{steps / wall_s:6.1f}" for wall_s, _, _ in runs))
    best_plain, best_viewed = min(plain), min(viewed)
    print(f"{args.policy}, {steps} steps timed, best of {args.repeats} (interleaved), page: {args.page}")
    for name, (wall_s, cpu_s, states) in (("without a view", best_plain), ("with a view", best_viewed)):
        print(f"{name:<15} {steps / wall_s:7.1f} steps/s  {1e3 * cpu_s / steps:6.2f} ms CPU a step  {states} states")
    rate_down, cpu_up = 1 - best_plain[0] / best_viewed[0], best_viewed[1] / best_plain[1] - 1
    print(f"steps/s down by {rate_down:.1%}; CPU a step up by {cpu_up:.1%}")


if __name__ == "__main__":
    main()
