"""Traversal reference for the auxiliary data of the Multi-Strand Tracking Graph (paper section 3.3-3.5, Appendix A).

The MSG stores, per vertex, data computed recursively from the vertex and its
parents (equations 2-4, 7-9, 11, 12). This module computes the same quantities
from their definitions by traversing the graph, with nothing stored and nothing
cached between calls, so that a property test can check the recursion against
it and a benchmark can time both.

Graph contract: a ``networkx.DiGraph`` DAG, edges parent -> child, with node
attributes ``count`` (targets of the tracklet; solo iff 1), ``labeled`` (the
face was captured) and ``length`` (tracklet length ``|tau(v)|``). The paper's
"no vertex" 0 is ``None``.

Definitions (the reading the recursions implement):

* A *labeled* vertex is a solo vertex with ``labeled`` true (``V_L`` of section
  3.3); a compound vertex flagged ``labeled`` is treated as unlabeled.
* An *unlabeled path* ``w -> ... -> v`` has no labeled interior vertex.
* The *unlabeled cone* of ``v``: the vertices with an unlabeled path to ``v``.
  It is found backwards from ``v``; a labeled vertex belongs to it but its
  parents are not looked at (a labeled ``v`` is its own cone).
* Every count is a count of (origin, unlabeled path) pairs, not of distinct
  origins: the recursions sum over parents, so an origin reached along ``k``
  paths counts ``k`` times (e.g. ``n_notL = 4`` with two distinct unlabeled
  origins after a blind-gap X ambiguity whose solos join again).
* *Origin-like* vertices of the cone are its labeled vertices and its unlabeled
  sources. Equations 2 and 8 count an unlabeled source as one (unlabeled)
  origin whatever its ``count``, so ``n_o`` and ``n_notL`` do too; the paper's
  definition of an origin (section 3.3) requires a solo vertex, so
  :func:`origins` leaves compound sources out. The two agree whenever sources
  are solo, as they should be.

Every public function costs O(vertices + edges of the unlabeled cone) and is
iterative, so 10^5-vertex chains need no recursion.
"""

from collections import deque
from collections.abc import Hashable
from dataclasses import dataclass

import networkx as nx

Vertex = Hashable


def is_solo(graph: nx.DiGraph, vertex: Vertex) -> bool:
    return graph.nodes[vertex]["count"] == 1


def is_labeled(graph: nx.DiGraph, vertex: Vertex) -> bool:
    """Membership of ``V_L``: a solo vertex whose face was captured."""
    return _labeled(graph.nodes[vertex])


def _labeled(attributes: dict) -> bool:
    return bool(attributes["labeled"]) and attributes["count"] == 1


@dataclass(frozen=True)
class _UnlabeledCone:
    """The unlabeled cone of ``vertex``, with what the traversal read of the graph.

    order : the cone in topological order, ancestors first, ``vertex`` last.
    attributes : member -> its node attributes.
    labeled : the labeled members, whose parents were not looked at.
    parents : unlabeled member -> its parents (all of them are in the cone).
    children : member -> the unlabeled members it is a parent of: with
        ``parents``, the cone's edges.
    one_child : member other than ``vertex`` -> whether its out-degree in the
        graph is 1.
    """

    vertex: Vertex
    order: list
    attributes: dict
    labeled: set
    parents: dict
    children: dict
    one_child: dict


def _unlabeled_cone(graph: nx.DiGraph, vertex: Vertex) -> _UnlabeledCone:
    """Backward search from ``vertex`` that stops at labeled vertices, then Kahn's sort of the cone."""
    nodes, pred, succ = graph.nodes, graph.pred, graph.succ
    attributes = {vertex: nodes[vertex]}
    labeled, parents, children, one_child = set(), {}, {vertex: []}, {}
    frontier = [vertex]
    while frontier:
        child = frontier.pop()
        if _labeled(attributes[child]):
            labeled.add(child)
            continue
        parents[child] = child_parents = tuple(pred[child])
        for parent in child_parents:
            if parent not in children:
                attributes[parent] = nodes[parent]
                children[parent] = [child]
                one_child[parent] = len(succ[parent]) == 1
                frontier.append(parent)
            else:
                children[parent].append(child)

    pending_parents = {member: len(parents.get(member, ())) for member in children}
    ready = deque(member for member, pending in pending_parents.items() if pending == 0)
    order = []
    while ready:
        member = ready.popleft()
        order.append(member)
        for child in children[member]:
            pending_parents[child] -= 1
            if pending_parents[child] == 0:
                ready.append(child)
    if len(order) != len(children):
        raise ValueError(f"the ancestors of {vertex!r} contain a cycle; the MSG must be a DAG")
    return _UnlabeledCone(vertex, order, attributes, labeled, parents, children, one_child)


