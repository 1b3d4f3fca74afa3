"""Cost of one closed-loop step on PETS 2009 with the HOG detector, split by role.

Runs the loop of :func:`ptztrack.loop.run_loop` on the built-in PETS
scenario with OpenCV's HOG detector (``pets_scenario("hog")``, beta 1, seed
0) for the policies ``fix``, ``intg`` and ``smpl``, and times each role of a
step with ``time.perf_counter``:

* read: decoding the step's recorded frame (``RecordedVideo.frame``);
* warp: rendering the 160 x 120 virtual view from it (``VirtualPTZ.render``);
* detect: HOG on the view, 6x upsampling and non-maximum suppression
  included (``HogPeopleDetector.boxes``), then ``feet_and_height_px``;
* track: the tracker's ``predict`` and ``update``;
* decide: the reachable actions and ``policy.choose``.

The roles are the backend's and the detector's own pieces
(``RecordedPTZ.image`` is ``video.frame`` -> ``virtual.render``; the HOG
detector's ``detect`` is ``boxes`` -> ``feet_and_height_px``), called in the
same order with the same seeds, so the timed steps are the episode's real
steps. Building the world and the
policy (the patrolling term's map) is set-up, not timed. The first
``--warmup`` steps (default 5) run but are excluded, so that Numba's
compilation and the first calls into OpenCV are not counted; the next
``--steps`` steps are timed. ``total`` is the wall time of the timed steps
per step (the parts cover all but the loop's own bookkeeping). The
process's CPU time over the same steps is recorded too: well below the wall
time, another process took the core and the figures are too high (a busy
virtual machine's host slows CPU time as well, so a quiet check is no
guarantee: take the fastest of a few runs).

Single-threaded: OMP, OpenBLAS, MKL and Numba are limited to one thread
through their environment variables (OMP_NUM_THREADS, OPENBLAS_NUM_THREADS,
MKL_NUM_THREADS, NUMBA_NUM_THREADS = 1, set before NumPy and Numba load) and
OpenCV through ``cv2.setNumThreads(1)``.

    python benchmarks/step_cost.py [--steps N] [--warmup N] [--json PATH]
"""

import os

for _variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_variable] = "1"

import argparse  # noqa: E402  (the thread counts must be set before NumPy, Numba and OpenCV load)
import time  # noqa: E402
from functools import partial  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

from ptztrack.builders.episode import make_policy, make_tracker  # noqa: E402
from ptztrack.builders.world import build_world  # noqa: E402
from ptztrack.config import pets_scenario  # noqa: E402
from ptztrack.detect.hog import HogPeopleDetector, feet_and_height_px  # noqa: E402
from ptztrack.files import write_json  # noqa: E402
from ptztrack.loop import episode_seeds  # noqa: E402
from ptztrack.types import DecisionContext, Detections  # noqa: E402

cv2.setNumThreads(1)

PARTS = ("read", "warp", "detect", "track", "decide")
POLICIES = ("fix", "intg", "smpl")


