"""``ptztrack experiment network synthetic``: PTZ cameras around the synthetic area, deciding together,
each alone, or fixed; with and without a wide fixed camera.

Placement, fixed before any run. PTZ camera ``k`` of ``N`` stands where the
scenario's camera stands (south of the area), turned about the area's centre
by ``360 k / N`` degrees: the same distance from the centre and height, so
one camera is the one-camera scene, two face each other from south and
north, four look in from the middle of each side. The wide fixed camera is
mounted 5 m up on a mast 2 m outside the south-west corner, with the
scenario's lens (its widest view, about 89 degrees across), and stays at its
widest view of the area; it has the scenario's detector like the others.
On a mast, ``N`` PTZ cameras all stand where the scenario's camera stands
(domes sharing one pole or one building's corner, as sites often mount
them): they see the same people from the same place, so what one camera
looks at is exactly what the others would also gain by.

Configurations, for ``N`` = 1 to ``max_ptz``: ``Nptz-joint`` (the PTZ cameras
choose greedily, each on what the views before it are expected to leave:
:mod:`ptztrack.network.policy`), ``Nptz-independent`` (each as if
alone), ``Nfixed`` (the same cameras, each at its widest view); for one
camera joint and independent are the same run, ``1ptz``. With the wide
camera, the same with ``+wide``, and ``wide`` alone. On the mast, for
``N`` >= 2, ``Nptz-joint-mast`` and ``Nptz-independent-mast``.

Every configuration runs the same sequences (seeds 0 .. n-1, the table's;
a development run starts further on, disjoint from them): the same
people and, for a camera at the same place in the list (the wide one comes
last), the same detector luck, so configurations pair up sequence by
sequence. A configuration's ``mota_se`` is the standard error of its mean
over the sequences; ``mota_minus_joint`` and ``mota_minus_joint_se`` are
the paired difference from the joint configuration of the same cameras and
its standard error.
"""

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ptztrack.builders.episode import run_episode
from ptztrack.builders.network import Coordination, network_world
from ptztrack.config import Scenario
from ptztrack.control.information_policy import InformationMethod
from ptztrack.evaluate.metrics import DISPLAY, network_metrics, standard_error
from ptztrack.experiments.cells import Execution, run_experiment_cells

WIDE_CAMERA_POSITION_M = (-2.0, -2.0, 5.0)
SUMMARY_KEYS = ("mota", "motp_m", "idf1", "detections", "zoom")


@dataclass(frozen=True)
class Configuration:
    """One row of the table: ``ptz`` cameras on the ring or the mast (``placement``) deciding ``mode``
    ('joint', 'independent' or, all of them, 'fixed'), with or without the ``wide`` camera;
    ``pairs_with``: the joint configuration of the same cameras (None for a joint one and for the wide
    camera alone)."""

    label: str
    ptz: int
    mode: Literal["joint", "independent", "fixed"]
    wide: bool
    pairs_with: str | None
    placement: Literal["ring", "mast"] = "ring"


@dataclass(frozen=True)
class NetworkCell:
    """One episode of the network experiment: ``scenario`` (with its cameras) run with ``coordination``
    and the policies' ``method`` on the sequence ``seed``, in the table's row ``configuration``."""

    scenario: Scenario
    coordination: Coordination
    method: InformationMethod
    seed: int
    configuration: Configuration


def ring_positions_m(scenario: Scenario, count: int) -> list[tuple[float, float, float]]:
    """``count`` camera positions: the scenario's camera turned about the area's centre by 360 k / count deg."""
    centre_m = np.asarray(scenario.area_m) / 2
    x_m, y_m, z_m = scenario.camera.position_m
    offset_m = np.array([x_m, y_m]) - centre_m
    positions = []
    for k in range(count):
        angle = 2 * math.pi * k / count
        turn = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
        x, y = centre_m + turn @ offset_m
        positions.append((float(x), float(y), z_m))
    return positions


def network_scenario(
    scenario: Scenario, ptz: int, fixed: bool, wide: bool, placement: Literal["ring", "mast"] = "ring"
) -> Scenario:
    """``scenario`` with ``ptz`` cameras (PTZ, or all fixed with ``fixed``) on the ring or on the mast at
    the scenario's camera and, with ``wide``, the wide fixed camera after them (alone for ``ptz`` 0)."""
    kind = "fixed" if fixed else "ptz"
    positions = ring_positions_m(scenario, ptz) if placement == "ring" else [scenario.camera.position_m] * ptz
    cameras = [{"kind": kind, "position_m": position} for position in positions]
    if wide:
        cameras.append({"kind": "fixed", "position_m": WIDE_CAMERA_POSITION_M})
    return Scenario.model_validate({**scenario.model_dump(), "cameras": cameras})


