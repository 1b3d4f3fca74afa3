"""The MSG traversal reference against the paper's examples, brute-force path enumeration and the literal recursions."""

import networkx as nx
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from msg_traversal import (
    future_ambiguity_score,
    is_labeled,
    is_solo,
    labeled_origins,
    origins,
    past_ambiguity_score,
    traversal_data,
    unlabeled_origins,
)


def msg(vertices, edges, labeled=()):
    """DiGraph from ``name -> (count, length)`` and parent -> child edges; ``labeled`` names the captured faces."""
    graph = nx.DiGraph()
    for name, (count, length) in vertices.items():
        graph.add_node(name, count=count, labeled=name in labeled, length=float(length))
    graph.add_edges_from(edges)
    return graph


def figure_2b(labeled=()):
    """A graph consistent with Figure 2(b): v1, v2 join into v4, which splits into v5, v6; v5 and v3 join into v7,
    which splits into v8, v9. The length of ``vi`` is ``i``."""
    vertices = {f"v{i}": (2 if i in (4, 7) else 1, i) for i in range(1, 10)}
    edges = [("v1", "v4"), ("v2", "v4"), ("v4", "v5"), ("v4", "v6")]
    edges += [("v5", "v7"), ("v3", "v7"), ("v7", "v8"), ("v7", "v9")]
    return msg(vertices, edges, labeled)


def blind_gap_x(labeled=()):
    """Solos a, b reappear after a blind gap as a2, b2, matched ambiguously (all four edges); a2, b2 join into g."""
    vertices = {"a": (1, 1), "b": (1, 2), "a2": (1, 3), "b2": (1, 4), "g": (2, 5)}
    edges = [("a", "a2"), ("a", "b2"), ("b", "a2"), ("b", "b2"), ("a2", "g"), ("b2", "g")]
    return msg(vertices, edges, labeled)


# --- oracles -------------------------------------------------------------------------------------------------------


def unlabeled_paths_to(graph, vertex):
    """Every unlabeled path ending at ``vertex``, as a list from its first vertex, by exhaustive backward extension."""
    paths, stack = [], [[vertex]]
    while stack:
        path = stack.pop()
        paths.append(path)
        if not is_labeled(graph, path[0]):
            stack.extend([parent, *path] for parent in graph.pred[path[0]])
    return paths


def brute_force_data(graph, vertex):
    """The traversal quantities by enumerating paths: n_o, n_notL, origins, n_ret, dL_dir, and the p_left chain."""
    paths = unlabeled_paths_to(graph, vertex)

    def origin_like(path):
        return is_labeled(graph, path[0]) or not graph.pred[path[0]]

    def n_unlabeled(member):
        starts = [path[0] for path in unlabeled_paths_to(graph, member)]
        return sum(1 for start in starts if not graph.pred[start] and not is_labeled(graph, start))

    from_labeled = [path for path in paths if is_labeled(graph, path[0])]
    one_child_before_end = [path for path in from_labeled if all(len(graph.succ[x]) == 1 for x in path[:-1])]
    off_chain_length = 0.0
    for path in from_labeled:
        on_chain = True
        for predecessor, x in zip(path, path[1:], strict=False):
            on_chain = on_chain and len(graph.succ[predecessor]) == 1
            off_chain_length += 0.0 if on_chain else graph.nodes[x]["length"]

    chain = []
    if not is_labeled(graph, vertex):
        chain = [vertex]
        while True:
            with_unlabeled = [parent for parent in graph.pred[chain[-1]] if n_unlabeled(parent) > 0]
            if len(with_unlabeled) != 1:
                break
            chain.append(with_unlabeled[0])
    n_o = sum(1 for path in paths if origin_like(path))
    n_notL = sum(1 for path in paths if origin_like(path) and not is_labeled(graph, path[0]))
    origin_counts = {}
    for path in paths:
        if origin_like(path) and is_solo(graph, path[0]):
            origin_counts[path[0]] = origin_counts.get(path[0], 0) + 1
    solos = [x for x in chain if is_solo(graph, x)]
    labeled = is_labeled(graph, vertex)
    return {
        "n_o": n_o,
        "n_notL": n_notL,
        "n_L": n_o - n_notL,
        "p_left": chain[1] if len(chain) > 1 else None,
        "C": solos[-1] if solos and n_notL > 0 else None,
        "L_notdir": sum(graph.nodes[x]["length"] * n_unlabeled(x) for x in chain),
        "n_ret": 1 if labeled else len(one_child_before_end),
        "dL_dir": 0.0 if labeled else off_chain_length,
        "origins": origin_counts,
    }