def _origin_path_counts(cone: _UnlabeledCone) -> dict:
    """Origin-like vertex ``w`` of the cone -> number of unlabeled paths ``w -> ... -> v``.

    Paths to ``v`` are counted backwards, in reverse topological order: a
    vertex's count is the sum of its cone children's counts, ``v``'s is 1.
    """
    paths_to_vertex = {cone.vertex: 1}
    for member in reversed(cone.order[:-1]):
        paths_to_vertex[member] = sum(paths_to_vertex[child] for child in cone.children[member])
    return {
        member: paths for member, paths in paths_to_vertex.items() if member in cone.labeled or not cone.parents[member]
    }


def origins(graph: nx.DiGraph, vertex: Vertex) -> dict:
    """Origins of ``vertex`` (section 3.3) -> number of unlabeled paths from each to ``vertex``.

    An origin is a solo vertex with an unlabeled path to ``vertex`` that is a
    source (unlabeled origin) or labeled (labeled origin). A labeled vertex is
    its only origin. Compound sources are not origins (see the module notes).
    """
    cone = _unlabeled_cone(graph, vertex)
    return {
        origin: paths for origin, paths in _origin_path_counts(cone).items() if cone.attributes[origin]["count"] == 1
    }


def labeled_origins(graph: nx.DiGraph, vertex: Vertex) -> set:
    return {origin for origin in origins(graph, vertex) if is_labeled(graph, origin)}


def unlabeled_origins(graph: nx.DiGraph, vertex: Vertex) -> set:
    return {origin for origin in origins(graph, vertex) if not is_labeled(graph, origin)}


@dataclass(slots=True)
class _ForwardCounts:
    """Path counts from the origin-like vertices of the cone to one cone vertex ``y``.

    unlabeled_origin_paths : (unlabeled source, unlabeled path to ``y``) pairs: ``n_notL(y)``.
    chain_paths : (labeled ``u``, path ``u -> y``) pairs still on ``u``'s forward
        labeling chain at ``y`` (each vertex before ``y`` has one child); 1 at a
        labeled ``y``: ``n_ret(y)``.
    off_chain_paths : the (labeled ``u``, path) pairs that have left the chain by ``y``.
    off_chain_length : over those pairs, the summed lengths of the path vertices
        after ``u`` that are off the chain, ``y`` included: ``Delta L_dir(y)``.
    """

    unlabeled_origin_paths: int
    chain_paths: int
    off_chain_paths: int
    off_chain_length: int


def _forward_counts(cone: _UnlabeledCone) -> dict:
    """Cone vertex -> :class:`_ForwardCounts`, by dynamic programming in topological order.

    A (labeled origin, path) pair is a walk of a two-state automaton: it starts
    *on* the chain at its labeled origin, moves along an edge ``p -> y`` staying
    on it iff ``p`` has out-degree 1, and once *off* stays off; each vertex it
    reaches off the chain adds that vertex's length. The unlabeled cone of a
    cone vertex lies inside the cone, so every vertex's counts are exact.
    """
    counts = {}
    for member in cone.order:
        if member in cone.labeled:
            counts[member] = _ForwardCounts(0, 1, 0, 0)
            continue
        parents = cone.parents[member]
        if not parents:
            counts[member] = _ForwardCounts(1, 0, 0, 0)
            continue
        unlabeled_origin_paths = chain_paths = off_chain_paths = 0
        off_chain_length = 0
        for parent in parents:
            parent_counts = counts[parent]
            unlabeled_origin_paths += parent_counts.unlabeled_origin_paths
            if cone.one_child[parent]:
                chain_paths += parent_counts.chain_paths
            else:
                off_chain_paths += parent_counts.chain_paths
            off_chain_paths += parent_counts.off_chain_paths
            off_chain_length += parent_counts.off_chain_length
        off_chain_length += cone.attributes[member]["length"] * off_chain_paths
        counts[member] = _ForwardCounts(unlabeled_origin_paths, chain_paths, off_chain_paths, off_chain_length)
    return counts


def _left_parent(cone: _UnlabeledCone, vertex: Vertex, counts: dict) -> Vertex | None:
    """``p_left`` (equation 3) of an unlabeled cone vertex: its only parent with unlabeled origins."""
    with_unlabeled_origins = [parent for parent in cone.parents[vertex] if counts[parent].unlabeled_origin_paths > 0]
    return with_unlabeled_origins[0] if len(with_unlabeled_origins) == 1 else None


