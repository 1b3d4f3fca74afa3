"""The Multi-Strand Tracking Graph (MSG) with its auxiliary data (face-capture paper, section 3).

A vertex is a tracklet: solo (one target, ``count`` 1) or compound (``count``
targets walking together, indistinguishable). An edge parent -> child is a
candidate association between consecutive tracklets. Node attributes:

- ``count`` (int, people in the tracklet), ``length`` (steps observed),
  ``labeled`` (a face was captured on it or matched to it; solo only),
  ``face`` (the identity of that face, None while unlabelled), ``active``
  (the tracklet still grows), ``first_step`` / ``last_step``;
- ``blobs``: the ids of the observations the tracklet is made of (the
  sensor's units seen continuously with the same members); the graph never
  reads them, the scoring maps them to the people they held. Tracklets the
  tracker associated wrongly hold blobs of other people, and a label is
  right only where its face is among a blob's people;
- the auxiliary data, each computed from the vertex and its parents alone:
  ``n_o`` (eq. 8), ``n_notL`` (eq. 2), ``p_left`` (eq. 3), ``C`` (eq. 4),
  ``L_notdir`` (eq. 7), ``n_ret`` (eq. 11), ``dL_dir`` (eq. 12). "No vertex"
  (the paper's 0) is None.

The recursions sum over parents, so an origin reachable along several
unlabelled paths counts once per path (without untangling these counts
double at every blind-gap X ambiguity and soon pass any float; lengths are
whole steps, so all of it is exact integer arithmetic); the tests' traversal
reference (``tests/msg_traversal.py``) computes the same quantities by
traversal, and a property test holds the two equal. ``length`` of an active vertex grows every step, which changes its
own ``L_notdir`` and ``dL_dir``: :func:`refresh` recomputes them in
O(|parents|) before a decision (its descendants do not exist yet).
"""

from collections.abc import Iterable

import networkx as nx

AUX_FIELDS = ("n_o", "n_notL", "p_left", "C", "L_notdir", "n_ret", "dL_dir")


def new_graph() -> nx.DiGraph:
    graph = nx.DiGraph()
    graph.graph["next_vertex"] = 0
    return graph


def is_labeled(graph: nx.DiGraph, v) -> bool:
    return graph.nodes[v]["labeled"]


def refresh(graph: nx.DiGraph, v) -> None:
    """Recompute v's auxiliary data from its own attributes and its parents' stored data."""
    node = graph.nodes[v]
    parents = list(graph.pred[v])
    if node["labeled"]:
        node.update(n_o=1, n_notL=0, p_left=None, C=None, L_notdir=0, n_ret=1, dL_dir=0)
        return
    if not parents:
        n_o, n_notL = 1, 1
    else:
        n_o = sum(graph.nodes[p]["n_o"] for p in parents)
        n_notL = sum(graph.nodes[p]["n_notL"] for p in parents)
    with_unlabeled_origins = [p for p in parents if graph.nodes[p]["n_notL"] > 0]
    p_left = with_unlabeled_origins[0] if len(with_unlabeled_origins) == 1 else None
    if n_notL == 0:
        candidate = None
    elif p_left is not None and graph.nodes[p_left]["C"] is not None:
        candidate = graph.nodes[p_left]["C"]
    else:
        candidate = v if node["count"] == 1 else None
    L_notdir = node["length"] * n_notL + (graph.nodes[p_left]["L_notdir"] if p_left is not None else 0)
    n_ret = sum(graph.nodes[p]["n_ret"] for p in parents if graph.out_degree(p) == 1)
    n_L = n_o - n_notL
    dL_dir = node["length"] * (n_L - n_ret) + sum(graph.nodes[p]["dL_dir"] for p in parents)
    node.update(n_o=n_o, n_notL=n_notL, p_left=p_left, C=candidate, L_notdir=L_notdir, n_ret=n_ret, dL_dir=dL_dir)


def refresh_descendants(graph: nx.DiGraph, vertices: Iterable) -> None:
    """Recompute the auxiliary data of ``vertices`` and everything below them, parents first."""
    affected = set()
    for v in vertices:
        if v in graph:
            affected.add(v)
            affected |= nx.descendants(graph, v)
    for v in nx.topological_sort(graph.subgraph(affected)):
        refresh(graph, v)


