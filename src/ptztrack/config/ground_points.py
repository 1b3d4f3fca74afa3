"""A ground points file (``camera calibrate --geometry --ground-points FILE``): pixels of a picture and
where they lie on the ground, in metres.

YAML::

    snapshot: ground.png          # optional: the picture the points were picked in (beside this file)
    points:                       # [u_px, v_px, x_m, y_m] each
      - [412.5, 300.0, 3.2, -1.0]

or CSV with the header ``u_px,v_px,x_m,y_m`` and a row per point. Pixels: the picture's top left corner
at (0, 0), pixel (row, col)'s centre at (col + 0.5, row + 0.5).
"""

import csv
import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ptztrack.config.reading import ScenarioError, read_yaml
from ptztrack.files import read_text

CSV_HEADER = ["u_px", "v_px", "x_m", "y_m"]
MAX_POINTS = 1000


@dataclass(frozen=True)
class GroundPoints:
    """pixels_px (N, 2), ground_m (N, 2); snapshot : the picture they were picked in, if the file names it."""

    pixels_px: np.ndarray
    ground_m: np.ndarray
    snapshot: Path | None


def load_ground_points(path: str | Path) -> GroundPoints:
    """Read a ground points file; a :class:`ScenarioError` of one line naming the file where it is not one
    (whether the points can place a camera is :func:`ptztrack.geometry.self_calibration.ground_points_problem`'s)."""
    path = Path(path)
    snapshot = None
    if path.suffix.lower() == ".csv":
        text = read_text(path, "ground points", 1_000_000, ScenarioError)
        rows = list(csv.reader(io.StringIO(text)))
        if not rows or [cell.strip() for cell in rows[0]] != CSV_HEADER:
            raise ScenarioError(f"{path}: expected a CSV whose first line is {','.join(CSV_HEADER)}")
        values = [row for row in rows[1:] if row]
    else:
        data = read_yaml(path, "ground points", ScenarioError)
        if not isinstance(data, dict) or "points" not in data or not set(data) <= {"points", "snapshot"}:
            raise ScenarioError(f"{path}: expected a mapping with points (and optionally snapshot)")
        values = data["points"]
        if data.get("snapshot") is not None:
            snapshot = path.parent / str(data["snapshot"])
    if not isinstance(values, list) or len(values) > MAX_POINTS:
        raise ScenarioError(f"{path}: points: expected a list of at most {MAX_POINTS} [u_px, v_px, x_m, y_m]")
    try:
        points = np.array([[float(value) for value in row] for row in values], dtype=float).reshape(-1, 4)
    except (TypeError, ValueError):
        raise ScenarioError(f"{path}: points: each point is four numbers, u_px, v_px, x_m, y_m") from None
    if any(len(row) != 4 for row in values):
        raise ScenarioError(f"{path}: points: each point is four numbers, u_px, v_px, x_m, y_m")
    return GroundPoints(points[:, :2], points[:, 2:], snapshot)