def step_costs(scenario, policy_name: str, steps: int, warmup: int, seed: int = 0) -> dict:
    """Seconds spent in each part over ``steps`` steps after ``warmup`` untimed ones, and the wall time.

    The loop is run_loop's (a perfect camera, the commanded pose) with the backend's image split
    into reading and warping.
    """
    scene_seed, _detector_seed, policy_seed, _landing_seed, _tracker_seed = episode_seeds(seed)
    world = build_world(scenario, np.random.default_rng(scene_seed))
    backend, detector = world.backend, world.detector
    if not isinstance(detector, HogPeopleDetector):
        raise ValueError("the scenario must use the HOG detector")
    available = world.truth.positions_m.shape[0]
    if warmup + steps > available:
        raise ValueError(f"{warmup} + {steps} steps asked, the recording has {available}")
    policy = make_policy(policy_name, scenario, world)
    tracker = make_tracker(None, scenario, world)
    policy_rng = np.random.default_rng(policy_seed)
    grid = world.grid

    clock = time.perf_counter
    action = world.start_action
    seconds = dict.fromkeys(PARTS, 0.0)
    actions = []
    start, cpu_start = clock(), time.process_time()
    for step in range(warmup + steps):
        if step == warmup:
            seconds = dict.fromkeys(PARTS, 0.0)
            start, cpu_start = clock(), time.process_time()
        t0 = clock()
        predicted = tracker.predict()
        t1 = clock()
        action = policy.choose(DecisionContext(step, action, grid.reachable(action), predicted, policy_rng))
        pose = grid.poses[action]
        t2 = clock()
        frame = backend.video.frame(int(backend.scene.video_frame[step]))
        t3 = clock()
        view = backend.virtual.render(frame, pose)
        t4 = clock()
        boxes, scores = detector.boxes(view)
        feet_px, height_px = feet_and_height_px(boxes)
        detections = Detections(feet_px, height_px, np.full(len(feet_px), -1), scores)
        t5 = clock()
        tracker.update(detections, pose, partial(backend.image, step, pose))
        t6 = clock()
        seconds["track"] += (t1 - t0) + (t6 - t5)
        seconds["decide"] += t2 - t1
        seconds["read"] += t3 - t2
        seconds["warp"] += t4 - t3
        seconds["detect"] += t5 - t4
        actions.append(int(action))
    wall, cpu = clock() - start, time.process_time() - cpu_start
    return {"seconds": seconds, "wall": wall, "cpu": cpu, "actions": actions}


def row(policy_name: str, costs: dict, steps: int, warmup: int) -> dict:
    per_step_ms = {part: 1e3 * costs["seconds"][part] / steps for part in PARTS}
    total_ms = 1e3 * costs["wall"] / steps
    return {
        "policy": policy_name,
        "steps": steps,
        "warmup": warmup,
        **{f"{part}_ms": per_step_ms[part] for part in PARTS},
        "total_ms": total_ms,
        "other_ms": total_ms - sum(per_step_ms.values()),
        "cpu_ms": 1e3 * costs["cpu"] / steps,
        "steps_per_s": 1e3 / total_ms,
        **{f"{part}_share": per_step_ms[part] / total_ms for part in PARTS},
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=100, help="timed steps per policy")
    parser.add_argument("--warmup", type=int, default=5, help="untimed steps run first")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", type=Path, help="write the rows here")
    args = parser.parse_args()
    if args.steps < 1 or args.warmup < 0:
        parser.error("--steps must be at least 1 and --warmup at least 0")
    scenario = pets_scenario("hog", **{"control.beta": 1.0})
    print(
        f"PETS 2009, HOG detector, beta 1, seed {args.seed}: ms per step over {args.steps} steps "
        f"after {args.warmup} warm-up steps, one thread"
    )
    header = f"{'policy':<8}" + "".join(f"{part:>8}" for part in PARTS) + f"{'total':>8}{'steps/s':>9}"
    header += "".join(f"{part + ' %':>10}" for part in PARTS)
    print(header, flush=True)
    rows = []
    for policy_name in POLICIES:
        costs = step_costs(scenario, policy_name, args.steps, args.warmup, args.seed)
        figures = row(policy_name, costs, args.steps, args.warmup)
        rows.append(figures)
        line = f"{policy_name:<8}" + "".join(f"{figures[part + '_ms']:>8.2f}" for part in PARTS)
        line += f"{figures['total_ms']:>8.2f}{figures['steps_per_s']:>9.1f}"
        line += "".join(f"{100 * figures[part + '_share']:>10.1f}" for part in PARTS)
        print(line, flush=True)
    print("total: wall time per timed step; the rest of it (other_ms in --json) is the loop's bookkeeping")
    busy = [figures["policy"] for figures in rows if figures["cpu_ms"] < 0.95 * figures["total_ms"]]
    if busy:
        print(f"warning: CPU time below 95 % of the wall time for {', '.join(busy)}: the machine was busy")
    if args.json:
        write_json(args.json, rows)


if __name__ == "__main__":
    main()
