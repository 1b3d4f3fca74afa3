"""The MSG's auxiliary data against the traversal reference, under random growth, labelling and untangling."""

import networkx as nx
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from msg_traversal import traversal_data
from ptztrack.facecapture import msg

# Weighted so that labels often come after joins and splits: untangling through compound vertices.
OPERATIONS = (
    "enter",
    "enter",
    "extend",
    "join",
    "join",
    "split",
    "split",
    "blind_gap",
    "exit",
    "label",
    "label",
    "label",
)


def total_length(graph):
    return sum(node["count"] * node["length"] for _, node in graph.nodes(data=True))


class Scene:
    """Targets moving through the events a tracker reports, building an MSG as the tracker layer does,
    with every true association among the edges. Each new tracklet is one blob, whose people ``truth`` keeps."""

    def __init__(self, untangling=True):
        self.graph = msg.new_graph()
        self.active = {}  # vertex -> the targets it holds
        self.truth = {}  # blob -> the targets it held
        self.next_target = 0
        self.step = 0
        self.untangling = untangling

    def start(self, events):
        blobs = range(len(self.truth), len(self.truth) + len(events))
        self.truth.update(zip(blobs, (frozenset(targets) for targets, _ in events), strict=True))
        tracklets = [(len(targets), [blob], parents) for (targets, parents), blob in zip(events, blobs, strict=True)]
        created = msg.add_tracklets(self.graph, tracklets, self.step)
        for (targets, parents), v in zip(events, created, strict=True):
            for p in parents:
                self.active.pop(p, None)
            self.active[v] = frozenset(targets)
            msg.extend(self.graph, v, self.step)

    def people(self, v):
        """Everybody in the blobs of v."""
        return frozenset().union(*(self.truth[blob] for blob in self.graph.nodes[v]["blobs"]))

    def apply(self, operation, draw):
        self.step += 1
        active = sorted(self.active)
        if operation == "enter" or not active:
            self.start([(frozenset({self.next_target}), [])])
            self.next_target += 1
        elif operation == "extend":
            msg.extend(self.graph, draw(st.sampled_from(active)), self.step, draw(st.integers(1, 5)))
        elif operation == "join" and len(active) >= 2:
            a, b = draw(st.lists(st.sampled_from(active), min_size=2, max_size=2, unique=True))
            self.start([(self.active[a] | self.active[b], [a, b])])
        elif operation == "split":
            compounds = [v for v in active if len(self.active[v]) > 1]
            if compounds:
                v = draw(st.sampled_from(compounds))
                targets = sorted(self.active[v])
                cut = draw(st.integers(1, len(targets) - 1))
                self.start([(frozenset(targets[:cut]), [v]), (frozenset(targets[cut:]), [v])])
        elif operation == "blind_gap" and len(active) >= 2:
            lost = draw(st.lists(st.sampled_from(active), min_size=2, max_size=4, unique=True))
            # Every unit seen again gets an edge from each lost tracklet (the truth among them).
            self.start([(self.active[v], lost) for v in lost])
        elif operation == "exit":
            v = draw(st.sampled_from(active))
            del self.active[v]
            self.graph.nodes[v]["active"] = False
        elif operation == "label":
            solos = [v for v in active if len(self.active[v]) == 1 and not self.graph.nodes[v]["labeled"]]
            if solos:
                v = draw(st.sampled_from(solos))
                msg.refresh(self.graph, v)
                (face,) = self.active[v]
                merged_into = msg.label(self.graph, v, face, self.untangling)
                self.active = {merged_into.get(u, u): targets for u, targets in self.active.items()}

    def check_against_traversal(self):
        for v in self.active:
            msg.refresh(self.graph, v)
        for v in self.graph:
            expected = traversal_data(self.graph, v)
            stored = {field: self.graph.nodes[v][field] for field in msg.AUX_FIELDS}
            assert stored == {field: expected[field] for field in msg.AUX_FIELDS}, (v, stored, expected)


@pytest.mark.slow
@settings(max_examples=1000, deadline=None)
@given(st.data())
def test_auxiliary_data_equals_traversal_through_growth_labelling_and_untangling(data):
    scene = Scene(untangling=data.draw(st.booleans()))
    for _ in range(data.draw(st.integers(1, 40))):
        before, had_active = total_length(scene.graph), bool(scene.active)
        operation = data.draw(st.sampled_from(OPERATIONS))
        scene.apply(operation, data.draw)
        if operation == "label" and had_active:
            assert total_length(scene.graph) == before
        assert nx.is_directed_acyclic_graph(scene.graph)
        scene.check_against_traversal()
    for v, node in scene.graph.nodes(data=True):
        assert node["count"] <= len(scene.people(v))
        if not node["labeled"]:
            continue
        assert node["count"] == 1
        # Labels are right: every blob of a labelled tracklet held its face.
        assert all(node["face"] in scene.truth[blob] for blob in node["blobs"])
        # No true association is lost: a labelled tracklet's target came from one of its parents, if it has any.
        parents = scene.graph.pred[v]
        if parents:
            assert any(node["face"] in scene.people(p) for p in parents)
