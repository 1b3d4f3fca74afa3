"""How a camera network's closed loop scales with its cameras and people: joint decisions per second,
the belief's update time and the step's wall time.

The scene. For ``N`` cameras, a square of ``ceil(sqrt(N))`` x ``ceil(sqrt(N))``
cells of 15 m x 15 m (the one-camera scene's area), with ``P`` synthetic
walkers over the whole of it. Camera ``k`` belongs to cell ``k`` (row by
row): it stands 13.5 m from the cell's centre, 2.5 m up, on the side away
from the area's centre, facing both (the one-camera scene's mount, repeated;
one camera is the one-camera scene itself). Every camera is a PTZ camera
with the scenario's grid, lens and realistic detector, and learns its own
detector model; the PTZ cameras decide jointly with 'intg'
(:class:`ptztrack.network.policy.NetworkInformationPolicy`) and the
one belief is updated by every camera in turn
(:class:`ptztrack.network.shared_belief.SharedBelief`).

The figures, over the ``--steps`` steps after ``--warmup`` (whose first step
starts the actors and compiles Numba's kernels in them; this process's are
compiled by a small episode before the table):

* ``decisions_per_s``: joint decisions (every camera's action) over the wall
  time of the decision stage (``NetworkEpisode.decision_s``);
* ``belief_update_ms``: the median over steps of every camera's update of the
  one tracker, one after the other (``NetworkEpisode.update_s``);
* ``step_ms``: the median wall time of a whole step (prediction, decision,
  every camera's look and update);
* ``decisions_per_s_before``: the same steps' decisions replayed with the
  conditioning as it was before issue 33 part 4 (the chosen view's
  homographies computed anew for its pose, every camera, every step:
  :func:`recomputed_posterior`), beside ``decisions_per_s_replayed``, the
  same replay with today's; the two must choose the same actions (the
  script stops if not).

Where the cameras run. With Ray (``--ray``, the default when Ray is
installed), each camera's capture and detection run in Ray actors
(:class:`ptztrack.loop.camera_actors.RayCameras`) on the cluster at
``RAY_ADDRESS``, else on a local one started here (loopback only, no
dashboard); ``--cameras-per-actor`` cameras share an actor's process (default:
as many as make one actor per CPU of the cluster, since each actor is a
process of about 260 MB). ``--no-ray`` runs them in this process. The
belief, its updates and the decisions are in this process either way.

    python benchmarks/network_scale.py [--cameras 1 4 16 64] [--people 10 100] [--steps 8]
                                       [--warmup 2] [--ray | --no-ray] [--cameras-per-actor N] [--json PATH]

``--json`` writes ``rows``, one per (cameras, people): ``cameras``,
``people``, ``decisions_per_s``, ``belief_update_ms``, ``step_ms``,
``decisions_per_s_before``, ``decisions_per_s_replayed``, ``cameras_per_actor``
(None in process); and ``executor``, ``steps``, ``warmup``, ``cpus`` and
``load_average`` (the 1-minute load before and after).
"""

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402  (the thread count must be set before NumPy loads)
import importlib.util  # noqa: E402
import math  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable  # noqa: E402
from functools import partial  # noqa: E402
from pathlib import Path  # noqa: E402
from unittest import mock  # noqa: E402

import numpy as np  # noqa: E402

from ptztrack.builders.network import network_policy, network_tracker, network_world  # noqa: E402
from ptztrack.config import Scenario, scenario_from_dict  # noqa: E402
from ptztrack.control.information_gain import action_geometry, detection_weight_integral  # noqa: E402
from ptztrack.files import write_json  # noqa: E402
from ptztrack.loop.simulated import (  # noqa: E402
    CameraFleet,
    CameraWorker,
    InProcessCameras,
    run_network_loop,
)
from ptztrack.network import policy as conditioning  # noqa: E402
from ptztrack.track.observation import observation_matrix  # noqa: E402
from ptztrack.types import Tracks  # noqa: E402

CELL_M = 15.0
# The one-camera scene's mount: 13.5 m from the area's centre, 2.5 m up.
CAMERA_DISTANCE_M, CAMERA_HEIGHT_M = 13.5, 2.5


