"""``ptztrack experiment network pets``: the virtual PTZ camera over a dataset's view with the published
detections of its other views as fixed cameras (:mod:`ptztrack.builders.pets_network`), one shared belief;
on the built-in PETS 2009 S2.L1, View_001 and six fixed views.

Configurations (N fixed views): ``ptz+Nfixed`` (the PTZ camera deciding jointly with the fixed views'
expected information, :mod:`ptztrack.network.policy`), ``Nfixed`` (the fixed views alone) and ``ptz``
(the PTZ camera alone: ``experiment pets --detector hog``'s information-gain run of the same beta and
seeds, step for step). A run with the PTZ camera depends on its seed (its online detector model's
draws), so it runs on seeds 0 .. n-1, as the PETS table does; the fixed views alone do not depend on it
(their models' draws only weigh a PTZ camera's decisions) and run once.

Scoring. The annotations are View_001's: they hold the people View_001 shows, not those only the other
views see. So the tracks are scored where the annotations are, inside the walkable area (the ground
the recorded View_001 shows, the area the PTZ camera's policies plan over); ``mota_all_tracks`` scores
every track, as ``experiment pets`` does (for ``ptz`` it is that table's ``intg`` column of the same
beta, seed by seed: ``mota_all_tracks_per_seed``). The walkable area reaches far beyond the ground the
annotators covered, so the ``*_tracking_area`` figures score the tracks and the people inside the
dataset's ``tracking_area_m`` (S2.L1's published tracking area, where the annotations are those of
published tracking results; the walkable area for a dataset without one).
"""

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ptztrack.builders.episode import run_episode
from ptztrack.builders.pets_network import pets_network_world, published_network_parts
from ptztrack.config import Scenario
from ptztrack.control.information_policy import InformationMethod
from ptztrack.evaluate.metrics import DISPLAY, looking_metrics, tracking_metrics, tracks_within, truth_within
from ptztrack.experiments.cells import Execution, run_experiment_cells
from ptztrack.geometry.area import rectangle_m
from ptztrack.occupancy.multiview import CameraView

# (label, with the PTZ camera, with the fixed views), in the table's order; N: the number of fixed views.
CONFIGURATIONS = (("ptz+Nfixed", True, True), ("Nfixed", False, True), ("ptz", True, False))
TRACKING_AREA_KEYS = ("mota", "idf1", "false_positives", "misses")
SUMMARY_KEYS = (
    "mota",
    "motp_m",
    "idf1",
    "false_positives",
    "misses",
    "switches",
    "mota_all_tracks",
    *(f"{key}_tracking_area" for key in TRACKING_AREA_KEYS),
    "detections",
)
SHOWN = {
    "false_positives": ("FP", "{:.1f}"),
    "misses": ("Misses", "{:.1f}"),
    "switches": ("IDsw", "{:.1f}"),
    "mota_all_tracks": ("MOTA all", "{:.1%}"),
    "mota_tracking_area": ("MOTA TA", "{:.1%}"),
    "idf1_tracking_area": ("IDF1 TA", "{:.1%}"),
    "false_positives_tracking_area": ("FP TA", "{:.1f}"),
    "misses_tracking_area": ("Misses TA", "{:.1f}"),
}


@dataclass(frozen=True)
class PetsNetworkCell:
    """One episode: the configuration ``config`` (``ptz``: with the PTZ camera; ``views``: the fixed
    cameras, none without) of ``scenario`` on ``seed``, the PTZ camera deciding by ``method``."""

    scenario: Scenario
    config: str
    ptz: bool
    views: tuple[CameraView, ...]
    seed: int
    method: InformationMethod = "intg"


def pets_network_cells(
    scenario: Scenario, views: Sequence[CameraView], seeds: int, method: InformationMethod = "intg"
) -> list[PetsNetworkCell]:
    """Every configuration (:data:`CONFIGURATIONS`): on seeds 0 .. ``seeds`` - 1 with the PTZ camera, once
    (seed 0) without it."""
    return [
        PetsNetworkCell(scenario, label.replace("N", str(len(views))), ptz, tuple(views) if fixed else (), seed, method)
        for label, ptz, fixed in CONFIGURATIONS
        for seed in range(seeds if ptz else 1)
    ]


