"""The occupancy-map (LPOM) page (``results/occupancy-map.md``): its fields and its headline."""

from __future__ import annotations

from collections.abc import Sequence

from . import Load
from .formatting import fixed, pct, table

OCCUPANCY_FIGURES = (
    ("MODA", "moda", pct),
    ("MODP", "modp", pct),
    ("precision", "precision", pct),
    ("recall", "recall", pct),
    ("error [m]", "error_m", lambda value: fixed(value, 3)),
    ("MOTA", "mota", pct),
    ("MOTP [m]", "motp_m", lambda value: fixed(value, 3)),
    ("IDF1", "idf1", pct),
)


def occupancy_table(rows: Sequence[dict]) -> str:
    """A row per people count and method; the clustering baseline feeds no tracker (blank MOTA to IDF1)."""
    body = [
        [str(row["people"]), row["method"]]
        + [show(row[key]) if row.get(key) is not None else "" for _, key, show in OCCUPANCY_FIGURES]
        for row in rows
    ]
    return table(["people", "method"] + [name for name, _, _ in OCCUPANCY_FIGURES], body)


def fields(load: Load) -> dict[str, str]:
    room = load("occupancy-synthetic-room")
    cell = {(row["people"], row["method"]): row for row in room}
    people = sorted({row["people"] for row in room})
    lpom_errors = [cell[count, "lpom"]["error_m"] for count in people]
    clustering_errors = [cell[count, "clustering"]["error_m"] for count in people]
    return {
        "room_table": occupancy_table(room),
        "room_lpom_error": f"{min(lpom_errors):.3f}-{max(lpom_errors):.3f}",
        "room_clustering_error": f"{min(clustering_errors):.3f}-{max(clustering_errors):.3f}",
        "room_lpom_moda_crowd": pct(cell[people[-1], "lpom"]["moda"]),
        "room_clustering_moda_crowd": pct(cell[people[-1], "clustering"]["moda"]),
        "room_crowd": str(people[-1]),
        "room_fitted": "; ".join(
            f"{count} {'person' if count == 1 else 'people'}: LPOM's strength "
            + " and ".join(f"{value:g}" for value in cell[count, "lpom"]["fitted_min_strength"])
            + ", POM's person width "
            + " and ".join(f"{value:g} m" for value in cell[count, "pom"]["fitted_width_m"])
            + ", the baseline's views "
            + " and ".join(str(value) for value in cell[count, "clustering"]["fitted_min_views"])
            for count in people
        ),
    }


def headline(load: Load) -> list[str]:
    cell = {(row["people"], row["method"]): row for row in load("occupancy-synthetic-room")}
    people = sorted({count for count, _ in cell})
    return [
        "[The occupancy map (LPOM)](occupancy-map.md)",
        "in the rendered room, LPOM's MODA "
        + " and ".join(
            f"{pct(cell[count, 'lpom']['moda'])} ({count} {'person' if count == 1 else 'people'})" for count in people
        )
        + ", error "
        + " and ".join(f"{cell[count, 'lpom']['error_m']:.3f} m" for count in people),
    ]