def recursion_oracle(graph):
    """Equations 2, 3, 4, 7, 8, 9, 11, 12 as printed, for every vertex in topological order."""
    data = {}
    for v in nx.topological_sort(graph):
        labeled, parents, length = is_labeled(graph, v), list(graph.pred[v]), graph.nodes[v]["length"]
        n_notL = 0 if labeled else 1 if not parents else sum(data[p]["n_notL"] for p in parents)
        n_o = 1 if labeled or not parents else sum(data[p]["n_o"] for p in parents)
        with_unlabeled = [p for p in parents if data[p]["n_notL"] > 0]
        p_left = with_unlabeled[0] if len(with_unlabeled) == 1 else None
        if n_notL == 0:
            candidate = None
        elif p_left is not None and data[p_left]["C"] is not None:
            candidate = data[p_left]["C"]
        else:
            candidate = v if is_solo(graph, v) else None
        if labeled:
            not_direct, n_ret, direct = 0.0, 1, 0.0
        else:
            not_direct = length * n_notL + (data[p_left]["L_notdir"] if p_left is not None else 0.0)
            n_ret = sum(data[p]["n_ret"] for p in parents if len(graph.succ[p]) == 1)
            direct = length * (n_o - n_notL - n_ret) + sum(data[p]["dL_dir"] for p in parents)
        data[v] = {
            "n_o": n_o,
            "n_notL": n_notL,
            "n_L": n_o - n_notL,
            "p_left": p_left,
            "C": candidate,
            "L_notdir": not_direct,
            "n_ret": n_ret,
            "dL_dir": direct,
        }
    return data


@st.composite
def msg_graphs(draw, max_vertices=12):
    """Random DAGs over 0..n-1 (edges i -> j, i < j) with random counts, lengths, and labels on solo vertices."""
    size = draw(st.integers(1, max_vertices))
    density = draw(st.sampled_from([10, 25, 45]))
    graph = nx.DiGraph()
    for name in range(size):
        count = draw(st.sampled_from([1, 1, 1, 2, 3]))
        labeled = count == 1 and draw(st.integers(0, 3)) == 0
        graph.add_node(name, count=count, labeled=labeled, length=float(draw(st.integers(0, 20))))
    for child in range(size):
        for parent in range(child):
            if draw(st.integers(0, 99)) < density:
                graph.add_edge(parent, child)
    return graph


# --- Figure 2 -------------------------------------------------------------------------------------------------------


def test_figure_2b_v1_v2_labeled_eliminates_to_v3_as_match_of_v9():
    data = traversal_data(figure_2b(labeled={"v1", "v2"}), "v9")
    assert data["p_left"] == "v7"
    assert data["C"] == "v3"


def test_figure_2b_v3_labeled_eliminates_to_non_source_v5_as_match_of_v9():
    data = traversal_data(figure_2b(labeled={"v3"}), "v9")
    assert data["C"] == "v5"
    assert unlabeled_origins(figure_2b(labeled={"v3"}), "v9") == {"v1", "v2"}


def test_figure_2b_without_labels_has_no_indirect_match_for_v9():
    graph = figure_2b()
    data = traversal_data(graph, "v9")
    assert origins(graph, "v9") == {"v1": 1, "v2": 1, "v3": 1}
    assert (data["n_o"], data["n_notL"], data["n_L"]) == (3, 3, 0)
    assert data["p_left"] == "v7"
    assert traversal_data(graph, "v7")["p_left"] is None  # both v5 and v3 carry unlabeled origins
    assert data["C"] == "v9"  # chain v9, v7 (compound): the candidate is v9 itself, no match by elimination
    assert data["L_notdir"] == 9 * 3 + 7 * 3


def test_figure_2b_labeled_v9_is_its_own_only_origin():
    data = traversal_data(figure_2b(labeled={"v3", "v9"}), "v9")
    assert data == {
        "n_o": 1, "n_notL": 0, "n_L": 1, "p_left": None, "C": None,
        "L_notdir": 0.0, "n_ret": 1, "dL_dir": 0.0, "S_P": 0.0,
    }  # fmt: skip
    assert origins(figure_2b(labeled={"v3", "v9"}), "v9") == {"v9": 1}