def run_pets_network_cell(cell: PetsNetworkCell) -> dict:
    """One cell's figures: the tracks inside the walkable area scored (:func:`tracking_metrics`),
    ``mota_all_tracks`` with every track, the ``*_tracking_area`` figures of the tracks and people inside
    the tracking area, and the cameras' detections and zoom."""
    world = pets_network_world(cell.scenario, cell.seed, cell.ptz, cell.views)
    policy, belief = published_network_parts(cell.scenario, world, cell.ptz, "joint", cell.method)
    episode = run_episode(cell.scenario, policy, cell.seed, world, tracker=belief)
    scored = tracking_metrics(episode.truth, tracks_within(episode.tracks, episode.area_polygon_m))
    every = tracking_metrics(episode.truth, episode.tracks)
    tracking_area = episode.area_polygon_m
    rectangle = cell.scenario.required_recording("the camera network's table").tracking_area_m
    if rectangle is not None:
        (x0, y0), (x1, y1) = rectangle
        tracking_area = rectangle_m(x1 - x0, y1 - y0) + (x0, y0)
    in_area = tracking_metrics(truth_within(episode.truth, tracking_area), tracks_within(episode.tracks, tracking_area))
    row = {"config": cell.config, "seed": cell.seed, "cameras": len(episode.cameras)}
    return {
        **row,
        **scored,
        "mota_all_tracks": every["mota"],
        **{f"{key}_tracking_area": in_area[key] for key in TRACKING_AREA_KEYS},
        **looking_metrics(episode.cameras),
    }


def summarise_pets_network(rows: Sequence[dict]) -> list[dict]:
    """One row per configuration, in order of first appearance: the means of :data:`SUMMARY_KEYS` and
    ``zoom`` over its seeds, ``seeds``, ``mota_sd`` (over the seeds; 0 for one), ``mota_per_seed``,
    ``mota_all_tracks_per_seed`` and ``mota_tracking_area_per_seed``."""
    summary = []
    for label in dict.fromkeys(row["config"] for row in rows):
        mine = sorted((row for row in rows if row["config"] == label), key=lambda row: row["seed"])
        mota = [row["mota"] for row in mine]
        summary.append(
            {
                "config": label,
                "seeds": len(mine),
                "cameras": mine[0]["cameras"],
                **{key: float(np.mean([row[key] for row in mine])) for key in (*SUMMARY_KEYS, "zoom")},
                "mota_sd": float(np.std(mota, ddof=1)) if len(mota) > 1 else 0.0,
                "mota_per_seed": mota,
                "mota_all_tracks_per_seed": [row["mota_all_tracks"] for row in mine],
                "mota_tracking_area_per_seed": [row["mota_tracking_area"] for row in mine],
                "objects": mine[0]["objects"],
            }
        )
    return summary


def run_pets_network_table(cells: list[PetsNetworkCell], execution: Execution) -> list[dict]:
    """The cells run on ``execution`` (a configuration's seeds in one worker, sharing HOG's memo of the
    views it has searched) and summarised (:func:`summarise_pets_network`)."""
    rows = run_experiment_cells(cells, run_pets_network_cell, execution, together=lambda cell: cell.config)
    return summarise_pets_network(rows)


def format_pets_network_table(summary: Sequence[dict], title: str = "") -> str:
    """A row per configuration: MOTA +- its standard deviation over the seeds, MOTP, IDF1, false positives,
    misses, identity switches, MOTA with every track scored, the tracking area's MOTA, IDF1, false
    positives and misses, detections and zoom."""
    shown = {**DISPLAY, **SHOWN}
    width = max(len(row["config"]) for row in summary) + 2
    keys = (*SUMMARY_KEYS[1:], "zoom")
    lines = [title] if title else []
    lines.append(f"{'config':<{width}}{'seeds':>6}{'MOTA':>17}" + "".join(f"{shown[key][0]:>11}" for key in keys))
    for row in summary:
        mota = f"{100 * row['mota']:.1f} +- {100 * row['mota_sd']:.1f} %"
        figures = "".join(f"{shown[key][1].format(row[key]):>11}" for key in keys)
        lines.append(f"{row['config']:<{width}}{row['seeds']:>6}{mota:>17}{figures}")
    return "\n".join(lines)


def pets_network_title(scenario: Scenario, seeds: int, method: str, recall: float) -> str:
    recording = scenario.required_recording("a camera network's table")
    return (
        f"camera network on {recording.name}: the virtual PTZ camera ({scenario.detector.kind}, "
        f"{method} b{scenario.control.beta:g}, {scenario.detector.model} model) and the published detections of "
        f"the dataset's other views as fixed cameras (recall {recall:g}), {scenario.frames} steps, {seeds} seeds "
        "with the PTZ camera (MOTA +- standard deviation over seeds; tracks scored inside the recorded view's "
        "walkable area, TA: tracks and people inside the dataset's tracking area)"
    )
