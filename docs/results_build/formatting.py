"""The formatting every figure of a results page goes through, and the statistics the pages share."""

from __future__ import annotations

import math
import statistics
from collections.abc import Sequence
from statistics import mean


def pct(fraction: float, digits: int = 1) -> str:
    """A fraction as a percentage: 0.7642 -> '76.4 %'."""
    return f"{100 * fraction:.{digits}f} %"


def pct_pm(fraction: float, spread: float, digits: int = 1) -> str:
    """A fraction and its spread as percentages: '76.4 +- 2.6 %'."""
    return f"{100 * fraction:.{digits}f} +- {100 * spread:.{digits}f} %"


def points(fraction_difference: float, spread: float | None = None) -> str:
    """A difference of fractions in percentage points, signed: '+1.3' or '+1.3 +- 2.6'."""
    text = f"{100 * fraction_difference:+.1f}"
    return text if spread is None else f"{text} +- {100 * spread:.1f}"


def fixed(value: float, digits: int) -> str:
    """A number with ``digits`` decimals."""
    return f"{value:.{digits}f}"


def dimensions(values: Sequence[float]) -> str:
    """Sizes joined by ' x ': (640, 480) -> '640 x 480', (25.0, 18.0) -> '25 x 18'."""
    return " x ".join(f"{value:g}" for value in values)


def integer(value: float) -> str:
    """A count, rounded, with thousands separated by commas: 12668 -> '12,668'."""
    return f"{round(value):,}"


def table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A Markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def standard_error(values: Sequence[float]) -> float:
    """The standard error of the mean of ``values`` (sample standard deviation over sqrt(n))."""
    return statistics.stdev(values) / math.sqrt(len(values))


def paired(first: Sequence[float], second: Sequence[float]) -> tuple[float, float]:
    """The mean of ``first - second`` run by run and its standard error."""
    differences = [a - b for a, b in zip(first, second, strict=True)]
    return mean(differences), standard_error(differences)


def by_label(rows: Sequence[dict]) -> dict[str, dict]:
    return {row["label"]: row for row in rows}


def span(values: Sequence[float], signed: bool = False) -> str:
    """The smallest and largest of ``values`` (fractions) in points: '6.6 to 21.6' (one figure where
    they round alike; with ``signed``, '-0.2 to +0.1')."""
    low, high = (f"{100 * value:{'+' if signed else ''}.1f}" for value in (min(values), max(values)))
    return low if low == high else f"{low} to {high}"
