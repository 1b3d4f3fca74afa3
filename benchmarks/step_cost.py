"""Cost of one closed-loop step on PETS 2009 with the HOG detector, split by role, and today's
detector beside it.

Runs the loop of :func:`ptztrack.loop.simulated.run_loop` on the built-in PETS
scenario with OpenCV's HOG detector (``pets_scenario("hog")``, beta 1, seed
0) for the strategies of Table 4 (``fix``, ``patrol``, ``random``, ``intg``,
``smpl``), and times each role of a step with ``time.perf_counter``:

* read: decoding the step's recorded frame (``RecordedVideo.frame``);
* warp: rendering the 160 x 120 virtual view from it (``VirtualPTZ.render``;
  the sampling map of a pose is kept from its first view on);
* detect: HOG on the view where a standing person can be (the scenario's
  ``hog_search`` 'ground', :class:`ptztrack.detect.hog.GroundSearch`), 6x
  upsampling and non-maximum suppression included
  (``HogPeopleDetector.boxes``, without the memo of views seen before that
  ``detect`` keeps), then ``feet_and_height_px``;
* track: the tracker's ``predict`` and ``update``;
* decide: the reachable actions and ``policy.choose``.

The roles are the backend's and the detector's own pieces
(``RecordedPTZ.image`` is ``video.frame`` -> ``virtual.render``; the HOG
detector's ``detect`` is ``boxes`` -> ``feet_and_height_px``), called in the
same order with the same seeds, so the timed steps are the episode's real
steps. Building the world and the policy (the patrolling term's map) is
set-up, not timed. The first ``--warmup`` steps (default 5) run but are
excluded, so that Numba's compilation and the first calls into OpenCV are
not counted; the next ``--steps`` steps are timed. ``total`` is the wall
time of the timed steps per step (the parts cover all but the loop's own
bookkeeping).

Today's detector (``hog_search`` 'image': every window of the pyramid,
OpenCV's ``detectMultiScale``) runs on every view right after the new one,
outside the step's time: ``today detect`` is its time on the same views and
``today steps/s`` the loop's rate had it detected instead (total - detect +
today's detect). Both detectors' boxes are scored against the annotations
on every timed view: recall over the annotated people wholly in view and
hidden at most ``recording.occluded_above``, precision over the detections;
a detection and a person match, one to one, when its feet lie within
``MATCH_FRACTION_OF_HEIGHT`` (0.3) of the person's height from theirs (the
rule of :mod:`ptztrack.detect.recall_fit`); a detection of a person partly
out of view or hidden is no false positive.

The process's CPU time over the same steps is recorded too (the new loop's
and today's detector's apart): well below the wall time, another process
took the core and the figures are too high (a busy virtual machine's host
slows CPU time as well, so a quiet check is no guarantee). Each policy runs
``--repeats`` times (default 2), interleaved, and its fastest run is kept,
for the new loop and today's detector each.

Single-threaded: OMP, OpenBLAS, MKL and Numba are limited to one thread
through their environment variables (OMP_NUM_THREADS, OPENBLAS_NUM_THREADS,
MKL_NUM_THREADS, NUMBA_NUM_THREADS = 1, set before NumPy and Numba load) and
OpenCV through ``cv2.setNumThreads(1)``; ``--threads N`` gives OpenCV N
threads instead (both detectors spread their pyramid levels over them), the
rest of the step staying on one.

    python benchmarks/step_cost.py [--steps N] [--warmup N] [--repeats N] [--threads N] [--json PATH]
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
from scipy.optimize import linear_sum_assignment  # noqa: E402

from ptztrack.builders.episode import make_policy, make_tracker  # noqa: E402
from ptztrack.builders.recording import pets_scenario  # noqa: E402
from ptztrack.builders.world import build_world  # noqa: E402
from ptztrack.detect.hog import HogPeopleDetector, feet_and_height_px  # noqa: E402
from ptztrack.detect.recall_fit import MATCH_FRACTION_OF_HEIGHT  # noqa: E402
from ptztrack.files import write_json  # noqa: E402
from ptztrack.geometry.ptz import PTZCamera, inside_image  # noqa: E402
from ptztrack.loop.streams import episode_streams  # noqa: E402
from ptztrack.types import DecisionContext, Detections, PeopleInView  # noqa: E402

cv2.setNumThreads(1)

PARTS = ("read", "warp", "detect", "track", "decide")
POLICIES = ("fix", "patrol", "rnd", "intg", "smpl")
# Per detector and view: people found, people (wholly in view, hidden at most occluded_above), detections
# of somebody, detections; "sized": a match also needs the detection's height within SIZE_FACTOR of the person's.
COUNTS = ("found", "found_sized", "people", "true", "true_sized", "detections")
SIZE_FACTOR = 1.5


def matches(people: PeopleInView, feet_px, height_px, camera: PTZCamera, max_hidden: float) -> np.ndarray:
    """COUNTS of one view: detections (feet (K, 2), heights (K,)) matched one to one to the annotated
    people whose feet are in the image, each within MATCH_FRACTION_OF_HEIGHT of its height."""
    visible = people.in_view & (people.hidden <= max_hidden)
    candidates = np.flatnonzero(inside_image(camera, np.nan_to_num(people.feet_px, nan=-1.0)) | visible)
    if len(candidates) == 0 or len(feet_px) == 0:
        return np.array([0, 0, visible.sum(), 0, 0, len(feet_px)])
    distance = np.linalg.norm(people.feet_px[candidates, None] - feet_px[None], axis=-1)
    far = distance > MATCH_FRACTION_OF_HEIGHT * people.height_px[candidates, None]
    ratio = height_px[None] / people.height_px[candidates, None]
    counts = []
    for apart in (far, far | (ratio > SIZE_FACTOR) | (ratio < 1 / SIZE_FACTOR)):
        rows, columns = linear_sum_assignment(np.where(apart, 1e9, distance))
        matched = ~apart[rows, columns]
        counts.append((visible[candidates[rows[matched]]].sum(), matched.sum()))
    (found, true), (found_sized, true_sized) = counts
    return np.array([found, found_sized, visible.sum(), true, true_sized, len(feet_px)])


def step_costs(scenario, reference: HogPeopleDetector, policy_name: str, steps: int, warmup: int, seed: int) -> dict:
    """Seconds spent in each part over ``steps`` steps after ``warmup`` untimed ones, the wall and CPU
    times, today's detector's (``reference``) on the same views, and both detectors' counts.

    The loop is the simulated loop's (a perfect camera, the commanded pose) with the backend's image split
    into reading and warping.
    """
    streams = episode_streams(seed)
    world = build_world(scenario, np.random.default_rng(streams.scene), model_seed=streams.detector_model)
    backend, detector = world.backend, world.detector
    if not isinstance(detector, HogPeopleDetector) or detector.search is None:
        raise ValueError("the scenario must use the HOG detector with a ground search")
    available = world.truth.positions_m.shape[0]
    if warmup + steps > available:
        raise ValueError(f"{warmup} + {steps} steps asked, the recording has {available}")
    policy = make_policy(policy_name, scenario, world)
    tracker = make_tracker(None, scenario, world)
    policy_rng = np.random.default_rng(streams.policy)
    grid = world.grid
    max_hidden = scenario.required_recording("the detectors' scores").occluded_above

    clock, cpu_clock = time.perf_counter, time.process_time
    action = world.start_action
    seconds = dict.fromkeys(PARTS, 0.0)
    reference_wall = reference_cpu = 0.0
    counts = {"ground": np.zeros(len(COUNTS), int), "image": np.zeros(len(COUNTS), int)}
    zooms = []
    start, cpu_start = clock(), cpu_clock()
    for step in range(warmup + steps):
        if step == warmup:
            seconds = dict.fromkeys(PARTS, 0.0)
            reference_wall = reference_cpu = 0.0
            start, cpu_start = clock(), cpu_clock()
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
        boxes, scores = detector.boxes(view, pose)
        feet_px, height_px = feet_and_height_px(boxes)
        detections = Detections(feet_px, height_px, np.full(len(feet_px), -1), scores)
        t5 = clock()
        tracker.update(detections, pose, partial(backend.image, step, pose))
        t6 = clock()
        cpu_before = cpu_clock()
        reference_boxes, _ = reference.boxes(view)
        t7, cpu_after = clock(), cpu_clock()
        seconds["track"] += (t1 - t0) + (t6 - t5)
        seconds["decide"] += t2 - t1
        seconds["read"] += t3 - t2
        seconds["warp"] += t4 - t3
        seconds["detect"] += t5 - t4
        reference_wall += t7 - t6
        reference_cpu += cpu_after - cpu_before
        if step >= warmup:
            people = backend.people(step, pose)
            counts["ground"] += matches(people, feet_px, height_px, world.camera, max_hidden)
            counts["image"] += matches(people, *feet_and_height_px(reference_boxes), world.camera, max_hidden)
            zooms.append(pose[2])
    wall = clock() - start - reference_wall
    cpu = cpu_clock() - cpu_start - reference_cpu
    return {
        "seconds": seconds,
        "wall": wall,
        "cpu": cpu,
        "reference_wall": reference_wall,
        "reference_cpu": reference_cpu,
        "counts": counts,
        "zoom": float(np.mean(zooms)),
    }


def quality(counts: dict) -> dict:
    """Recall and precision (feet and sized) of the new detector and today's from their COUNTS."""
    rates = {}
    for prefix in ("", "reference_"):
        for suffix in ("", "_sized"):
            rates[f"{prefix}recall{suffix}"] = counts[f"{prefix}found{suffix}"] / max(counts[f"{prefix}people"], 1)
            rates[f"{prefix}precision{suffix}"] = counts[f"{prefix}true{suffix}"] / max(
                counts[f"{prefix}detections"], 1
            )
    return rates


