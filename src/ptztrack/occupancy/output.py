"""What the occupancy-map experiment leaves behind, per recording, each file written atomically.

* ``metrics.json``: the rows (one per method);
* ``detections.csv``: every kept detection: ``method, frame, x_m, y_m, score`` (a map method's: the
  mode's strength, with its covariance ``var_x_m2, cov_xy_m2, var_y_m2``; clustering: its views);
* ``tracks.csv``: the tracker's reported tracks fed by each map method: ``method, frame, id, x_m, y_m``;
* ``maps/frame_NNNNN.png``: the occupancy map of every ``images_every``-th frame, and
  ``occupancy.mp4``: of every frame; seen from above (x right, y up), the map in colour (scaled to
  each frame's largest value), the truth as white circles of the 0.5 m match radius, the map
  methods' detections as crosses (LPOM green, LPOM from silhouettes magenta, POM orange), the
  baseline's as cyan diamonds, the ids of the tracks fed by LPOM in yellow.
"""

import csv
import io
from pathlib import Path

import cv2
import numpy as np

from ptztrack.files import write_atomically, write_json
from ptztrack.occupancy.evaluation import MATCH_RADIUS_M, OccupancyRun
from ptztrack.view.video import write_video

PICTURE_WIDTH_PX = 600
CAPTION_PX = 28
TRUTH_BGR, CLUSTERING_BGR, TRACK_BGR = (255, 255, 255), (230, 200, 40), (0, 230, 255)
# The map methods' crosses, in the order they run: green, magenta, orange.
MAP_METHOD_BGR = ((60, 220, 60), (220, 60, 220), (0, 140, 255))
MAP_METHOD_COLOURS = ("green", "magenta", "orange")


def _scale(run: OccupancyRun) -> int:
    """Picture pixels per cell."""
    return max(1, PICTURE_WIDTH_PX // run.grid.shape[1])


def map_picture(run: OccupancyRun, frame: int, title: str) -> np.ndarray:
    """The map of ``frame`` with the truth, both methods' detections and the tracks: (h, w, 3) uint8 BGR,
    both sides even (for the video)."""
    scale, grid = _scale(run), run.grid
    rows, columns = grid.shape
    height, width = rows * scale + CAPTION_PX, columns * scale
    picture = np.zeros((height + height % 2, width + width % 2, 3), np.uint8)
    coloured = cv2.applyColorMap(run.frames.maps_u8[frame][::-1], cv2.COLORMAP_INFERNO)
    picture[: rows * scale, :width] = cv2.resize(coloured, (width, rows * scale), interpolation=cv2.INTER_NEAREST)

    def to_px(points_m) -> np.ndarray:
        points_m = np.asarray(points_m, dtype=float).reshape(-1, 2)
        u = (points_m[:, 0] - grid.origin_m[0]) / grid.cell_m * scale
        v = rows * scale - (points_m[:, 1] - grid.origin_m[1]) / grid.cell_m * scale
        return np.round(np.stack([u, v], axis=-1)).astype(int)

    truth = run.truth_m[frame]
    radius_px = int(round(MATCH_RADIUS_M / grid.cell_m * scale))
    for point in to_px(truth[~np.isnan(truth[:, 0])]):
        cv2.circle(picture, tuple(int(value) for value in point), radius_px, TRUTH_BGR, 1, cv2.LINE_AA)
    for point in to_px(run.clustering[frame].position_m):
        cv2.drawMarker(picture, tuple(int(value) for value in point), CLUSTERING_BGR, cv2.MARKER_DIAMOND, 12, 2)
    for kept, colour in zip(run.kept.values(), MAP_METHOD_BGR, strict=False):
        for point in to_px(kept[frame].position_m):
            cv2.drawMarker(picture, tuple(int(value) for value in point), colour, cv2.MARKER_CROSS, 14, 2)
    first = next(iter(run.kept))
    tracks = run.tracks[first][frame]
    for track_id, point in zip(tracks.ids, to_px(tracks.mean[:, :2]), strict=True):
        cv2.putText(picture, str(track_id), (int(point[0]) + 8, int(point[1]) - 8), 0, 0.45, TRACK_BGR, 1, cv2.LINE_AA)
    crosses = ", ".join(f"{method} {name}" for method, name in zip(run.kept, MAP_METHOD_COLOURS, strict=False))
    caption = f"{title}  frame {frame}   truth o   + {crosses}   clustering <>   {first} tracks id"
    cv2.putText(picture, caption, (6, rows * scale + 19), 0, 0.45, (255, 255, 255), 1, cv2.LINE_AA)
    return picture


def detections_csv(run: OccupancyRun) -> bytes:
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow(("method", "frame", "x_m", "y_m", "score", "var_x_m2", "cov_xy_m2", "var_y_m2"))
    for method, kept in run.kept.items():
        for frame, modes in enumerate(kept):
            for (x, y), strength, covariance in zip(modes.position_m, modes.strength, modes.covariance_m2, strict=True):
                writer.writerow((method, frame, x, y, strength, covariance[0, 0], covariance[0, 1], covariance[1, 1]))
    for frame, clusters in enumerate(run.clustering):
        for (x, y), views in zip(clusters.position_m, clusters.views, strict=True):
            writer.writerow(("clustering", frame, x, y, views, "", "", ""))
    return text.getvalue().encode()


def tracks_csv(run: OccupancyRun) -> bytes:
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow(("method", "frame", "id", "x_m", "y_m"))
    for method, method_tracks in run.tracks.items():
        for frame, tracks in enumerate(method_tracks):
            writer.writerows(
                (method, frame, track_id, x, y) for track_id, (x, y) in zip(tracks.ids, tracks.mean[:, :2], strict=True)
            )
    return text.getvalue().encode()


def write_occupancy_outputs(directory: Path, run: OccupancyRun, images_every: int) -> None:
    """Write the files listed in this module's docstring into ``directory`` (created if needed)."""
    directory = Path(directory)
    (directory / "maps").mkdir(parents=True, exist_ok=True)
    title = str(run.rows[0]["dataset"])
    write_json(directory / "metrics.json", run.rows)
    write_atomically(directory / "detections.csv", detections_csv(run))
    write_atomically(directory / "tracks.csv", tracks_csv(run))
    frames = len(run.clustering)
    for frame in range(0, frames, images_every):
        ok, png = cv2.imencode(".png", map_picture(run, frame, title))
        write_atomically(directory / "maps" / f"frame_{frame:05d}.png", png.tobytes())
    size = map_picture(run, 0, title).shape[1::-1]
    write_video(
        directory / "occupancy.mp4", (map_picture(run, f, title) for f in range(frames)), run.frame_rate_hz, size
    )
