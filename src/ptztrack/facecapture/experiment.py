"""The face-capture experiment (MSG paper, section 4): simulate, schedule, score M against N_j/s.

One run: a road-grid scene (:mod:`ptztrack.facecapture.roads`) watched by one PTZ
camera at the area's centre (:mod:`ptztrack.facecapture.road_camera`), whose
observations alone feed the tracklet tracker (:mod:`ptztrack.facecapture.tracklets`).
Every zoomed-out step the scheduler (:mod:`ptztrack.facecapture.scheduler`)
either stays zoomed out or zooms in on one walker for ``zoom_steps`` to
capture a face, aimed where the tracker predicts the walker at the capture;
a captured face labels the walker's tracklet, matches it and (for the
schedulers that untangle) untangles the graph. Every scheduler of a run
meets the same scene and the same capture draws.

The score (eq. 1) is M = sum_z |tau_L(z)| / sum_z sum_i |tau_i(z)|, on each
scheduler's own final graph with the same rules: the part of every observed
person-step that lies in a tracklet labelled with that person. A label
reaches the labelled vertex and its forward and backward labelling chains
(a vertex that is its parent's only child, a parent that is its child's
only parent; Appendix A), up to a vertex labelled otherwise; within them it
counts only on the blobs (observed units) that held the person, so wrong
associations earn nothing.
"""

from dataclasses import dataclass, replace

import matplotlib
import networkx as nx
import numpy as np
from matplotlib.figure import Figure

from ptztrack.evaluate.metrics import standard_error
from ptztrack.facecapture.parameters import (
    MsgExperimentParameters,
    RoadCameraParameters,
    RoadSceneParameters,
    TrackletTrackerParameters,
)
from ptztrack.facecapture.road_camera import Blob, RoadCamera, Zoom
from ptztrack.facecapture.roads import RoadScene, walk_roads
from ptztrack.facecapture.scheduler import SCHEDULERS
from ptztrack.facecapture.tracklets import TrackletTracker
from ptztrack.loop.capture import run_capture_loop

_EXPERIMENT = MsgExperimentParameters()


@dataclass(frozen=True)
class MsgRun:
    """What a run left: the final graph, the camera's blobs, the zooms (decision step, vertex zoomed on),
    the captured faces (step, person) and the score."""

    graph: nx.DiGraph
    blobs: dict[int, Blob]
    zooms: list[tuple[int, int]]
    captures: list[tuple[int, int]]
    m: float


def run_msg(
    scene: RoadScene,
    scheduler: str,
    config: TrackletTrackerParameters | None = None,
    zoom_out_score: float = _EXPERIMENT.zoom_out_score,
    seed: int = 0,
    zoomed_half_width_m: float = RoadCameraParameters.zoomed_half_width_m,
    steps: int | None = None,
) -> MsgRun:
    """Run one scheduler (a name in :data:`SCHEDULERS`) over a scene: ``config`` the tracker's (by
    default :class:`TrackletTrackerParameters`'s defaults), ``seed`` fixes the capture draws,
    ``steps`` stops the run after that many steps (default: all). Only the camera reads the scene, one
    step at a time."""
    config = config or TrackletTrackerParameters()
    if scheduler not in SCHEDULERS:
        raise ValueError(f"unknown scheduler {scheduler!r}; expected one of {', '.join(SCHEDULERS)}")
    chosen = SCHEDULERS[scheduler]
    camera_m = (scene.area_m / 2, scene.area_m / 2)
    camera = RoadCamera(scene, camera_m, np.random.default_rng([seed, 2]), zoomed_half_width_m)
    tracker = TrackletTracker(scene.area_m, scene.frame_rate_hz, camera_m, config, chosen.untangling)

    def decide(step: int) -> tuple[Zoom, int] | None:
        candidate = chosen.choose(tracker, step, zoom_out_score)
        if candidate is None:
            return None
        return Zoom(candidate.blob, candidate.aim_m, step + config.zoom_steps), candidate.vertex

    zooms, captures = run_capture_loop(camera, tracker, decide, len(scene.positions_m) if steps is None else steps)
    return MsgRun(tracker.graph, camera.blobs, zooms, captures, labelled_fraction(tracker.graph, camera.blobs))


def labelled_fraction(graph: nx.DiGraph, blobs: dict[int, Blob]) -> float:
    """M of eq. 1 on a final graph: the labelled share of the person-steps of ``blobs`` (the camera's)."""
    total = sum(len(blob.members) * blob.steps for blob in blobs.values())
    if total == 0:
        return float("nan")
    labelled = 0
    for face, vertices in labelled_reach(graph).items():
        reached = {b for v in vertices for b in graph.nodes[v]["blobs"]}
        labelled += sum(blobs[b].steps for b in reached if face in blobs[b].members)
    return labelled / total


