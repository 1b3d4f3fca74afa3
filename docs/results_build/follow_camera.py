"""The follow-camera page (``results/follow-camera.md``): its fields and its headline."""

from __future__ import annotations

import math
from collections.abc import Sequence
from statistics import mean

from . import Load
from .formatting import fixed, integer, table

FOLLOW_ROWS = (
    ("in-view fraction", "in_view_fraction", 3),
    ("target point error", "target_point_error", 3),
    ("losses declared", "losses", 2),
    ("recoveries", "recoveries", 2),
    ("steps lost", "lost_steps", 2),
    ("jitter [deg/step^2]", "jitter_deg", 3),
    ("height sd / mean", "height_sd_ratio", 3),
    ("ground error while tracking [m]", "ground_error_m", 2),
    ("zoom", "zoom", 2),
)
OTB_ROWS = (
    ("success AUC", "success_auc", 3),
    ("precision at 20 px", "precision_20px", 3),
    ("frames per second", "fps", 0),
)


def finite_mean(values: Sequence[float]) -> float:
    finite = [value for value in values if value is not None and math.isfinite(value)]
    return mean(finite) if finite else float("nan")


def fields(load: Load) -> dict[str, str]:
    summary = load("follow")
    trackers = [row["tracker"] for row in summary["closed_loop"]]
    people = summary["people"]

    def of(tracker: str, parity: int | None = None) -> list[dict]:
        return [
            row for row in people if row["tracker"] == tracker and (parity is None or row["target_id"] % 2 == parity)
        ]

    def split(tracker: str, key: str, digits: int) -> str:
        return " / ".join(fixed(finite_mean([row[key] for row in of(tracker, parity)]), digits) for parity in (0, 1))

    closed = {row["tracker"]: row for row in summary["closed_loop"]}
    body = []
    for name, key, digits in FOLLOW_ROWS:
        body.append([name] + [fixed(closed[tracker][key], digits) for tracker in trackers])
        if key in ("in_view_fraction", "target_point_error"):
            body.append([f"{name}, even / odd people"] + [split(tracker, key, digits) for tracker in trackers])
    otb = {row["tracker"]: row for row in summary["otb"]}
    otb_body = [[name] + [fixed(otb[tracker][key], digits) for tracker in trackers] for name, key, digits in OTB_ROWS]
    particle = sorted(of("particle"), key=lambda row: row["in_view_fraction"])
    kept = [row for row in particle if row["in_view_fraction"] >= 0.98]
    otb_people = sorted({row["target_id"] for row in summary["otb_people"]})
    return particle_seeds_fields(load) | {
        "follow_people": str(closed[trackers[0]]["people"]),
        "follow_steps": integer(sum(row["steps"] for row in of(trackers[0]))),
        "follow_table": table([""] + trackers, body),
        "follow_otb_people": ", ".join(str(person) for person in otb_people),
        "follow_otb_table": table([""] + trackers, otb_body),
        "follow_particle_in_view": fixed(closed["particle"]["in_view_fraction"], 3),
        "follow_particle_in_view_odd": fixed(finite_mean([row["in_view_fraction"] for row in of("particle", 1)]), 3),
        "follow_csrt_in_view": fixed(closed["csrt"]["in_view_fraction"], 3),
        "follow_mil_in_view": fixed(closed["mil"]["in_view_fraction"], 3),
        "follow_kept_count": str(len(kept)),
        "follow_lost_people": ", ".join(
            f"person {row['target_id']} ({row['in_view_fraction']:.2f})"
            for row in particle
            if row["in_view_fraction"] < 0.98
        ),
    }


# Each run and the seed its command gives (``--seed``; the first run takes the default, 0).
FOLLOW_SEED_RUNS = (("follow", 0), ("follow-particle-seed-1", 1), ("follow-particle-seed-2", 2))
FOLLOW_SEED_ROWS = (
    ("in-view fraction", "closed_loop", "in_view_fraction"),
    ("target point error", "closed_loop", "target_point_error"),
    ("success AUC", "otb", "success_auc"),
    ("precision at 20 px", "otb", "precision_20px"),
)


def particle_seeds_fields(load: Load) -> dict[str, str]:
    """The particle filter's figures at each seed of its draws, and their mean."""
    runs = [load(run) for run, _ in FOLLOW_SEED_RUNS]
    seeds = [str(seed) for _, seed in FOLLOW_SEED_RUNS]
    body = []
    for name, section, key in FOLLOW_SEED_ROWS:
        values = [next(row for row in run[section] if row["tracker"] == "particle")[key] for run in runs]
        body.append([name] + [fixed(value, 3) for value in values] + [fixed(mean(values), 3)])
    return {"follow_seeds_table": table([""] + [f"seed {seed}" for seed in seeds] + ["mean"], body)}


def headline(load: Load) -> list[str]:
    closed = {row["tracker"]: row for row in load("follow")["closed_loop"]}
    return [
        "[The follow camera](follow-camera.md)",
        f"the particle filter keeps its person in view {closed['particle']['in_view_fraction']:.3f} of the time "
        f"over all PETS people, CSRT {closed['csrt']['in_view_fraction']:.3f}, "
        f"MIL {closed['mil']['in_view_fraction']:.3f}",
    ]
