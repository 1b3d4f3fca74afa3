"""The face-capture experiment (MSG paper, section 4): simulate, schedule, score M against N_j/s.

One run: a road-grid scene (:mod:`ptztrack.scene.roads`) watched by one PTZ
camera. Every zoomed-out step the scheduler either stays zoomed out or zooms
in on one walker for ``zoom_steps`` to capture a face; the tracklet oracle
(:mod:`ptztrack.scene.road_tracklets`) grows the tracklet graph meanwhile, and a
captured face labels the walker's tracklet, matches it and (unless switched
off) untangles the graph. The three schedulers of a run see the same scene.

The score (eq. 1) is M = sum_z |tau_L(z)| / sum_z sum_i |tau_i(z)|: the part
of every target's tracklets, counted once per target a tracklet holds, that
is labelled with the target. A labelled tracklet's label also reaches along
its forward and backward labelling chains (a vertex that is its parent's
only child, a parent that is its child's only parent), as in the paper's
experiments; only tracklets that really hold the target count.
"""

from dataclasses import dataclass, replace

import matplotlib
import networkx as nx
import numpy as np
from matplotlib.figure import Figure

from ptztrack.control.msg_scheduler import CHOOSERS
from ptztrack.scene.road_tracklets import TrackletOracle, TrackletOracleConfig
from ptztrack.scene.roads import RoadScene, RoadSceneConfig, joins_and_splits, walk_roads
from ptztrack.track.msg import label

DEFAULT_ZOOM_OUT_SCORE = 5.0


@dataclass(frozen=True)
class MsgRun:
    """What a run left: the final graph, the captures (step, person) and the score."""

    graph: nx.DiGraph
    captures: list[tuple[int, int]]
    m: float
    nj_s: int


def run_msg(
    scene: RoadScene,
    scheduler: str,
    config: TrackletOracleConfig | None = None,
    zoom_out_score: float = DEFAULT_ZOOM_OUT_SCORE,
) -> MsgRun:
    """Run one scheduler ('msg', 'msg-no-untangling' or 'naive') over a scene (``config``: the
    oracle's, by default :class:`TrackletOracleConfig`'s defaults)."""
    config = config or TrackletOracleConfig()
    if scheduler not in CHOOSERS:
        raise ValueError(f"unknown scheduler {scheduler!r}; expected one of {', '.join(CHOOSERS)}")
    choose = CHOOSERS[scheduler]
    untangling = scheduler == "msg"
    oracle = TrackletOracle(
        scene.positions_m,
        scene.group_id,
        scene.heading,
        scene.area_m,
        scene.frame_rate_hz,
        float(np.max(scene.speed_m_s)),
        scene.road_spacing_m,
        config,
    )
    captures = []
    zoomed, zoom_end = None, -1
    for step in range(len(scene.positions_m)):
        if zoomed is not None and step <= zoom_end:
            oracle.observe(step, zoomed.unit)
            continue
        if zoomed is not None:
            vertex = oracle.unit_vertex[zoomed.unit]
            oracle.relabel(label(oracle.graph, vertex, untangling))
            captures.append((step - 1, next(iter(zoomed.unit))))
            zoomed = None
        oracle.observe(step)
        zoomed = choose(oracle, step, zoom_out_score)
        zoom_end = step + config.zoom_steps
    m = labelled_fraction(oracle.graph, chains=scheduler != "naive")
    return MsgRun(oracle.graph, captures, m, int(joins_and_splits(scene).sum()))


def labelled_fraction(graph: nx.DiGraph, chains: bool = True) -> float:
    """M of eq. 1 on a final graph; ``chains``: labels reach along labelling chains."""
    total = sum(node["count"] * node["length"] for _, node in graph.nodes(data=True))
    if total == 0:
        return float("nan")
    labelled = 0.0
    for target, vertices in _labelled_reach(graph, chains).items():
        labelled += sum(graph.nodes[v]["length"] for v in vertices if target in graph.nodes[v]["targets"])
    return labelled / total