def test_figure_2b_v1_labeled_extends_forward_to_compound_v4_only():
    """Appendix A: labeled v1's single child v4 extends its labeling; v4 splits, so v5 is off the chain."""
    graph = figure_2b(labeled={"v1"})
    v4, v5 = traversal_data(graph, "v4"), traversal_data(graph, "v5")
    assert (v4["n_ret"], v4["dL_dir"]) == (1, 0.0)
    assert (v5["n_ret"], v5["dL_dir"]) == (0, 5.0)
    assert labeled_origins(graph, "v5") == {"v1"} and unlabeled_origins(graph, "v5") == {"v2"}
    assert [v5["p_left"], v5["C"]] == ["v4", "v2"]
    assert v5["L_notdir"] == 5 * 1 + 4 * 1 + 2 * 1
    assert v5["S_P"] == pytest.approx((5.0 + 11.0) / 2)
    assert past_ambiguity_score(graph, "v5") == v5["S_P"]


# --- blind-gap X ambiguity: counts are (origin, path) pairs ---------------------------------------------------------


def test_blind_gap_x_counts_each_origin_once_per_unlabeled_path():
    graph = blind_gap_x()
    assert origins(graph, "a2") == {"a": 1, "b": 1}
    assert origins(graph, "g") == {"a": 2, "b": 2}
    data = traversal_data(graph, "g")
    assert (data["n_o"], data["n_notL"]) == (4, 4)
    assert traversal_data(graph, "a2")["C"] == "a2"  # two parents with unlabeled origins: no elimination


def test_blind_gap_x_with_a_labeled():
    graph = blind_gap_x(labeled={"a"})
    a2, g = traversal_data(graph, "a2"), traversal_data(graph, "g")
    assert (a2["p_left"], a2["C"]) == ("b", "b")  # a2 is b's if it is not a's
    assert (g["n_o"], g["n_notL"], g["n_L"]) == (4, 2, 2)
    assert labeled_origins(graph, "g") == {"a"} and unlabeled_origins(graph, "g") == {"b"}
    assert g["n_ret"] == 0  # a has two children: no forward chain
    assert g["dL_dir"] == (3 + 5) + (4 + 5)  # paths a-a2-g and a-b2-g, all off the chain
    assert g["L_notdir"] == 5 * 2  # two parents carry unlabeled origins: p_left(g) is None
    assert g["S_P"] == pytest.approx((17 + 10) / 4)


# --- forward labeling chains ----------------------------------------------------------------------------------------


def test_forward_chains_from_two_labeled_vertices_meet():
    vertices = {"u": (1, 1), "w": (2, 2), "u2": (1, 3), "x": (2, 4), "y": (1, 5)}
    edges = [("u", "w"), ("w", "x"), ("u2", "x"), ("x", "y")]
    graph = msg(vertices, edges, labeled={"u", "u2"})
    assert [traversal_data(graph, v)["n_ret"] for v in ("w", "x", "y")] == [1, 2, 2]
    assert traversal_data(graph, "y")["dL_dir"] == 0.0  # everything is a forward extension
    graph.add_edge("x", "z")
    graph.nodes["z"].update(count=1, labeled=False, length=6.0)
    y = traversal_data(graph, "y")
    assert (y["n_ret"], y["n_L"], y["dL_dir"]) == (0, 2, 2 * 5.0)


def test_labeled_vertex_hides_its_ancestors():
    graph = msg({"a": (1, 1), "b": (1, 2), "c": (1, 3)}, [("a", "b"), ("b", "c")], labeled={"b"})
    data = traversal_data(graph, "c")
    assert origins(graph, "c") == {"b": 1}
    assert (data["n_o"], data["n_L"], data["n_ret"], data["C"]) == (1, 1, 1, None)


def test_traversal_does_not_look_past_labeled_vertices():
    graph = msg({"b": (1, 2), "c": (1, 3)}, [("b", "c")], labeled={"b"})
    graph.add_edge("hidden", "b")  # no attributes: reading them would raise
    assert traversal_data(graph, "c")["n_o"] == 1
    assert traversal_data(graph, "b")["n_o"] == 1


# --- conventions ----------------------------------------------------------------------------------------------------


def test_compound_source_counts_as_unlabeled_origin_but_is_not_one():
    """Equations 2 and 8 count any unlabeled source; the definition of an origin requires a solo vertex."""
    graph = msg({"g": (2, 4), "s": (1, 1)}, [("g", "s")], labeled={"g"})  # a compound is never labeled
    g, s = traversal_data(graph, "g"), traversal_data(graph, "s")
    assert (g["n_o"], g["n_notL"], g["C"]) == (1, 1, None)
    assert (s["n_o"], s["n_notL"], s["p_left"], s["C"]) == (1, 1, "g", "s")
    assert origins(graph, "s") == {} and origins(graph, "g") == {}


