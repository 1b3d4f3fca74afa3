"""What the live web view costs a run: steps per second with and without it, in one process.

The same synthetic episode (``--policy``, ``--frames``, seed 0) runs
``--repeats`` times alternately without a view and with one, served on
127.0.0.1 with a page connected: a WebSocket client in another process (as
a browser is) that reads every state it is sent and parses its JSON. Both
are timed from the end of the first step (the viewed run waits there for
its page) to the last, in wall time and in this process's CPU time (the
server's thread included). It prints the best of each and the slowdown;
the issue asks for less than 10 %.

    python benchmarks/view_overhead.py [--policy smpl] [--frames 200] [--repeats 5]
"""

import argparse
import subprocess
import sys
import time

from ptztrack.builders.episode import episode_world, make_policy, run_episode
from ptztrack.config import scenario_from_dict
from ptztrack.evaluate.video import view_renderer
from ptztrack.evaluate.view_state import ViewState
from ptztrack.evaluate.web_view import ViewHub, ViewServer

PAGE = """
import json, sys
from websockets.sync.client import connect
states = 0
with connect(sys.argv[1], max_size=None) as socket:
    for message in socket:
        json.loads(message)
        states += 1
print(states)
"""


def timed_run(scenario, policy_name: str, view: bool) -> tuple[float, float, int]:
    """(wall s, CPU s, states sent) from the end of the first step to the end of the run."""
    world = episode_world(scenario, 0)
    policy = make_policy(policy_name, scenario, world)
    started = [0.0, 0.0]

    def mark(step: int) -> None:
        if step == 0:
            started[:] = time.perf_counter(), time.process_time()

    if not view:
        run_episode(scenario, policy, 0, world, observer=lambda step, context, record: mark(step))
        return time.perf_counter() - started[0], time.process_time() - started[1], 0
    hub = ViewHub(paused=True, resume_on_connect=True)
    observe = ViewState(world, policy, scenario.frames, policy_name, view_renderer(world)).observer(hub.after_step)

    def observer(step, context, record):
        observe(step, context, record)
        mark(step)

    with ViewServer(hub) as server:
        address = f"ws://127.0.0.1:{server.port}/ws"
        with subprocess.Popen([sys.executable, "-c", PAGE, address], stdout=subprocess.PIPE, text=True) as page:
            run_episode(scenario, policy, 0, world, observer=observer)
            wall_s, cpu_s = time.perf_counter() - started[0], time.process_time() - started[1]
            states = int(page.communicate()[0])
    return wall_s, cpu_s, states


def main() -> None:
    arguments = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    arguments.add_argument("--policy", default="smpl")
    arguments.add_argument("--frames", type=int, default=200)
    arguments.add_argument("--repeats", type=int, default=5)
    args = arguments.parse_args()
    scenario = scenario_from_dict({"frames": args.frames})
    timed_run(scenario, args.policy, False)  # compile numba's functions before timing
    plain, viewed = [], []
    for _ in range(args.repeats):
        plain.append(timed_run(scenario, args.policy, False))
        viewed.append(timed_run(scenario, args.policy, True))
    steps = args.frames - 1
    for name, runs in (("without", plain), ("with", viewed)):
        print(f"{name:<8} steps/s " + " ".join(f"{steps / wall_s:6.1f}" for wall_s, _, _ in runs))
    best_plain, best_viewed = min(plain), min(viewed)
    print(f"{args.policy}, {steps} steps timed, best of {args.repeats} (interleaved)")
    for name, (wall_s, cpu_s, states) in (("without a view", best_plain), ("with a view", best_viewed)):
        print(f"{name:<15} {steps / wall_s:7.1f} steps/s  {1e3 * cpu_s / steps:6.2f} ms CPU a step  {states} states")
    rate_down, cpu_up = 1 - best_plain[0] / best_viewed[0], best_viewed[1] / best_plain[1] - 1
    print(f"steps/s down by {rate_down:.1%}; CPU a step up by {cpu_up:.1%}")


if __name__ == "__main__":
    main()
