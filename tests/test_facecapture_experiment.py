"""The face-capture experiment: no decision reads the future, the score M, and the paper's qualitative results."""

from dataclasses import replace

import networkx as nx
import numpy as np
import pytest

from ptztrack.facecapture import msg
from ptztrack.facecapture.experiment import (
    labelled_fraction,
    msg_cells,
    paired_difference_m,
    run_msg,
    run_msg_cell,
    summarise_by_ambiguity,
)
from ptztrack.facecapture.parameters import MsgExperimentParameters, TrackletTrackerParameters
from ptztrack.facecapture.road_camera import Blob
from ptztrack.facecapture.roads import RoadScene, walk_roads
from ptztrack.facecapture.scheduler import SCHEDULERS
from ptztrack.loop.executors import execute_cells

BUSY = replace(MsgExperimentParameters.scene, people=15, join_probability=0.7)


class TruthUpTo(np.ndarray):
    """A (T, ...) array of simulated truth that refuses to give out any step after ``last_step``."""

    last_step: int

    @classmethod
    def of(cls, array: np.ndarray, last_step: int) -> "TruthUpTo":
        guarded = array.view(cls)
        guarded.last_step = last_step
        return guarded

    def __getitem__(self, index):
        try:
            steps = np.arange(self.shape[0])[index[0] if isinstance(index, tuple) else index]
        except IndexError:  # a mask over more than the steps: it reads them all
            steps = np.arange(self.shape[0])
        if np.max(steps, initial=-1) > self.last_step:
            raise AssertionError(f"read the truth of step {np.max(steps)} with only up to {self.last_step} known")
        return np.asarray(self)[index]


def with_truth_replaced_after(scene: RoadScene, step: int, continuation: str) -> RoadScene:
    """``scene`` with every person's truth after ``step`` replaced, by nothing (absent) or by another walk,
    and unreadable."""
    positions_m, group_id, heading = scene.positions_m.copy(), scene.group_id.copy(), scene.heading.copy()
    if continuation == "nothing":
        positions_m[step + 1 :], heading[step + 1 :], group_id[step + 1 :] = np.nan, np.nan, -1
    else:
        other = walk_roads(BUSY, np.random.default_rng(99))
        positions_m[step + 1 :], heading[step + 1 :] = other.positions_m[step + 1 :], other.heading[step + 1 :]
        group_id[step + 1 :] = np.where(other.group_id[step + 1 :] >= 0, other.group_id[step + 1 :] + 1000, -1)
    truth = {"positions_m": positions_m, "group_id": group_id, "heading": heading}
    return replace(scene, **{name: TruthUpTo.of(array, step) for name, array in truth.items()})


def test_the_guarded_truth_refuses_the_steps_after_its_last():
    truth = TruthUpTo.of(np.zeros((10, 3, 2)), 4)
    assert truth[4, 1].shape == (2,) and truth[:5].shape == (5, 3, 2)
    for index in (5, (7, 0), slice(3, 6), (Ellipsis, 0), np.zeros((10, 3), dtype=bool)):
        with pytest.raises(AssertionError, match="read the truth of step"):
            truth[index]


@pytest.mark.parametrize("scheduler", list(SCHEDULERS))
def test_no_decision_reads_the_future_cutting_the_truth_after_a_step_changes_nothing_up_to_it(scheduler):
    scene = walk_roads(BUSY, np.random.default_rng(3))
    full = run_msg(scene, scheduler, seed=3)
    # Cut where a zoom is decided, where its face is captured, and anywhere.
    decided = next(step for step, _ in full.zooms if step >= 150)
    for step in (decided, decided + TrackletTrackerParameters().zoom_steps, 300):
        original = run_msg(scene, scheduler, seed=3, steps=step + 1)
        assert original.zooms == [zoom for zoom in full.zooms if zoom[0] <= step]
        for continuation in ("nothing", "another walk"):
            cut = run_msg(with_truth_replaced_after(scene, step, continuation), scheduler, seed=3, steps=step + 1)
            assert cut.zooms == original.zooms and cut.captures == original.captures
            assert nx.utils.graphs_equal(cut.graph, original.graph)
            assert cut.blobs == original.blobs


def test_m_counts_the_labelled_person_steps_along_labelling_chains_on_the_blobs_that_held_the_face():
    graph = msg.new_graph()
    a, b = msg.add_tracklets(graph, [(1, [0], []), (1, [1], [])], 0)
    (group,) = msg.add_tracklets(graph, [(2, [2], [a, b])], 10)
    a2, b2 = msg.add_tracklets(graph, [(1, [3], [group]), (1, [4], [group])], 15)
    blobs = {
        0: Blob(frozenset({0}), 0, 9),
        1: Blob(frozenset({1}), 0, 9),
        2: Blob(frozenset({0, 1}), 10, 14),
        3: Blob(frozenset({0}), 15, 24),
        4: Blob(frozenset({1}), 15, 24),
    }
    total = 10 + 10 + 2 * 5 + 10 + 10
    assert labelled_fraction(graph, blobs) == 0.0
    graph.nodes[a].update(labeled=True, face=0)
    # a's only child is the group: the label reaches it (forward chain), for person 0 only.
    assert labelled_fraction(graph, blobs) == pytest.approx((10 + 5) / total)
    graph.nodes[b2].update(labeled=True, face=1)
    # b2's only parent is the group (backward chain), which held person 1 too.
    assert labelled_fraction(graph, blobs) == pytest.approx((10 + 5 + 10 + 5) / total)
    # A label on a tracklet of somebody else (a wrong association) earns nothing.
    graph.nodes[a2].update(labeled=True, face=1)
    assert labelled_fraction(graph, blobs) == pytest.approx((10 + 5 + 10 + 5) / total)


def test_differences_pair_up_run_by_run():
    rows = [
        {"scheduler": name, "seed": seed, "nj_s": nj_s, "m": m}
        for name, seed, nj_s, m in [
            ("a", 0, 14, 0.9), ("b", 0, 14, 0.7),
            ("a", 1, 16, 0.8), ("b", 1, 16, 0.7),
            ("a", 2, 3, 0.5), ("b", 2, 3, 0.8),
        ]
    ]  # fmt: skip
    mean, se, runs = paired_difference_m(rows, "a", "b", nj_s=15)
    assert (mean, runs) == (pytest.approx(0.15), 2) and se == pytest.approx(0.05)
    assert paired_difference_m(rows, "a", "b")[::2] == (pytest.approx(0.0), 3)


def test_a_run_is_reproducible_and_every_scheduler_captures_faces():
    scene = walk_roads(
        replace(MsgExperimentParameters.scene, people=12, join_probability=0.7), np.random.default_rng(3)
    )
    for scheduler in SCHEDULERS:
        first, second = run_msg(scene, scheduler, seed=1), run_msg(scene, scheduler, seed=1)
        assert first.m == second.m and first.captures == second.captures
        assert len(first.captures) > 0 and 0 < first.m <= 1
    with pytest.raises(ValueError, match="unknown scheduler"):
        run_msg(scene, "greedy")


@pytest.mark.slow
def test_the_paper_scheduler_labels_more_than_the_naive_one_and_untangling_helps():
    rows = [row for rows in execute_cells(msg_cells(16), run_msg_cell, "serial") for row in rows]
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
    assert execute_cells(cells, run_msg_cell, "local", workers=2) == execute_cells(cells, run_msg_cell, "serial")
