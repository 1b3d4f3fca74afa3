"""The long-runs page (``results/long-runs.md``): its fields and its headline."""

from __future__ import annotations

from . import Load
from .formatting import fixed, pct, table


def fields(load: Load) -> dict[str, str]:
    runs = {"default": load("soak-default"), "long_run": load("soak-long-run")}
    targets = load("targets")["long_runs"]

    def memory(run: dict) -> tuple[float, float]:
        at = {int(step): mb for step, mb in run["rss_mb_at"].items()}
        return at[min(step for step in at if step >= targets["memory_from_step"])], at[max(at)]

    def growth(run: dict) -> str:
        start, end = memory(run)
        return f"{start:.0f} / {end:.0f} MB ({100 * (end / start - 1):+.1f} %)"

    figures = (
        ("MOTA", lambda run: pct(run["mota"]), ""),
        ("IDF1", lambda run: pct(run["idf1"]), f">= {pct(targets['idf1_at_least'], 0)}"),
        (
            "identity switches per 100 steps",
            lambda run: fixed(run["id_switches_per_100_steps"], 1),
            f"<= {targets['switches_per_100_steps_at_most']:g}",
        ),
        (
            f"switches, first / last {targets['window_steps']:,} steps",
            lambda run: f"{run['switches_first_2000']} / {run['switches_last_2000']}",
            "last no higher than first",
        ),
        ("distinct track ids reported", lambda run: str(run["track_ids_reported"]), ""),
        (
            f"resident memory at step {targets['memory_from_step']:,} / the last",
            growth,
            f"within {pct(targets['memory_growth_at_most'], 0)}",
        ),
        ("writing the folder", lambda run: f"{run['write_s']:.1f} s", f"within {targets['write_s_at_most']:g} s"),
        ("running the steps", lambda run: f"{run['run_s']:.1f} s", ""),
    )
    body = [[name, show(runs["default"]), show(runs["long_run"]), asked] for name, show, asked in figures]
    gaps = runs["long_run"]["switch_gaps"]
    return {
        "soak_steps": str(runs["default"]["steps"]),
        "soak_people": str(runs["default"]["people"]),
        "soak_table": table(["figure", "default tracker", "`examples/long_run.yaml`", "asked"], body),
        "soak_person_unmatched": " / ".join(fixed(value, 0) for value in gaps["person_unmatched_steps"]),
        "soak_track_undetected": " / ".join(fixed(value, 0) for value in gaps["track_unseen_steps"]),
    }


def headline(load: Load) -> list[str]:
    default, long_run = load("soak-default"), load("soak-long-run")
    return [
        "[Long runs](long-runs.md)",
        f"{default['steps']:,} steps of the synthetic scene: with the long-run options MOTA {pct(long_run['mota'])}, "
        f"IDF1 {pct(long_run['idf1'])}, {long_run['id_switches_per_100_steps']:.1f} identity switches per 100 steps; "
        f"the default tracker {pct(default['mota'])}, {pct(default['idf1'])}, "
        f"{default['id_switches_per_100_steps']:.1f}",
    ]
