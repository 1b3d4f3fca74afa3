"""The face-capture experiment: the tracker layer's graph, the score M, and the paper's qualitative results."""

from dataclasses import replace

import numpy as np
import pytest

from ptztrack.evaluate.executors import run_cells
from ptztrack.evaluate.msg import (
    EXPERIMENT_SCENE,
    labelled_fraction,
    msg_cells,
    run_msg,
    run_msg_cell,
    summarise_by_ambiguity,
)
from ptztrack.scene.road_tracklets import TrackletOracle, TrackletOracleConfig
from ptztrack.scene.roads import walk_roads
from ptztrack.track import msg

SPACING_M = 10.0


def straight_walks(starts_m, headings, steps: int, speed_m_s: float = 1.0, rate_hz: float = 5.0):
    """Walkers on straight roads from ``starts_m`` (N, 2) along unit ``headings`` (N, 2)."""
    time_s = np.arange(steps)[:, None, None] / rate_hz
    positions_m = np.asarray(starts_m, float)[None] + np.asarray(headings, float)[None] * speed_m_s * time_s
    heading = np.broadcast_to(np.asarray(headings, float), positions_m.shape).copy()
    return positions_m, heading


def tracker_for(positions_m, group_id, heading, zoom_steps=5):
    return TrackletOracle(
        positions_m, group_id, heading, 40.0, 5.0, 1.0, SPACING_M, TrackletOracleConfig(zoom_steps=zoom_steps)
    )


def test_a_join_and_a_split_become_a_compound_vertex_between_solo_ones():
    diagonal = np.array([1.0, 1.0]) / np.sqrt(2)
    positions_m, heading = straight_walks([[5.0, 5.0], [5.0, 5.0]], [diagonal, diagonal], 30)
    group_id = np.full((30, 2), -1)
    group_id[10:20] = 0  # walking together for steps 10-19
    tracker = tracker_for(positions_m, group_id, heading)
    for step in range(30):
        tracker.observe(step)
    graph = tracker.graph
    compound = [v for v in graph if graph.nodes[v]["count"] == 2]
    assert len(compound) == 1
    (c,) = compound
    assert graph.in_degree(c) == 2 and graph.out_degree(c) == 2
    assert graph.nodes[c]["length"] == 10
    # Every observed person-step is in exactly one tracklet.
    assert sum(node["count"] * node["length"] for _, node in graph.nodes(data=True)) == 60


def test_a_blind_gap_makes_x_ambiguities_only_between_walkers_who_could_have_swapped():
    along = np.array([1.0, 1.0]) / np.sqrt(2)
    # Two walkers half a metre apart on one road, a third far away.
    positions_m, heading = straight_walks([[5.0, 5.0], [5.35, 5.35], [30.0, 10.0]], [along, along, along], 40)
    tracker = tracker_for(positions_m, np.full((40, 3), -1), heading)
    for step in range(10):
        tracker.observe(step)
    zoomed = frozenset({2})
    for step in range(10, 16):
        tracker.observe(step, zoomed)
    tracker.observe(16)
    graph = tracker.graph
    near = [tracker.unit_vertex[frozenset({0})], tracker.unit_vertex[frozenset({1})]]
    for v in near:
        assert graph.in_degree(v) == 2  # either of the two lost tracklets could be this one
    far = tracker.unit_vertex[zoomed]
    assert graph.nodes[far]["length"] == 17 and graph.in_degree(far) == 0


def test_m_counts_labelled_length_per_target_with_labelling_chains():
    graph = msg.new_graph()
    a, b = msg.add_tracklets(graph, [({0}, []), ({1}, [])], 0)
    msg.extend(graph, a, 9, 10)
    msg.extend(graph, b, 9, 10)
    (group,) = msg.add_tracklets(graph, [({0, 1}, [a, b])], 10)
    msg.extend(graph, group, 14, 5)
    a2, b2 = msg.add_tracklets(graph, [({0}, [group]), ({1}, [group])], 15)
    msg.extend(graph, a2, 24, 10)
    msg.extend(graph, b2, 24, 10)
    total = 10 + 10 + 2 * 5 + 10 + 10
    assert labelled_fraction(graph) == 0.0
    graph.nodes[a]["labeled"] = True
    # a's only child is the group: the label reaches it (forward chain), for target 0 only.
    assert labelled_fraction(graph) == pytest.approx((10 + 5) / total)
    graph.nodes[b2]["labeled"] = True
    # b2's only parent is the group (backward chain), which holds target 1 too.
    assert labelled_fraction(graph) == pytest.approx((10 + 5 + 10 + 5) / total)


def test_a_run_is_reproducible_and_every_scheduler_captures_faces():
    scene = walk_roads(replace(EXPERIMENT_SCENE, people=12, join_probability=0.7), np.random.default_rng(3))
    for scheduler in ("msg", "msg-no-untangling", "naive"):
        first, second = run_msg(scene, scheduler), run_msg(scene, scheduler)
        assert first.m == second.m and first.captures == second.captures
        assert len(first.captures) > 0 and 0 < first.m <= 1
    with pytest.raises(ValueError, match="unknown scheduler"):
        run_msg(scene, "greedy")


@pytest.mark.slow
def test_the_paper_scheduler_labels_more_than_the_naive_one_and_untangling_helps():
    rows = [row for rows in run_cells(msg_cells(16), run_msg_cell, "serial") for row in rows]
    mean_m = {
        scheduler: np.mean([row["m"] for row in rows if row["scheduler"] == scheduler])
        for scheduler in ("msg", "msg-no-untangling", "naive")
    }
    assert mean_m["msg"] > mean_m["naive"]
    assert mean_m["msg"] > mean_m["msg-no-untangling"]
    summary = summarise_by_ambiguity(rows)
    assert sum(row["runs"] for row in summary) == len(rows)


@pytest.mark.slow
def test_local_processes_and_serial_give_the_same_rows():
    cells = msg_cells(4)
    assert run_cells(cells, run_msg_cell, "local", workers=2) == run_cells(cells, run_msg_cell, "serial")