def _labelled_reach(graph: nx.DiGraph, chains: bool = True) -> dict:
    """{target: vertices its labels reach}: labelled vertices, and with ``chains`` their forward and
    backward labelling chains."""
    reach: dict = {}
    for v, node in graph.nodes(data=True):
        if not node["labeled"]:
            continue
        (target,) = node["targets"]
        vertices = reach.setdefault(target, set())
        vertices.add(v)
        if not chains:
            continue
        for step_to, degree in ((graph.succ, graph.out_degree), (graph.pred, graph.in_degree)):
            x = v
            while degree(x) == 1:
                (x,) = step_to[x]
                if target not in graph.nodes[x]["targets"] or x in vertices:
                    break
                vertices.add(x)
    return reach


# The experiment's scenes: walkers who stay a while and meet often, so that a
# few dozen of them reach the paper's range of N_j/s (0-40).
EXPERIMENT_SCENE = RoadSceneConfig(
    meet_radius_m=3.0, group_duration_s=(3.0, 10.0), stay_s=(40.0, 90.0), duration_s=150.0, entry_window_s=(0.0, 60.0)
)
PEOPLE_RANGE = (8, 26)
JOIN_PROBABILITY_RANGE = (0.1, 0.95)
BIN_WIDTH = 5


@dataclass(frozen=True)
class MsgCell:
    """One simulation of the experiment, run by every scheduler: its seed fixes the scene."""

    seed: int
    scene: RoadSceneConfig
    tracklets: TrackletOracleConfig = TrackletOracleConfig()
    zoom_out_score: float = DEFAULT_ZOOM_OUT_SCORE


def msg_cells(runs: int, base: RoadSceneConfig = EXPERIMENT_SCENE) -> list[MsgCell]:
    """``runs`` simulations across ambiguity levels: people and join probability drawn per run from its seed."""
    cells = []
    for seed in range(runs):
        rng = np.random.default_rng([seed, 1])
        people = int(rng.integers(*PEOPLE_RANGE))
        join_probability = float(rng.uniform(*JOIN_PROBABILITY_RANGE))
        cells.append(MsgCell(seed, replace(base, people=people, join_probability=join_probability)))
    return cells


def run_msg_cell(cell: MsgCell) -> list[dict]:
    """One row per scheduler: ``scheduler``, ``nj_s``, ``m``, ``captures``, ``seed``, ``people``,
    ``join_probability``."""
    scene = walk_roads(cell.scene, np.random.default_rng(cell.seed))
    rows = []
    for scheduler in CHOOSERS:
        run = run_msg(scene, scheduler, cell.tracklets, cell.zoom_out_score)
        rows.append(
            {
                "scheduler": scheduler,
                "nj_s": run.nj_s,
                "m": run.m,
                "captures": len(run.captures),
                "seed": cell.seed,
                "people": cell.scene.people,
                "join_probability": cell.scene.join_probability,
            }
        )
    return rows


def summarise_by_ambiguity(rows: list[dict], bin_width: int = BIN_WIDTH) -> list[dict]:
    """Per scheduler and N_j/s bin centred on a multiple of ``bin_width`` (``nj_s`` the centre, the bin
    [nj_s - bin_width / 2, nj_s + bin_width / 2)): runs, mean M and its standard deviation."""
    summary = []
    for scheduler in dict.fromkeys(row["scheduler"] for row in rows):
        mine = [row for row in rows if row["scheduler"] == scheduler]
        centres = np.floor(np.array([row["nj_s"] for row in mine]) / bin_width + 0.5).astype(int) * bin_width
        m = np.array([row["m"] for row in mine])
        for centre in np.unique(centres):
            values = m[centres == centre]
            summary.append(
                {
                    "scheduler": scheduler,
                    "nj_s": int(centre),
                    "runs": int(len(values)),
                    "m_mean": float(values.mean()),
                    "m_std": float(values.std()),
                }
            )
    return summary