def grid_scenario(cameras: int, people: int, frames: int) -> Scenario:
    """The scene of the module's docstring: ``cameras`` cameras over their cells, ``people`` walkers."""
    side = math.ceil(math.sqrt(cameras))
    area_m = side * CELL_M
    centre_m = np.array([area_m / 2, area_m / 2])
    mounts = []
    for k in range(cameras):
        cell_centre_m = CELL_M * (np.array([k % side, k // side]) + 0.5)
        inwards = centre_m - cell_centre_m
        distance_m = float(np.linalg.norm(inwards))
        # The one cell at the centre (one camera) keeps the one-camera scene's camera, south of it.
        direction = inwards / distance_m if distance_m > 0 else np.array([0.0, 1.0])
        x_m, y_m = cell_centre_m - CAMERA_DISTANCE_M * direction
        mounts.append({"kind": "ptz", "position_m": (float(x_m), float(y_m), CAMERA_HEIGHT_M)})
    return scenario_from_dict(
        {"area_m": (area_m, area_m), "frames": frames, "people": {"count": people}, "cameras": mounts}
    )


def recomputed_posterior(tracks: Tracks, policy, action: int) -> Tracks:
    """The conditioning before issue 33 part 4: as :func:`ptztrack.network.policy.expected_posterior`,
    but with the view's homographies and Jacobian computed anew for its pose."""
    if len(tracks) == 0:
        return tracks
    pose = policy.grid.poses[action]
    mean_m, position_cov_m2 = tracks.mean[:, :2], tracks.covariance[:, :2, :2]
    geometry = action_geometry(policy.camera, pose[None], policy.person_height_m)
    alpha = detection_weight_integral(policy.camera, geometry, policy.recall, mean_m, position_cov_m2, policy.V)[0]
    seen = np.flatnonzero(alpha > 0)
    C = observation_matrix(policy.camera, pose, tracks.mean[seen])
    return conditioning.expected_update(tracks, seen, alpha[seen], C, policy.V)


class RecordedPolicy:
    """The network's policy, keeping every step's decision contexts for the replay."""

    def __init__(self, policy):
        self.policy, self.contexts = policy, []

    def choose(self, contexts):
        self.contexts.append(contexts)
        return self.policy.choose(contexts)


def replayed_decisions_per_s(policy, recorded) -> tuple[float, list]:
    """Decisions per second of ``policy`` over the ``recorded`` steps' contexts (the fastest of three
    passes: on a shared machine the slower ones measure the other processes) and its choices."""
    passes_s = []
    for _ in range(3):
        started = time.perf_counter()
        choices = [policy.choose(contexts) for contexts in recorded]
        passes_s.append(time.perf_counter() - started)
    return len(recorded) / min(passes_s), choices


def measure(cameras: int, people: int, steps: int, warmup: int, fleet, seed: int = 0) -> dict:
    """One row: the episode of ``cameras`` and ``people`` run for ``warmup + steps`` steps, the last
    ``steps`` measured (see the module's docstring)."""
    scenario = grid_scenario(cameras, people, warmup + steps)
    world = network_world(scenario, seed)
    policy = network_policy(scenario, world, "joint", "intg")
    recorder = RecordedPolicy(policy)
    episode = run_network_loop(world, recorder, network_tracker(scenario, world), seed, fleet)
    measured = slice(warmup, None)
    recorded = recorder.contexts[measured]
    replayed, choices = replayed_decisions_per_s(policy, recorded)
    with mock.patch.object(conditioning, "expected_posterior", recomputed_posterior):
        before, choices_before = replayed_decisions_per_s(policy, recorded)
    if choices_before != choices:
        raise SystemExit(f"{cameras} cameras, {people} people: the conditioning of before chose other actions")
    return {
        "cameras": cameras,
        "people": people,
        "decisions_per_s": steps / float(np.sum(episode.decision_s[measured])),
        "belief_update_ms": 1e3 * float(np.median(episode.update_s[measured])),
        "step_ms": 1e3 * float(np.median(episode.step_s[measured])),
        "decisions_per_s_before": before,
        "decisions_per_s_replayed": replayed,
        "tracks": float(np.mean([len(contexts[0].tracks) for contexts in recorded])),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cameras", type=int, nargs="+", default=[1, 4, 16, 64])
    parser.add_argument("--people", type=int, nargs="+", default=[10, 100])
    parser.add_argument("--steps", type=int, default=8, help="measured steps per size")
    parser.add_argument("--warmup", type=int, default=2, help="steps run first and not measured")
    parser.add_argument(
        "--ray",
        action=argparse.BooleanOptionalAction,
        default=importlib.util.find_spec("ray") is not None,
        help="the cameras in Ray actors (default: if Ray is installed)",
    )
    parser.add_argument("--cameras-per-actor", type=int, help="default: one actor per CPU of the cluster")
    parser.add_argument("--json", type=Path, help="write the rows here")
    args = parser.parse_args()
    if args.steps < 1 or args.warmup < 1:
        parser.error("--steps and --warmup must be 1 or more (the first step starts the actors)")
    load_before = os.getloadavg()[0]
    cpus = None
    if args.ray:
        from ptztrack.loop.camera_actors import RayCameras
        from ptztrack.loop.executors import connect_ray

        cpus = int(connect_ray().cluster_resources().get("CPU", 1))
        where = os.environ.get("RAY_ADDRESS") or "a local cluster (127.0.0.1)"
        print(f"cameras in Ray actors on {where}, {cpus} CPUs", flush=True)
    else:
        print("cameras in this process", flush=True)
    print(f"{args.steps} steps measured after {args.warmup}; load average {load_before:.2f}", flush=True)
    print(
        f"{'cameras':>8}{'people':>8}{'tracks':>8}{'decisions/s':>13}{'before':>9}{'replayed':>10}"
        f"{'update ms':>11}{'step ms':>9}{'per actor':>11}",
        flush=True,
    )
    # Numba compiles this process's kernels on their first tracks: an episode first, not measured.
    measure(4, 20, 3, 1, InProcessCameras)
    rows = []
    for people in args.people:
        for cameras in args.cameras:
            fleet: Callable[[list[CameraWorker]], CameraFleet] = InProcessCameras
            per_actor = None
            if args.ray:
                per_actor = args.cameras_per_actor or math.ceil(cameras / cpus)
                fleet = partial(RayCameras, cameras_per_actor=per_actor)
            row = measure(cameras, people, args.steps, args.warmup, fleet) | {"cameras_per_actor": per_actor}
            rows.append(row)
            print(
                f"{cameras:>8}{people:>8}{row['tracks']:>8.0f}{row['decisions_per_s']:>13.1f}"
                f"{row['decisions_per_s_before']:>9.1f}{row['decisions_per_s_replayed']:>10.1f}"
                f"{row['belief_update_ms']:>11.1f}{row['step_ms']:>9.0f}{per_actor or '-':>11}",
                flush=True,
            )
    load_after = os.getloadavg()[0]
    print(f"load average after: {load_after:.2f}")
    if args.json:
        write_json(
            args.json,
            {
                "executor": "ray" if args.ray else "in-process",
                "steps": args.steps,
                "warmup": args.warmup,
                "cpus": cpus or os.cpu_count(),
                "load_average": [load_before, load_after],
                "rows": rows,
            },
        )


if __name__ == "__main__":
    main()
