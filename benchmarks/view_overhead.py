"""What the live web view costs a run: steps per second with and without it, in one process.

The same synthetic episode (``--policy``, ``--frames``, seed 0) runs
``--repeats`` times alternately without a view and with one, served on
127.0.0.1 with a page connected (a WebSocket client that takes every state
it is sent, as a browser does). It prints the best steps per second of each
and the slowdown; the issue asks for less than 10 %.

    python benchmarks/view_overhead.py [--policy smpl] [--frames 200] [--repeats 3]
"""

import argparse
import asyncio
import threading
import time

from websockets.asyncio.client import connect

from ptztrack.builders.episode import episode_world, make_policy, run_episode
from ptztrack.config import scenario_from_dict
from ptztrack.evaluate.view_state import ViewState
from ptztrack.evaluate.web_view import ViewHub, ViewServer


def steps_per_s(scenario, policy_name: str, view: bool) -> float:
    world = episode_world(scenario, 0)
    policy = make_policy(policy_name, scenario, world)
    steps = scenario.frames
    if not view:
        started = time.perf_counter()
        run_episode(scenario, policy, 0, world)
        return steps / (time.perf_counter() - started)
    hub = ViewHub(ViewState(world, policy, steps, policy_name), paused=True, resume_on_connect=True)
    with ViewServer(hub) as server:
        page = threading.Thread(target=asyncio.run, args=(_page(server.port),))
        page.start()
        # Timed from the page's arrival: the run waits for it.
        started = [time.perf_counter()]

        def observer(step, context, record):
            hub(step, context, record)
            if step == 0:
                started[0] = time.perf_counter()

        run_episode(scenario, policy, 0, world, observer=observer)
        rate = (steps - 1) / (time.perf_counter() - started[0])
    page.join()
    return rate


async def _page(port: int) -> None:
    async with connect(f"ws://127.0.0.1:{port}/ws", max_size=None) as socket:
        async for _ in socket:
            pass


def main() -> None:
    arguments = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    arguments.add_argument("--policy", default="smpl")
    arguments.add_argument("--frames", type=int, default=200)
    arguments.add_argument("--repeats", type=int, default=3)
    args = arguments.parse_args()
    scenario = scenario_from_dict({"frames": args.frames})
    steps_per_s(scenario, args.policy, False)  # compile numba's functions before timing
    plain, viewed = [], []
    for _ in range(args.repeats):
        plain.append(steps_per_s(scenario, args.policy, False))
        viewed.append(steps_per_s(scenario, args.policy, True))
    best_plain, best_viewed = max(plain), max(viewed)
    print(f"{args.policy}, {args.frames} steps, best of {args.repeats}")
    print(f"without a view  {best_plain:8.1f} steps/s")
    print(f"with a view     {best_viewed:8.1f} steps/s")
    print(f"slowdown        {1 - best_viewed / best_plain:8.1%}")


if __name__ == "__main__":
    main()
