"""The papers' tables: per column, the mean over sequences of each figure."""

from collections.abc import Sequence

import numpy as np

from ptztrack.evaluate.metrics import DISPLAY

# The paper's rows.
SUMMARY_KEYS = ("mota", "motp_m", "height_px", "detections", "zoom")


def summarise(rows: Sequence[dict]) -> list[dict]:
    """Per table column, in the order of first appearance, the mean over sequences of the paper's figures
    (the paper averages per-sequence results)."""
    summary = []
    for label in dict.fromkeys(row["label"] for row in rows):
        mine = [row for row in rows if row["label"] == label]
        means = {key: float(np.mean([row[key] for row in mine])) for key in SUMMARY_KEYS}
        first = mine[0]
        summary.append(
            {"strategy": first["strategy"], "label": label, "beta": first["beta"], "sequences": len(mine), **means}
        )
    return summary


def format_table(summary: Sequence[dict], title: str = "") -> str:
    """The paper's layout: a row per figure, a column per strategy."""
    width = max(len(DISPLAY[key][0]) for key in SUMMARY_KEYS)
    columns = [max(10, len(row["label"]) + 2) for row in summary]
    lines = [title] if title else []
    lines.append(
        " " * width + "".join(f"{row['label']:>{column}}" for row, column in zip(summary, columns, strict=True))
    )
    for key in SUMMARY_KEYS:
        label, fmt = DISPLAY[key]
        cells = (f"{fmt.format(row[key]):>{column}}" for row, column in zip(summary, columns, strict=True))
        lines.append(f"{label:<{width}}" + "".join(cells))
    return "\n".join(lines)
