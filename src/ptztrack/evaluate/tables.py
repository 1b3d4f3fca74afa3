"""The papers' tables: per column, the mean over sequences of each figure."""

from collections.abc import Sequence

import numpy as np

from ptztrack.evaluate.metrics import DISPLAY, standard_error

# The paper's rows.
SUMMARY_KEYS = ("mota", "motp_m", "height_px", "detections", "zoom")


def summarise(rows: Sequence[dict]) -> list[dict]:
    """Per table column, in the order of first appearance, the mean over its runs of the paper's figures
    (the paper averages per-sequence results), with ``instances`` (person-instances per run),
    ``mota_per_sequence`` (in (fold, seed) order, so that columns pair up run by run), ``mota_se``
    (the standard error of the mean; 0 for one run), ``mota_sd`` (the standard deviation over the
    runs; 0 for one) and ``seeds`` (how many); rows of a protocol with folds also give ``mota_folds``,
    the mean of each fold."""
    summary = []
    for label in dict.fromkeys(row["label"] for row in rows):
        mine = sorted((row for row in rows if row["label"] == label), key=lambda row: (row.get("fold", 0), row["seed"]))
        means = {key: float(np.mean([row[key] for row in mine])) for key in SUMMARY_KEYS}
        mota = [row["mota"] for row in mine]
        first = mine[0]
        entry = {
            "strategy": first["strategy"],
            "label": label,
            "beta": first["beta"],
            "sequences": len(mine),
            "seeds": len({row["seed"] for row in mine}),
            **means,
            "mota_se": standard_error(mota),
            "mota_sd": float(np.std(mota, ddof=1)) if len(mota) > 1 else 0.0,
            "instances": float(np.mean([row["objects"] for row in mine])),
            "mota_per_sequence": mota,
        }
        folds = sorted({row["fold"] for row in mine if "fold" in row})
        if folds:
            entry["mota_folds"] = [
                float(np.mean([row["mota"] for row in mine if row["fold"] == fold])) for fold in folds
            ]
        summary.append(entry)
    return summary


def paired_difference(summary: Sequence[dict], first: str, second: str) -> tuple[float, float, int]:
    """The mean per-sequence MOTA difference of column ``first`` minus column ``second``, its
    standard error and the number of sequences (the columns must share their sequences)."""
    columns = {row["label"]: row for row in summary}
    a, b = (np.asarray(columns[label]["mota_per_sequence"]) for label in (first, second))
    if len(a) != len(b):
        raise ValueError(f"{first} and {second} ran {len(a)} and {len(b)} sequences: they do not pair up")
    difference = a - b
    return float(difference.mean()), standard_error(difference), len(difference)


def format_table(summary: Sequence[dict], title: str = "", spread: str = "mota_se") -> str:
    """The paper's layout: a row per figure, a column per strategy; under MOTA its ``spread`` over the
    runs, in points: the standard error (``mota_se``) or the standard deviation (``mota_sd``)."""
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
        if key == "mota" and any(row["sequences"] > 1 for row in summary):
            errors = (
                f"+-{100 * row[spread]:.1f}"[:column].rjust(column)
                for row, column in zip(summary, columns, strict=True)
            )
            lines.append(" " * width + "".join(errors))
    return "\n".join(lines)