def add_tracklets(graph: nx.DiGraph, tracklets: list[tuple[int, Iterable, Iterable]], step: int) -> list[int]:
    """Start new tracklets at ``step``: one vertex per (count, blobs, parents), all edges of the event at once.

    Adding every child of a parent in one event matters: a parent's number of
    children enters its children's ``n_ret`` (forward labelling chains).
    Parents stop being active, with their auxiliary data brought up to their
    final length. Returns the new vertex ids.
    """
    for p in {p for _, _, parents in tracklets for p in parents}:
        refresh(graph, p)
    created = []
    for count, blobs, parents in tracklets:
        v = graph.graph["next_vertex"]
        graph.graph["next_vertex"] += 1
        graph.add_node(
            v, count=count, blobs=frozenset(blobs), length=0, labeled=False, face=None, active=True,
            first_step=step, last_step=step,
        )  # fmt: skip
        for p in parents:
            graph.add_edge(p, v)
            graph.nodes[p]["active"] = False
        created.append(v)
    for v in created:
        refresh(graph, v)
    return created


def extend(graph: nx.DiGraph, v, step: int, steps: int = 1) -> None:
    """The tracklet of v was observed for ``steps`` more steps, up to ``step``."""
    node = graph.nodes[v]
    node["length"] += steps
    node["last_step"] = step


def path_cone(graph: nx.DiGraph, start, end) -> tuple[set, set]:
    """The vertices on unlabelled paths start -> ... -> end (labelled vertices only at the ends), and
    among them those on every such path. Both empty if there is no such path."""
    allowed = {start, end} | {
        v for v in nx.ancestors(graph, end) & nx.descendants(graph, start) if not is_labeled(graph, v)
    }
    sub = graph.subgraph(allowed)
    order = list(nx.topological_sort(sub))
    paths_from_start = {v: 0 for v in order}
    paths_from_start[start] = 1
    for v in order:
        if v != start:
            paths_from_start[v] = sum(paths_from_start[p] for p in sub.pred[v])
    paths_to_end = {v: 0 for v in order}
    paths_to_end[end] = 1
    for v in reversed(order):
        if v != end:
            paths_to_end[v] = sum(paths_to_end[c] for c in sub.succ[v])
    total = paths_from_start[end]
    cone = {v for v in order if paths_from_start[v] and paths_to_end[v]} if total else set()
    on_every_path = {v for v in cone if paths_from_start[v] * paths_to_end[v] == total}
    return cone, on_every_path


def untangle(graph: nx.DiGraph, start, end) -> dict:
    """Untangle the graph between a labelled vertex ``start`` and ``end``, just labelled with the same
    face (section 3.2). Returns {old vertex: vertex now holding its tracklet} for merged vertices.

    The target z went from start to end along one of the unlabelled paths
    between them. A vertex on every such path holds z for sure: a solo one
    becomes labelled and keeps only edges within those paths (its one
    target came from and went into them); a compound one splits into a
    labelled solo vertex of z and a remainder of the other targets, which
    takes the compound's edges outside the paths (both keep its blobs). Edges within the paths
    stay unless they would carry z into a vertex without it or the reverse.
    With a single path this is the paper's untangling, and the chain merges
    into one labelled vertex. Total tracklet length (count x length) is
    conserved and, if the graph held every true association, none is lost.
    """
    face = graph.nodes[end]["face"]
    cone, certain = path_cone(graph, start, end)
    # Whoever loses or gains an edge needs fresh auxiliary data, and may now be part of a chain.
    touched = {n for v in cone for n in (v, *graph.pred[v], *graph.succ[v])}
    holds_z, without_z = set(), set()
    parts = {}
    for v in cone:
        node = graph.nodes[v]
        if v not in certain or node["count"] == 1:
            parts[v] = [v]
            if v in certain:
                holds_z.add(v)
            continue
        solo, remainder = graph.graph["next_vertex"], graph.graph["next_vertex"] + 1
        graph.graph["next_vertex"] += 2
        graph.add_node(solo, **{**node, "count": 1})
        graph.add_node(remainder, **{**node, "count": node["count"] - 1})
        graph.add_edges_from((p, remainder) for p in graph.pred[v] if p not in cone)
        graph.add_edges_from((remainder, c) for c in graph.succ[v] if c not in cone)
        parts[v] = [solo, remainder]
        holds_z.add(solo)
        without_z.add(remainder)
    cone_edges = [(a, b) for a in cone for b in graph.succ[a] if b in cone]
    for a, b in cone_edges:
        for x in parts[a]:
            for y in parts[b]:
                if not ({x, y} & holds_z and {x, y} & without_z):
                    graph.add_edge(x, y)
    graph.remove_nodes_from([v for v in cone if len(parts[v]) == 2])
    within = cone | holds_z | without_z
    for v in holds_z & set(graph):
        # The start's past and the end's future lie outside the paths, and stay.
        if v != start:
            graph.remove_edges_from([(p, v) for p in list(graph.pred[v]) if p not in within])
        if v != end:
            graph.remove_edges_from([(v, c) for c in list(graph.succ[v]) if c not in within])
        graph.nodes[v].update(labeled=True, face=face)
    touched = {v for v in touched | holds_z | without_z if v in graph}
    touched |= {n for v in touched for n in (*graph.pred[v], *graph.succ[v])}
    merged_into = merge_chains(graph, touched)
    refresh_descendants(graph, {merged_into.get(v, v) for v in touched})
    return merged_into


