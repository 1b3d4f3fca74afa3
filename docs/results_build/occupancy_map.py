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


def occupancy_table(rows: Sequence[dict], leading: Sequence[str] = ("people",)) -> str:
    """A row per method (after the ``leading`` columns, e.g. the people count); the clustering baseline
    feeds no tracker (blank MOTA to IDF1)."""
    body = [
        [str(row[column]) for column in leading]
        + [row["method"]]
        + [show(row[key]) if row.get(key) is not None else "" for _, key, show in OCCUPANCY_FIGURES]
        for row in rows
    ]
    return table([*leading, "method"] + [name for name, _, _ in OCCUPANCY_FIGURES], body)


def fields(load: Load) -> dict[str, str]:
    room = load("occupancy-synthetic-room")
    cell = {(row["people"], row["method"]): row for row in room}
    people = sorted({row["people"] for row in room})
    lpom_errors = [cell[count, "lpom"]["error_m"] for count in people]
    clustering_errors = [cell[count, "clustering"]["error_m"] for count in people]
    return (
        pets_fields(load)
        | plaza_fields(load)
        | {
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
    )


def pets_fields(load: Load) -> dict[str, str]:
    """PETS 2009 S2.L1's seven views: every method's row, and what was fitted on each half."""
    rows = load("occupancy-pets")
    method = {row["method"]: row for row in rows}
    return {
        "pets_table": occupancy_table(rows, leading=()),
        "pets_frames": str(rows[0]["frames"]),
        "pets_views": str(rows[0]["views"]),
        "pets_lpom_recall": pct(method["lpom"]["recall"]),
        "pets_lpom_foreground_recall": pct(method["lpom-foreground"]["recall"]),
        "pets_pom_moda": pct(method["pom"]["moda"]),
        "pets_clustering_moda": pct(method["clustering"]["moda"]),
        "pets_fitted": "LPOM's strength "
        + " and ".join(f"{value:g}" for value in method["lpom"]["fitted_min_strength"])
        + ", POM's person width "
        + " and ".join(f"{value:g} m" for value in method["pom"]["fitted_width_m"])
        + ", its masks from "
        + " and ".join(method["pom"]["fitted_masks"])
        + ", the baseline's views "
        + " and ".join(str(value) for value in method["clustering"]["fitted_min_views"]),
    }


def plaza_fields(load: Load) -> dict[str, str]:
    """The rendered plaza under PETS's seven cameras: a row per crowd and method."""
    rows = load("occupancy-synthetic-plaza")
    return {"plaza_table": occupancy_table(rows), "plaza_frames": str(rows[0]["frames"])}


def headline(load: Load) -> list[str]:
    cell = {(row["people"], row["method"]): row for row in load("occupancy-synthetic-room")}
    people = sorted({count for count, _ in cell})
    pets = {row["method"]: row for row in load("occupancy-pets")}
    return [
        "[The occupancy map (LPOM)](occupancy-map.md)",
        "in the rendered room, LPOM's MODA "
        + " and ".join(
            f"{pct(cell[count, 'lpom']['moda'])} ({count} {'person' if count == 1 else 'people'})" for count in people
        )
        + ", error "
        + " and ".join(f"{cell[count, 'lpom']['error_m']:.3f} m" for count in people)
        + "; on PETS 2009 S2.L1, POM's MODA "
        + f"{pct(pets['pom']['moda'])} and LPOM's {pct(pets['lpom']['moda'])}",
    ]