def configurations(max_ptz: int) -> list[Configuration]:
    """Every configuration of the table (see the module's docstring), in its order."""
    rows = []
    for wide in (False, True):
        suffix = "+wide" if wide else ""
        for count in range(1, max_ptz + 1):
            joint = f"{count}ptz-joint{suffix}" if count > 1 else f"1ptz{suffix}"
            rows.append(Configuration(joint, count, "joint", wide, None))
            if count > 1:
                rows.append(Configuration(f"{count}ptz-independent{suffix}", count, "independent", wide, joint))
            rows.append(Configuration(f"{count}fixed{suffix}", count, "fixed", wide, joint))
    rows.append(Configuration("wide", 0, "fixed", True, None))
    for count in range(2, max_ptz + 1):
        joint = f"{count}ptz-joint-mast"
        rows.append(Configuration(joint, count, "joint", False, None, "mast"))
        rows.append(Configuration(f"{count}ptz-independent-mast", count, "independent", False, joint, "mast"))
    return rows


def network_cells(
    scenario: Scenario,
    sequences: int,
    max_ptz: int = 4,
    method: InformationMethod = "intg",
    first_sequence: int = 0,
) -> list[NetworkCell]:
    """Every configuration (:func:`configurations`) on the sequences ``first_sequence`` .. ``first_sequence
    + sequences - 1``."""
    seeds = range(first_sequence, first_sequence + sequences)
    cells = []
    for configuration in configurations(max_ptz):
        network = network_scenario(
            scenario, configuration.ptz, configuration.mode == "fixed", configuration.wide, configuration.placement
        )
        coordination: Coordination = "independent" if configuration.mode == "independent" else "joint"
        cells += [NetworkCell(network, coordination, method, seed, configuration) for seed in seeds]
    return cells


def run_network_cell(cell: NetworkCell) -> dict:
    """One cell's metrics (:func:`~ptztrack.evaluate.metrics.network_metrics`), with ``config``, the
    configuration it pairs with (``joint``) and ``seed``."""
    world = network_world(cell.scenario, cell.seed)
    episode = run_episode(cell.scenario, cell.method, cell.seed, world, coordination=cell.coordination)
    row = {"config": cell.configuration.label, "joint": cell.configuration.pairs_with, "seed": cell.seed}
    return {**row, **network_metrics(episode)}


def summarise_network(rows: Sequence[dict]) -> list[dict]:
    """One row per configuration, in order of first appearance: the means over its sequences of
    :data:`SUMMARY_KEYS`, ``mota_se``, ``mota_per_sequence`` (by seed), ``seeds`` and ``sequences``; and for a
    configuration with a joint one to pair with, ``joint``, ``mota_minus_joint`` and its paired
    standard error ``mota_minus_joint_se``."""
    by_label: dict[str, list[dict]] = {}
    for row in rows:
        by_label.setdefault(row["config"], []).append(row)
    summary = []
    for label, mine in by_label.items():
        mine = sorted(mine, key=lambda row: row["seed"])
        mota = [row["mota"] for row in mine]
        entry = {
            "config": label,
            "sequences": len(mine),
            **{key: float(np.mean([row[key] for row in mine])) for key in SUMMARY_KEYS},
            "mota_se": standard_error(mota),
            "mota_per_sequence": mota,
            "seeds": [row["seed"] for row in mine],
        }
        joint = mine[0]["joint"]
        if joint is not None and joint in by_label:
            paired = np.asarray(mota) - [row["mota"] for row in sorted(by_label[joint], key=lambda row: row["seed"])]
            entry |= {
                "joint": joint,
                "mota_minus_joint": float(paired.mean()),
                "mota_minus_joint_se": standard_error(paired),
            }
        summary.append(entry)
    return summary


def run_network_table(cells: list[NetworkCell], execution: Execution) -> list[dict]:
    """The cells run on ``execution`` and summarised (:func:`summarise_network`)."""
    return summarise_network(run_experiment_cells(cells, run_network_cell, execution))


def format_network_table(summary: Sequence[dict], title: str = "") -> str:
    """A row per configuration: MOTA +- its standard error, the paired difference from the joint
    configuration of the same cameras +- its standard error (points), MOTP, IDF1, detections and zoom."""
    width = max(len(row["config"]) for row in summary) + 2
    header = f"{'config':<{width}}{'MOTA':>16}{'- joint [points]':>20}"
    header += "".join(f"{DISPLAY[key][0]:>13}" for key in SUMMARY_KEYS[1:])
    lines = [title] if title else []
    lines.append(header)
    for row in summary:
        mota = f"{100 * row['mota']:.1f} +- {100 * row['mota_se']:.1f} %"
        paired = ""
        if "joint" in row:
            paired = f"{100 * row['mota_minus_joint']:+.1f} +- {100 * row['mota_minus_joint_se']:.1f}"
        figures = "".join(f"{DISPLAY[key][1].format(row[key]):>13}" for key in SUMMARY_KEYS[1:])
        lines.append(f"{row['config']:<{width}}{mota:>16}{paired:>20}{figures}")
    return "\n".join(lines)


def network_title(scenario: Scenario, sequences: int, method: str, first_sequence: int = 0) -> str:
    which = f"{sequences} sequences" + (f" from seed {first_sequence}" if first_sequence else "")
    return (
        f"camera network on the synthetic scene, {scenario.detector.kind} detector "
        f"({scenario.detector.model} model), PTZ policies {method}, {which} of "
        f"{scenario.frames} frames (MOTA +- standard error over sequences; - joint: paired)"
    )