def merge_chains(graph: nx.DiGraph, vertices: Iterable) -> dict:
    """Merge every chain through ``vertices``: an edge a -> b where a has one child, b one parent and both
    the same count is one tracklet, unless the faces of two people label them. The later vertex keeps its
    id (active vertices keep theirs). Returns {merged vertex: vertex now holding its tracklet}."""
    merged_into = {}
    pending = [v for v in vertices if v in graph]
    while pending:
        b = pending.pop()
        if b not in graph or graph.in_degree(b) != 1:
            continue
        (a,) = graph.pred[b]
        node_a, node_b = graph.nodes[a], graph.nodes[b]
        if graph.out_degree(a) != 1 or node_a["count"] != node_b["count"]:
            continue
        if None not in (node_a["face"], node_b["face"]) and node_a["face"] != node_b["face"]:
            continue
        node_b["length"] += node_a["length"]
        node_b["first_step"] = node_a["first_step"]
        node_b["blobs"] = node_a["blobs"] | node_b["blobs"]
        node_b["labeled"] = node_b["labeled"] or node_a["labeled"]
        node_b["face"] = node_b["face"] if node_b["face"] is not None else node_a["face"]
        graph.add_edges_from((p, b) for p in graph.pred[a])
        graph.remove_node(a)
        merged_into[a] = b
        for old, new in merged_into.items():
            if new == a:
                merged_into[old] = b
        pending.append(b)
    return merged_into


def label(graph: nx.DiGraph, v, face, untangling: bool = True) -> dict:
    """The face ``face`` (an identity) was captured on the active solo vertex v: label it, match it and untangle.

    Face matching is exact, and a labelled vertex's face is known (captured,
    or given by untangling), so the direct match is the latest labelled
    vertex with the same face: with a graph that holds every true
    association, the target's labelled vertices lie on its own path in time
    order, and older ones could reach v only along other targets' paths.
    With no labelled vertex of that face, the indirect match by
    elimination is C(v) (Claim 1), read before v is labelled. With
    ``untangling``, the paths between the match and v are untangled
    (:func:`untangle`). Returns {old vertex: vertex now holding its
    tracklet} for merged vertices (v keeps its id).
    """
    indirect_candidate = graph.nodes[v]["C"]
    same_face = [u for u, node in graph.nodes(data=True) if node["labeled"] and node["face"] == face]
    graph.nodes[v].update(labeled=True, face=face)
    refresh_descendants(graph, [v])
    if not untangling:
        return {}
    if same_face:
        start = max(same_face, key=lambda u: graph.nodes[u]["last_step"])
    elif indirect_candidate not in (None, v):
        start = indirect_candidate
    else:
        return {}
    if not path_cone(graph, start, v)[0]:
        return {}
    return untangle(graph, start, v)