def labelled_reach(graph: nx.DiGraph) -> dict:
    """{face: vertices its labels reach}: the vertices labelled with it, and their forward and backward
    labelling chains up to a vertex labelled with another face."""
    reach: dict = {}
    for v, node in graph.nodes(data=True):
        if not node["labeled"]:
            continue
        vertices = reach.setdefault(node["face"], set())
        vertices.add(v)
        for step_to, degree in ((graph.succ, graph.out_degree), (graph.pred, graph.in_degree)):
            x = v
            while degree(x) == 1:
                (x,) = step_to[x]
                if graph.nodes[x]["labeled"] or x in vertices:
                    break
                vertices.add(x)
    return reach


@dataclass(frozen=True)
class MsgCell:
    """One simulation of the experiment, run by every scheduler: its seed fixes the scene and the capture draws."""

    seed: int
    scene: RoadSceneParameters
    tracker: TrackletTrackerParameters = TrackletTrackerParameters()
    zoom_out_score: float = _EXPERIMENT.zoom_out_score
    zoomed_half_width_m: float = RoadCameraParameters.zoomed_half_width_m


def msg_cells(runs: int, base: RoadSceneParameters = _EXPERIMENT.scene) -> list[MsgCell]:
    """``runs`` simulations across ambiguity levels: people and join probability drawn per run from its seed."""
    cells = []
    for seed in range(runs):
        rng = np.random.default_rng([seed, 1])
        people = int(rng.integers(*_EXPERIMENT.people_range))
        join_probability = float(rng.uniform(*_EXPERIMENT.join_probability_range))
        cells.append(MsgCell(seed, replace(base, people=people, join_probability=join_probability)))
    return cells


def run_msg_cell(cell: MsgCell) -> list[dict]:
    """One row per scheduler: ``scheduler``, ``nj_s``, ``m``, ``zooms`` (captures tried), ``captures``
    (faces captured), ``seed``, ``people``, ``join_probability``."""
    scene = walk_roads(cell.scene, np.random.default_rng(cell.seed))
    rows = []
    for scheduler in SCHEDULERS:
        run = run_msg(scene, scheduler, cell.tracker, cell.zoom_out_score, cell.seed, cell.zoomed_half_width_m)
        rows.append(
            {
                "scheduler": scheduler,
                "nj_s": scene.nj_s,
                "m": run.m,
                "zooms": len(run.zooms),
                "captures": len(run.captures),
                "seed": cell.seed,
                "people": cell.scene.people,
                "join_probability": cell.scene.join_probability,
            }
        )
    return rows


def summarise_by_ambiguity(rows: list[dict], bin_width: int = _EXPERIMENT.bin_width) -> list[dict]:
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


def paired_difference_m(
    rows: list[dict], first: str, second: str, nj_s: int | None = None, bin_width: int = _EXPERIMENT.bin_width
) -> tuple[float, float, int]:
    """M of scheduler ``first`` minus M of ``second``, paired by run (seed): mean, its standard error and
    the number of runs; over all runs, or those in the N_j/s bin centred on ``nj_s``."""
    m = {(row["scheduler"], row["seed"]): row["m"] for row in rows}
    nj_s_of = {row["seed"]: row["nj_s"] for row in rows}
    seeds = sorted(seed for seed in nj_s_of if (first, seed) in m and (second, seed) in m)
    if nj_s is not None:
        seeds = [seed for seed in seeds if np.floor(nj_s_of[seed] / bin_width + 0.5) * bin_width == nj_s]
    difference = np.array([m[first, seed] - m[second, seed] for seed in seeds])
    if difference.size == 0:
        return float("nan"), float("nan"), 0
    return float(difference.mean()), standard_error(difference), int(difference.size)


def format_paired_differences(rows: list[dict], first: str = "msg", nj_s: int = _EXPERIMENT.key_nj_s) -> str:
    """``first`` minus every other scheduler, paired by run: mean +- standard error, over all runs and in
    the bin centred on ``nj_s``; then each scheduler's faces captured per capture tried."""
    schedulers = [name for name in dict.fromkeys(row["scheduler"] for row in rows) if name != first]
    lines = [f"{'paired by run':<28}{'all runs':>24}{f'N_j/s bin {nj_s}':>24}"]
    for second in schedulers:
        line = f"{first + ' - ' + second:<28}"
        for centre in (None, nj_s):
            mean, se, runs = paired_difference_m(rows, first, second, centre)
            line += f"{mean:>+12.4f} +- {se:.4f} ({runs:>3})"
        lines.append(line)
    rates = []
    for name in dict.fromkeys(row["scheduler"] for row in rows):
        mine = [row for row in rows if row["scheduler"] == name]
        tried = sum(row["zooms"] for row in mine)
        rates.append(f"{name} {sum(row['captures'] for row in mine) / max(tried, 1):.3f}")
    lines.append("faces captured per capture tried: " + ", ".join(rates))
    return "\n".join(lines)


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


def ambiguity_figure(rows: list[dict], bin_width: int = _EXPERIMENT.bin_width) -> Figure:
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
    for face, vertices in labelled_reach(run.graph).items():
        for blob in (run.blobs[b] for v in vertices for b in run.graph.nodes[v]["blobs"]):
            if face in blob.members:
                labelled[blob.first_step : blob.last_step + 1, face] = True
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
