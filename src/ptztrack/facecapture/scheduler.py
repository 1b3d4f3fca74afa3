"""Whom to zoom in on for a face, or whether to stay zoomed out (face-capture paper, sections 3.4-3.5).

The schedulers read only the tracklet tracker (:mod:`ptztrack.facecapture.tracklets`):
its graph and its predictions. A candidate is a tracklet in view that is
solo, unlabelled and whose capture the tracker expects to succeed (E_s).

The paper's scheduler scores every candidate v

    S_L(v) = E_s(v) (alpha(v) S_F(v) + beta(v) S_P(v)),    (eq. 5)

S_F(v) = Join(v) n_notL(v) / n_o(v): the chance that v's target has never
been labelled, if it is predicted to meet others (labelling it now prevents
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

The naive scheduler [2] zooms in on the candidate predicted to leave first,
whenever there is one. A scheduler is a selection rule and whether captured
faces untangle the graph (:data:`SCHEDULERS`): the paper's three, and two
ablations of equation 5, 'msg-no-join' (S_F off) and 'leave-first' (the
naive rule with untangling).
"""

from collections.abc import Callable
from dataclasses import dataclass

import networkx as nx

from ptztrack.facecapture.msg import refresh
from ptztrack.facecapture.parameters import SchedulerParameters
from ptztrack.facecapture.tracklets import TrackletTracker

_WEIGHTS = SchedulerParameters()


@dataclass(frozen=True)
class Candidate:
    """A tracklet in view, solo and unlabelled, whose face the tracker expects a capture to get.

    vertex : its MSG vertex; blob : the unit the camera sees; steps_to_exit : predicted steps until it leaves;
    joins_soon : Join(v), a meeting predicted within the join horizon; aim_m : (2,) its predicted position
    at the capture, where the camera is to aim.
    """

    vertex: int
    blob: int
    steps_to_exit: float
    joins_soon: bool
    aim_m: tuple[float, float]


def candidates(tracker: TrackletTracker, step: int) -> list[Candidate]:
    """The tracklets a zoom-in at ``step`` could label: solo, unlabelled, E_s true."""
    horizon_steps = round(tracker.config.join_horizon_s * tracker.frame_rate_hz)
    found = []
    for blob, vertex in tracker.vertex_of.items():
        if tracker.graph.nodes[vertex]["count"] != 1 or tracker.graph.nodes[vertex]["labeled"]:
            continue
        if not tracker.capture_expected(blob):
            continue
        aim_m = tracker.predicted_position_m(blob, tracker.config.zoom_steps)
        found.append(
            Candidate(
                vertex,
                blob,
                tracker.steps_to_exit(blob),
                tracker.meets_within(blob, horizon_steps),
                (float(aim_m[0]), float(aim_m[1])),
            )
        )
    return found


def labeling_score(graph: nx.DiGraph, candidate: Candidate, zoom_steps: int, future_term: bool = True) -> float:
    """S_L(v) of eq. 5 for a candidate whose capture is expected to succeed (E_s = 1), in steps;
    ``future_term`` False drops alpha S_F (Join = 0)."""
    node = graph.nodes[candidate.vertex]
    future = future_term * candidate.joins_soon * node["n_notL"] / node["n_o"]
    past = (node["dL_dir"] + node["L_notdir"]) / node["n_o"]
    alpha = min(candidate.steps_to_exit, 1e6) * (
        _WEIGHTS.source_weight if graph.in_degree(candidate.vertex) == 0 else 1.0
    )
    beta = _WEIGHTS.sink_weight if candidate.steps_to_exit <= _WEIGHTS.sink_horizon_zooms * zoom_steps else 1.0
    return alpha * future + beta * past


def msg_choice(
    tracker: TrackletTracker, step: int, zoom_out_score: float, future_term: bool = True
) -> Candidate | None:
    """The paper's scheduler: the candidate of highest S_L, if above the zoom-out score S_zo."""
    best, best_score = None, zoom_out_score
    for candidate in candidates(tracker, step):
        refresh(tracker.graph, candidate.vertex)
        score = labeling_score(tracker.graph, candidate, tracker.config.zoom_steps, future_term)
        if score > best_score:
            best, best_score = candidate, score
    return best


def msg_no_join_choice(tracker: TrackletTracker, step: int, zoom_out_score: float) -> Candidate | None:
    """The paper's scheduler with S_F off (Join = 0): S_L = beta S_P."""
    return msg_choice(tracker, step, zoom_out_score, future_term=False)


def leave_first_choice(tracker: TrackletTracker, step: int, zoom_out_score: float) -> Candidate | None:
    """The naive rule: the candidate predicted to leave first (S_zo plays no part)."""
    found = candidates(tracker, step)
    return min(found, key=lambda c: (c.steps_to_exit, c.vertex)) if found else None


@dataclass(frozen=True)
class Scheduler:
    """A selection rule (tracker, step, S_zo) -> candidate or None, and whether faces untangle the graph."""

    choose: Callable[[TrackletTracker, int, float], Candidate | None]
    untangling: bool


SCHEDULERS: dict[str, Scheduler] = {
    "msg": Scheduler(msg_choice, untangling=True),
    "msg-no-untangling": Scheduler(msg_choice, untangling=False),
    "naive": Scheduler(leave_first_choice, untangling=False),
    "msg-no-join": Scheduler(msg_no_join_choice, untangling=True),
    "leave-first": Scheduler(leave_first_choice, untangling=True),
}