def format_ambiguity_table(summary: list[dict]) -> str:
    """Rows: N_j/s bins by centre; columns: schedulers, mean M +- standard deviation (runs)."""
    schedulers = list(dict.fromkeys(row["scheduler"] for row in summary))
    cells = {(row["scheduler"], row["nj_s"]): row for row in summary}
    lines = ["N_j/s " + "".join(f"{name:>26}" for name in schedulers)]
    for centre in sorted({row["nj_s"] for row in summary}):
        line = f"{centre:>5} "
        for name in schedulers:
            row = cells.get((name, centre))
            line += f"{row['m_mean']:>14.3f} +- {row['m_std']:.3f} ({row['runs']:>3})" if row else f"{'':>27}"
        lines.append(line)
    return "\n".join(lines)


def ambiguity_figure(rows: list[dict], bin_width: int = BIN_WIDTH) -> Figure:
    """M against N_j/s per scheduler, mean and standard deviation per bin, like the paper's Figure 7."""
    figure = Figure(figsize=(7, 4.5))
    axes = figure.add_subplot()
    summary = summarise_by_ambiguity(rows, bin_width)
    schedulers = list(dict.fromkeys(row["scheduler"] for row in summary))
    offsets = np.linspace(-0.6, 0.6, len(schedulers)) if len(schedulers) > 1 else [0.0]
    for offset, scheduler in zip(offsets, schedulers, strict=True):
        mine = [row for row in summary if row["scheduler"] == scheduler]
        centres = np.array([row["nj_s"] for row in mine]) + offset
        axes.errorbar(
            centres, [row["m_mean"] for row in mine], yerr=[row["m_std"] for row in mine],
            marker="o", capsize=3, label=scheduler,
        )  # fmt: skip
    axes.set_xlabel("N_j/s (joins that split again, summed over targets)")
    axes.set_ylabel("M (labelled fraction of the tracklets)")
    axes.set_ylim(0, 1.02)
    axes.grid(alpha=0.3)
    axes.legend()
    axes.set_title(f"{len({row['seed'] for row in rows})} simulations: mean and standard deviation per bin")
    figure.tight_layout()
    return figure


def trails_figure(scene: RoadScene, run: MsgRun, title: str = "") -> Figure:
    """One simulation's trails in (x, y, t), like the paper's Figure 5a: solid where the walker's tracklet
    is labelled with it in the final graph, dashed where not (or not observed), triangles at face captures."""
    figure = Figure(figsize=(8, 7))
    axes = figure.add_subplot(projection="3d")
    labelled = np.zeros(scene.positions_m.shape[:2], dtype=bool)
    for target, vertices in _labelled_reach(run.graph).items():
        for v in vertices:
            node = run.graph.nodes[v]
            if target in node["targets"]:
                labelled[node["first_step"] : node["last_step"] + 1, target] = True
    time_s = np.arange(len(scene.positions_m)) / scene.frame_rate_hz
    colours = matplotlib.colormaps["tab20"]
    for person in range(scene.positions_m.shape[1]):
        x, y = scene.positions_m[:, person].T
        colour = colours(person % 20)
        for mask, style in ((labelled[:, person], "-"), (~labelled[:, person], ":")):
            axes.plot(np.where(mask, x, np.nan), np.where(mask, y, np.nan), time_s, style, color=colour, lw=1.2)
    for step, person in run.captures:
        axes.scatter(*scene.positions_m[step, person], time_s[step], marker="^", color="black", s=25)
    axes.set_xlabel("x [m]")
    axes.set_ylabel("y [m]")
    axes.set_zlabel("t [s]")
    axes.set_title(title or "solid: labelled, dotted: unlabelled, triangles: face captures")
    figure.tight_layout()
    return figure