def test_future_ambiguity_score():
    graph = blind_gap_x(labeled={"a"})
    assert future_ambiguity_score(graph, "g", expected_join=True) == pytest.approx(2 / 4)
    assert future_ambiguity_score(graph, "g", expected_join=False) == 0.0


def test_cycle_is_rejected():
    graph = msg({"a": (1, 1), "b": (1, 1)}, [("a", "b"), ("b", "a")])
    with pytest.raises(ValueError, match="cycle"):
        traversal_data(graph, "a")


class _CountedLookups:
    """A mapping of a graph (its nodes, pred or succ) that counts the look-ups into it."""

    def __init__(self, mapping, counter: list):
        self.mapping, self.counter = mapping, counter

    def __getitem__(self, key):
        self.counter[0] += 1
        return self.mapping[key]


class _CountingGraph:
    """A DiGraph's nodes, pred and succ, each look-up counted: the work a traversal does on the graph."""

    def __init__(self, graph: nx.DiGraph):
        self.lookups = [0]
        self.nodes = _CountedLookups(graph.nodes, self.lookups)
        self.pred = _CountedLookups(graph.pred, self.lookups)
        self.succ = _CountedLookups(graph.succ, self.lookups)


@pytest.mark.parametrize("first_labeled", [False, True])
def test_long_chain_is_iterative_and_linear(first_labeled):
    """A chain far deeper than Python's recursion limit, read once per vertex (its attributes, parents and
    children: three look-ups): linear work, counted rather than timed."""
    size = 100_000
    graph = nx.DiGraph()
    graph.add_nodes_from((i, {"count": 1, "labeled": first_labeled and i == 0, "length": 1.0}) for i in range(size))
    graph.add_edges_from((i, i + 1) for i in range(size - 1))
    counting = _CountingGraph(graph)
    data = traversal_data(counting, size - 1)
    assert counting.lookups[0] <= 3 * size, counting.lookups[0]
    if first_labeled:
        assert (data["n_L"], data["n_ret"], data["dL_dir"], data["C"]) == (1, 1, 0.0, None)
    else:
        assert (data["n_notL"], data["p_left"], data["C"], data["L_notdir"]) == (1, size - 2, 0, float(size))


# --- properties on random DAGs --------------------------------------------------------------------------------------


@settings(deadline=None, max_examples=300)
@given(msg_graphs())
def test_traversal_matches_brute_force_path_enumeration(graph):
    for vertex in graph:
        data, expected = traversal_data(graph, vertex), brute_force_data(graph, vertex)
        assert origins(graph, vertex) == expected.pop("origins")
        for key, value in expected.items():
            assert data[key] == (pytest.approx(value) if isinstance(value, float) else value), key
        assert data["S_P"] == pytest.approx((expected["dL_dir"] + expected["L_notdir"]) / expected["n_o"])


@settings(deadline=None, max_examples=300)
@given(msg_graphs())
def test_traversal_matches_the_recursions(graph):
    """The recursions' values equal the traversal's, except p_left of a labeled vertex (None by the traversal's
    convention; equation 3 read literally may name a parent, which no other quantity then uses)."""
    recursion = recursion_oracle(graph)
    for vertex in graph:
        data = traversal_data(graph, vertex)
        for key, value in recursion[vertex].items():
            if key == "p_left" and is_labeled(graph, vertex):
                assert data[key] is None
            elif isinstance(value, float):
                assert data[key] == pytest.approx(value), key
            else:
                assert data[key] == value, key


@settings(deadline=None, max_examples=200)
@given(msg_graphs())
def test_direct_length_equals_its_per_vertex_form(graph):
    """dL_dir(v) = sum over unlabeled x of the cone of paths(x -> v) * length(x) * (n_L(x) - n_ret(x))."""
    for vertex in graph:
        if is_labeled(graph, vertex):
            continue
        paths_from = {}
        for path in unlabeled_paths_to(graph, vertex):
            paths_from[path[0]] = paths_from.get(path[0], 0) + 1
        per_vertex = 0.0
        for x, paths in paths_from.items():
            if not is_labeled(graph, x):
                data = traversal_data(graph, x)
                per_vertex += paths * graph.nodes[x]["length"] * (data["n_L"] - data["n_ret"])
        assert traversal_data(graph, vertex)["dL_dir"] == pytest.approx(per_vertex)