def _left_chain(cone: _UnlabeledCone, counts: dict) -> list:
    """The ``p_left`` chain ``v, p_left(v), p_left(p_left(v)), ...`` of the cone's ``v``; empty if ``v`` is labeled."""
    if cone.vertex in cone.labeled:
        return []
    chain = [cone.vertex]
    while (parent := _left_parent(cone, chain[-1], counts)) is not None:
        chain.append(parent)
    return chain


def traversal_data(graph: nx.DiGraph, vertex: Vertex) -> dict:
    """The MSG auxiliary data of ``vertex``, from the definitions by one traversal of its unlabeled cone.

    n_o (equation 8) : (origin, unlabeled path) pairs; compound sources count (module notes).
    n_notL (equation 2) : the pairs with an unlabeled origin.
    n_L (equation 9) : ``n_o - n_notL``, the pairs with a labeled origin.
    p_left (equation 3) : the only parent with ``n_notL > 0``, else None. None
        for a labeled vertex, whose parents are not looked at (its ``n_notL``
        is 0 whatever they are, so ``C`` and ``L_notdir`` do not depend on it).
    C (equation 4, unrolled) : None if ``n_notL == 0``, else the farthest-back
        solo vertex of the ``p_left`` chain ``v, p_left(v), ...``, or None if
        the chain has no solo vertex. A value outside ``{None, v}`` is the
        indirect match of ``v`` by elimination.
    L_notdir (equation 7, unrolled) : 0 for a labeled vertex, else the sum of
        ``length(x) * n_notL(x)`` over the ``p_left`` chain of ``v``.
    n_ret (equation 11) : 1 for a labeled vertex, else the (labeled ``u``,
        unlabeled path ``u -> v``) pairs in which every vertex but ``v`` has
        one child: the forward labeling chains reaching ``v``.
    dL_dir (equation 12) : 0 for a labeled vertex, else the sum over
        (labeled origin ``u``, unlabeled path ``pi`` from ``u`` to ``v``) of
        the lengths of the vertices ``x != u`` of ``pi`` off ``u``'s forward
        labeling chain along ``pi`` (the longest prefix of ``pi`` after ``u``
        in which each vertex's predecessor on ``pi`` has out-degree 1).
        Equivalently, the sum over unlabeled ``x`` of the cone of
        ``paths(x -> v) * length(x) * (n_L(x) - n_ret(x))``, which is
        equation 12 unrolled (labeled parents add 0): ``x`` off the chain is
        unlabeled, and splits ``pi`` into an unlabeled path ``u -> x``, on
        which alone its chain membership depends, and an unlabeled path
        ``x -> v``; of the ``n_L(x)`` pairs ``(u, u -> x)``, ``n_ret(x)`` keep
        ``x`` on the chain. Computed from the first form.
    S_P (equation 6) : ``(dL_dir + L_notdir) / n_o``.
    """
    cone = _unlabeled_cone(graph, vertex)
    origin_paths = _origin_path_counts(cone)
    n_origins = sum(origin_paths.values())
    n_unlabeled = sum(paths for origin, paths in origin_paths.items() if origin not in cone.labeled)
    counts = _forward_counts(cone)
    left_chain = _left_chain(cone, counts)
    if n_unlabeled == 0:
        candidate = None
    else:
        candidate = next((member for member in reversed(left_chain) if cone.attributes[member]["count"] == 1), None)
    not_direct_length = sum(
        (cone.attributes[member]["length"] * counts[member].unlabeled_origin_paths for member in left_chain), 0
    )
    direct_length = counts[vertex].off_chain_length
    return {
        "n_o": n_origins,
        "n_notL": n_unlabeled,
        "n_L": n_origins - n_unlabeled,
        "p_left": left_chain[1] if len(left_chain) > 1 else None,
        "C": candidate,
        "L_notdir": not_direct_length,
        "n_ret": counts[vertex].chain_paths,
        "dL_dir": direct_length,
        "S_P": (direct_length + not_direct_length) / n_origins,
    }


def past_ambiguity_score(graph: nx.DiGraph, vertex: Vertex) -> float:
    """``S_P(v) = (Delta L_dir(v) + L_notdir(v)) / n_o(v)`` (equation 6)."""
    return traversal_data(graph, vertex)["S_P"]


def future_ambiguity_score(graph: nx.DiGraph, vertex: Vertex, expected_join: bool) -> float:
    """``S_F(v) = Join(v) n_notL(v) / n_o(v)`` (section 3.5); ``expected_join`` is the tracker's ``Join(v)``."""
    data = traversal_data(graph, vertex)
    return float(expected_join) * data["n_notL"] / data["n_o"]
