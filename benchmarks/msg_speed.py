"""Time of one face-capture scheduling decision against the size of the tracklet graph (MSG paper, section 3.5).

    python benchmarks/msg_speed.py [--sizes 100 1000 10000 100000] [--seed 0] [--json PATH]

A graph grows as a tracker would grow it over a long, crowded run: about 20
targets walking at a time, joining, splitting, losing each other in blind
gaps (X ambiguities), leaving and arriving, with faces captured now and then
but no untangling (so the graph keeps every ambiguity, the worst case). At
each size one decision scores every candidate (active, unlabelled, solo)
vertex: with the auxiliary data (refresh from the parents, then read) and by
traversal (``traversal_data`` of the tests' reference, ``tests/msg_traversal.py``); the two
must agree, and the script stops if they do not. Prints, per size, the
vertices, candidates, ms per decision each way and the ratio; ``--json``
writes rows ``vertices``, ``aux_ms``, ``traversal_ms``.
"""

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from ptztrack.facecapture import msg

# The traversal reference is test code, not part of the installed package.
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from msg_traversal import traversal_data  # noqa: E402

ACTIVE_TARGETS = 20


def grow(graph, active: dict, rng: np.random.Generator, next_target: list) -> None:
    """One tracker event on ``graph``; ``active`` maps active vertices to their targets."""
    vertices = sorted(active)
    event = rng.choice(["join", "split", "blind_gap", "turnover", "label"], p=[0.3, 0.25, 0.25, 0.1, 0.1])
    step = graph.number_of_nodes()  # any increasing stamp will do
    events = []
    if event == "join" and len(vertices) >= 2:
        a, b = rng.choice(vertices, 2, replace=False)
        events = [(active[a] | active[b], [a, b])]
    elif event == "split":
        compounds = [v for v in vertices if len(active[v]) > 1]
        if compounds:
            v = compounds[rng.integers(len(compounds))]
            targets = sorted(active[v])
            cut = int(rng.integers(1, len(targets)))
            events = [(frozenset(targets[:cut]), [v]), (frozenset(targets[cut:]), [v])]
    elif event == "blind_gap" and len(vertices) >= 2:
        lost = list(rng.choice(vertices, min(len(vertices), int(rng.integers(2, 4))), replace=False))
        events = [(active[v], lost) for v in lost]
    elif event == "turnover" or len(active) < ACTIVE_TARGETS:
        if vertices and len(active) >= ACTIVE_TARGETS:
            gone = vertices[rng.integers(len(vertices))]
            graph.nodes[gone]["active"] = False
            del active[gone]
        events = [(frozenset({next_target[0]}), [])]
        next_target[0] += 1
    elif event == "label":
        solos = [v for v in vertices if len(active[v]) == 1 and not graph.nodes[v]["labeled"]]
        if solos:
            v = solos[rng.integers(len(solos))]
            (face,) = active[v]
            msg.label(graph, v, face, untangling=False)
    # One blob per tracklet: the benchmark never scores, so the blob id only has to be fresh.
    tracklets = [
        (len(targets), [graph.graph["next_vertex"] + i], parents) for i, (targets, parents) in enumerate(events)
    ]
    created = msg.add_tracklets(graph, tracklets, step)
    for (targets, parents), v in zip(events, created, strict=True):
        for p in parents:
            active.pop(p, None)
        active[v] = frozenset(targets)
    for v in active:
        msg.extend(graph, v, step, int(rng.integers(1, 20)))


def decide_with_aux(graph, candidates) -> list[tuple]:
    scores = []
    for v in candidates:
        msg.refresh(graph, v)
        node = graph.nodes[v]
        scores.append((node["n_notL"] / node["n_o"], (node["dL_dir"] + node["L_notdir"]) / node["n_o"]))
    return scores


def decide_by_traversal(graph, candidates) -> list[tuple]:
    scores = []
    for v in candidates:
        data = traversal_data(graph, v)
        scores.append((data["n_notL"] / data["n_o"], data["S_P"]))
    return scores


def timed_ms(function, *args, repeats: int) -> tuple[float, object]:
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        result = function(*args)
        best = min(best, time.perf_counter() - start)
    return best * 1e3, result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[100, 1000, 10_000, 100_000])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", help="write rows vertices, aux_ms, traversal_ms here")
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    graph, active, next_target = msg.new_graph(), {}, [0]
    rows = []
    print(f"{'vertices':>9} {'candidates':>10} {'aux ms':>9} {'traversal ms':>13} {'ratio':>9}")
    for size in sorted(args.sizes):
        while graph.number_of_nodes() < size:
            grow(graph, active, rng, next_target)
        candidates = [v for v, targets in active.items() if len(targets) == 1 and not graph.nodes[v]["labeled"]]
        aux_ms, aux = timed_ms(decide_with_aux, graph, candidates, repeats=20)
        traversal_ms, traversal = timed_ms(decide_by_traversal, graph, candidates, repeats=3 if size < 50_000 else 1)
        if not np.allclose(aux, traversal, rtol=1e-12, atol=0.0):
            raise SystemExit(f"auxiliary data and traversal disagree at {graph.number_of_nodes()} vertices")
        rows.append({"vertices": graph.number_of_nodes(), "aux_ms": aux_ms, "traversal_ms": traversal_ms})
        print(
            f"{graph.number_of_nodes():>9} {len(candidates):>10} {aux_ms:>9.3f} {traversal_ms:>13.1f}"
            f" {traversal_ms / aux_ms:>8.0f}x"
        )
    if args.json:
        with open(args.json, "w") as file:
            json.dump(rows, file, indent=2)


if __name__ == "__main__":
    main()
