"""What a run leaves behind: metrics.json, tracks.csv, episode.png and episode.mp4, each written atomically."""

import csv
import io
import json
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

from ptztrack.episode import Episode
from ptztrack.files import write_atomically
from ptztrack.evaluate.video import RenderView, write_episode_video
from ptztrack.geometry.ptz import ground_footprint

TRACK_COLUMNS = ("frame", "id", "x_m", "y_m", "vx_m_s", "vy_m_s", "var_x_m2", "cov_xy_m2", "var_y_m2")


def metrics_json(metrics: dict) -> bytes:
    return (json.dumps(metrics, indent=2, sort_keys=True) + "\n").encode()


def tracks_csv(episode: Episode) -> bytes:
    """One row per track and frame: position, velocity and position covariance."""
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow(TRACK_COLUMNS)
    for frame, tracks in enumerate(episode.tracks):
        for track_id, mean, covariance in zip(tracks.ids, tracks.mean, tracks.covariance, strict=True):
            writer.writerow(
                [frame, int(track_id)]
                + [f"{value:.6f}" for value in mean]
                + [f"{covariance[0, 0]:.6g}", f"{covariance[0, 1]:.6g}", f"{covariance[1, 1]:.6g}"]
            )
    return text.getvalue().encode()


def episode_figure(episode: Episode, title: str = "") -> Figure:
    """Ground-plane picture: true paths (grey), tracks (coloured by id), camera footprints over time (outlines)."""
    figure = Figure(figsize=(7, 7))
    axes = figure.add_subplot()
    camera = episode.camera
    (x0, y0), (x1, y1) = episode.area_bounds_m
    footprints = ground_footprint(camera, episode.poses, max_range_m=40.0)
    for footprint in footprints:
        axes.fill(*footprint.T, facecolor="none", edgecolor="tab:blue", alpha=0.25, lw=0.8)
    axes.fill(*footprints[-1].T, color="tab:blue", alpha=0.08, lw=0)
    axes.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, ls="--", color="black", lw=1))
    for path in np.swapaxes(episode.truth.positions_m, 0, 1):
        axes.plot(*path.T, color="0.55", lw=3, alpha=0.6, solid_capstyle="round")
    colours = matplotlib.colormaps["tab20"]
    track_paths: dict[int, list] = {}
    for frame, tracks in enumerate(episode.tracks):
        for track_id, mean in zip(tracks.ids, tracks.mean, strict=True):
            track_paths.setdefault(int(track_id), []).append((frame, *mean[:2]))
    for track_id, rows in track_paths.items():
        rows = np.asarray(rows)
        axes.plot(rows[:, 1], rows[:, 2], ".-", ms=2, lw=1, color=colours(track_id % 20))
        axes.annotate(str(track_id), rows[-1, 1:], fontsize=7, color=colours(track_id % 20))
    axes.plot(*camera.centre_m[:2], "k^", ms=9)
    axes.annotate("camera", camera.centre_m[:2], xytext=(6, -3), textcoords="offset points", fontsize=8)
    margin_m = 2.0
    axes.set_xlim(min(x0, camera.centre_m[0]) - margin_m, max(x1, camera.centre_m[0]) + margin_m)
    axes.set_ylim(min(y0, camera.centre_m[1]) - margin_m, max(y1, camera.centre_m[1]) + margin_m)
    axes.set_aspect("equal")
    axes.set_xlabel("x [m]")
    axes.set_ylabel("y [m]")
    axes.set_title(title or "truth (grey), tracks (colour, id at the end), camera footprints (blue outlines, last one shaded)")
    figure.tight_layout()
    return figure


def write_figure(path: Path, figure: Figure) -> None:
    """A Matplotlib figure as a PNG, written atomically and without a timestamp (same data, same bytes)."""
    png = io.BytesIO()
    figure.savefig(png, format="png", dpi=110, metadata={"Software": None})
    write_atomically(Path(path), png.getvalue())


def write_outputs(
    directory: Path, episode: Episode, metrics: dict, title: str = "", render_view: RenderView | None = None
) -> None:
    """Write metrics.json, tracks.csv and episode.png into ``directory`` (created if needed),
    and with ``render_view`` (see :mod:`ptztrack.evaluate.video`) episode.mp4, captioned with ``title``."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    write_atomically(directory / "metrics.json", metrics_json(metrics))
    write_atomically(directory / "tracks.csv", tracks_csv(episode))
    write_figure(directory / "episode.png", episode_figure(episode, title))
    if render_view is not None:
        write_episode_video(directory / "episode.mp4", episode, render_view, title)