def row(policy_name: str, costs: dict, reference: dict, steps: int, warmup: int) -> dict:
    """The figures of a policy: its fastest run (``costs``) and today's detector's fastest (``reference``)."""
    per_step_ms = {part: 1e3 * costs["seconds"][part] / steps for part in PARTS}
    total_ms = 1e3 * costs["wall"] / steps
    reference_detect_ms = 1e3 * reference["reference_wall"] / steps
    reference_total_ms = total_ms - per_step_ms["detect"] + reference_detect_ms
    figures = {
        "policy": policy_name,
        "steps": steps,
        "warmup": warmup,
        "zoom": costs["zoom"],
        **{f"{part}_ms": per_step_ms[part] for part in PARTS},
        "total_ms": total_ms,
        "other_ms": total_ms - sum(per_step_ms.values()),
        "cpu_ms": 1e3 * costs["cpu"] / steps,
        "steps_per_s": 1e3 / total_ms,
        **{f"{part}_share": per_step_ms[part] / total_ms for part in PARTS},
        "reference_detect_ms": reference_detect_ms,
        "reference_detect_cpu_ms": 1e3 * reference["reference_cpu"] / steps,
        "reference_steps_per_s": 1e3 / reference_total_ms,
        "detect_speedup": reference_detect_ms / per_step_ms["detect"],
    }
    figures |= {count: int(value) for count, value in zip(COUNTS, costs["counts"]["ground"], strict=True)}
    figures |= {f"reference_{count}": int(value) for count, value in zip(COUNTS, costs["counts"]["image"], strict=True)}
    return figures | quality(figures)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=100, help="timed steps per policy")
    parser.add_argument("--warmup", type=int, default=5, help="untimed steps run first")
    parser.add_argument("--repeats", type=int, default=2, help="runs per policy; the fastest is kept")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--threads", type=int, default=1, help="OpenCV's threads (the detectors')")
    parser.add_argument("--json", type=Path, help="write the rows here")
    args = parser.parse_args()
    if args.steps < 1 or args.warmup < 0 or args.repeats < 1 or args.threads < 1:
        parser.error("--steps, --repeats and --threads must be at least 1 and --warmup at least 0")
    cv2.setNumThreads(args.threads)
    scenario = pets_scenario("hog", **{"control.beta": 1.0})
    settings = scenario.detector
    reference = HogPeopleDetector(settings.hog_upsample, settings.hog_hit_threshold, settings.hog_nms_iou)
    print(
        f"PETS 2009, HOG detector, beta 1, seed {args.seed}: ms per step over {args.steps} steps "
        f"after {args.warmup} warm-up steps, OpenCV on {args.threads} thread(s), fastest of {args.repeats} runs; "
        "today: every window (detectMultiScale) on the same views"
    )
    header = f"{'policy':<8}{'zoom':>6}" + "".join(f"{part:>8}" for part in PARTS) + f"{'total':>8}{'steps/s':>9}"
    header += f"{'cpu':>8}{'today detect':>14}{'today steps/s':>15}{'speed-up':>10}"
    print(header, flush=True)
    fastest: dict[str, dict] = {}
    fastest_reference: dict[str, dict] = {}
    for _ in range(args.repeats):
        for policy_name in POLICIES:
            costs = step_costs(scenario, reference, policy_name, args.steps, args.warmup, args.seed)
            if policy_name not in fastest or costs["wall"] < fastest[policy_name]["wall"]:
                fastest[policy_name] = costs
            if (
                policy_name not in fastest_reference
                or costs["reference_wall"] < fastest_reference[policy_name]["reference_wall"]
            ):
                fastest_reference[policy_name] = costs
    rows = [row(name, fastest[name], fastest_reference[name], args.steps, args.warmup) for name in POLICIES]
    for figures in rows:
        line = f"{figures['policy']:<8}{figures['zoom']:>6.2f}" + "".join(
            f"{figures[part + '_ms']:>8.2f}" for part in PARTS
        )
        line += f"{figures['total_ms']:>8.2f}{figures['steps_per_s']:>9.1f}{figures['cpu_ms']:>8.1f}"
        line += f"{figures['reference_detect_ms']:>14.1f}{figures['reference_steps_per_s']:>15.2f}"
        line += f"{figures['detect_speedup']:>9.1f}x"
        print(line)
    print("total: wall time per timed step; the rest of it (other_ms in --json) is the loop's bookkeeping")
    print(
        f"\ndetection quality on the {len(POLICIES) * args.steps} timed views: recall of the annotated people wholly "
        f"in view and hidden at most {scenario.required_recording('scores').occluded_above:g}, precision of the "
        f"detections; matched one to one, feet within {MATCH_FRACTION_OF_HEIGHT:g} of the person's height "
        f"(sized: and heights within {SIZE_FACTOR:g}x); new / today"
    )
    print(f"{'policy':<8}{'people':>7}{'recall':>14}{'sized':>14}{'detections':>13}{'precision':>14}{'sized':>14}")
    for figures in rows:
        print(_quality_line(figures["policy"], figures))
    keys = [*COUNTS, *(f"reference_{count}" for count in COUNTS)]
    print(_quality_line("all", {key: sum(figures[key] for figures in rows) for key in keys}))
    busy = [figures["policy"] for figures in rows if figures["cpu_ms"] < 0.95 * figures["total_ms"]]
    if busy:
        print(f"warning: CPU time below 95 % of the wall time for {', '.join(busy)}: the machine was busy")
    if args.json:
        write_json(args.json, rows)


def _quality_line(label: str, counts: dict) -> str:
    """People, recall (feet; sized), detections (new / today), precision (feet; sized), new / today."""
    rates = quality(counts)
    line = f"{label:<8}{counts['people']:>7}"
    line += "".join(f"{rates[k]:>8.3f} /{rates['reference_' + k]:.3f}" for k in ("recall", "recall_sized"))
    line += f"{counts['detections']:>7} /{counts['reference_detections']:<4}"
    return line + "".join(f"{rates[k]:>8.3f} /{rates['reference_' + k]:.3f}" for k in ("precision", "precision_sized"))


if __name__ == "__main__":
    main()
