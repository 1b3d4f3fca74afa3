"""Whom to zoom in on for a face, or whether to stay zoomed out (face-capture paper, sections 3.4-3.5).

The paper's scheduler scores every active, unlabelled solo tracklet v

    S_L(v) = E_s(v) (alpha(v) S_F(v) + beta(v) S_P(v)),    (eq. 5)

S_F(v) = Join(v) n_notL(v) / n_o(v): the chance that v's target has never
been labelled, if it is about to join others (labelling it now prevents
a future ambiguity); S_P(v) = (dL_dir(v) + L_notdir(v)) / n_o(v) (eq. 6): the
labelled length expected to be recovered in the past by matching v. Both
come from the auxiliary data in O(|parents|). It zooms in on the best v if
S_L(v) > S_zo, a constant.

The paper leaves alpha, beta and S_zo open ("alpha and beta are higher for
source and expected sink vertices"). S_P is a length in steps, S_F a
probability, so here alpha(v) carries a length: the steps v's target is
expected to remain in view (what a future ambiguity would leave unlabelled),
doubled for a source; beta(v) is 2 for a target expected to leave before
the camera could come back to it (within two zoom durations), else 1.

The naive scheduler [2] zooms in on the unlabelled target predicted to leave
first, whenever there is one whose face can be captured; it keeps no graph,
so its faces label tracklets but never untangle them. 'msg-no-untangling' is
the paper's scheduler with untangling switched off.
"""

from collections.abc import Callable
from dataclasses import dataclass

import networkx as nx

from ptztrack.scene.road_tracklets import TrackletOracle
from ptztrack.track.msg import refresh

# alpha's boost for a source and beta for a target expected to leave within this many zoom durations.
SOURCE_WEIGHT = 2.0
SINK_WEIGHT = 2.0
SINK_HORIZON_ZOOMS = 2.0


@dataclass(frozen=True)
class Candidate:
    """An active unlabelled solo tracklet whose face the camera could capture now."""

    vertex: int
    unit: frozenset
    steps_to_exit: float
    joins_soon: bool


def candidates(oracle: TrackletOracle, step: int) -> list[Candidate]:
    """The tracklets a zoom-in could label at ``step``: solo, unlabelled, E_s true."""
    found = []
    for unit, vertex in oracle.unit_vertex.items():
        if len(unit) != 1 or oracle.graph.nodes[vertex]["labeled"]:
            continue
        (person,) = unit
        if not oracle.capture_succeeds(step, person):
            continue
        joins_soon = oracle.joins_within(step, person, round(oracle.config.join_horizon_s * oracle.frame_rate_hz))
        found.append(Candidate(vertex, unit, oracle.steps_to_exit(step, person), joins_soon))
    return found


def labeling_score(graph: nx.DiGraph, candidate: Candidate, zoom_steps: int) -> float:
    """S_L(v) of eq. 5 for a candidate whose capture is expected to succeed (E_s = 1), in steps."""
    node = graph.nodes[candidate.vertex]
    future = candidate.joins_soon * node["n_notL"] / node["n_o"]
    past = (node["dL_dir"] + node["L_notdir"]) / node["n_o"]
    alpha = min(candidate.steps_to_exit, 1e6) * (SOURCE_WEIGHT if graph.in_degree(candidate.vertex) == 0 else 1.0)
    beta = SINK_WEIGHT if candidate.steps_to_exit <= SINK_HORIZON_ZOOMS * zoom_steps else 1.0
    return alpha * future + beta * past


def msg_choice(oracle: TrackletOracle, step: int, zoom_out_score: float) -> Candidate | None:
    """The paper's scheduler: the candidate of highest S_L, if above the zoom-out score S_zo."""
    best, best_score = None, zoom_out_score
    for candidate in candidates(oracle, step):
        refresh(oracle.graph, candidate.vertex)
        score = labeling_score(oracle.graph, candidate, oracle.config.zoom_steps)
        if score > best_score:
            best, best_score = candidate, score
    return best


def naive_choice(oracle: TrackletOracle, step: int, zoom_out_score: float) -> Candidate | None:
    """The naive scheduler: the candidate predicted to leave first."""
    found = candidates(oracle, step)
    return min(found, key=lambda c: (c.steps_to_exit, c.vertex)) if found else None


CHOOSERS: dict[str, Callable] = {"msg": msg_choice, "msg-no-untangling": msg_choice, "naive": naive_choice}
