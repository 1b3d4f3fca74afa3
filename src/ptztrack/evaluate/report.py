"""What a run leaves behind, each file written atomically.

* ``metrics.json``: the run's metrics;
* ``steps.csv``: per step the action, the commanded, landed and believed poses and the decision time;
* ``detections.csv``: per step every measurement the tracker was updated with, in the image and on the ground;
* ``tracks.csv``: per step every reported track's state and position covariance;
* ``tracks_mot.txt`` and ``truth_mot.txt``: the tracks and the truth in the MOTChallenge layout
  ``frame,id,left,top,width,height,conf,x,y,z`` (frames from 1, one per step; x and y on the ground
  in metres, printed so that they read back exactly; no boxes: -1), so that a run can be re-scored
  by any MOT tool (no truth_mot.txt for a run without ground truth);
* ``episode.png`` and ``episode.mp4``: pictures.
"""

import csv
import io
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure
from matplotlib.patches import Polygon

from ptztrack.evaluate.metrics import with_undefined_noted
from ptztrack.files import strict_json, write_atomically
from ptztrack.geometry.area import bounds_m
from ptztrack.geometry.ptz import ground_footprint
from ptztrack.loop.steps import Episode
from ptztrack.names import TRUTH_MOT_FILE
from ptztrack.track.observation import ground_points
from ptztrack.types import Tracks
from ptztrack.view.video import VIDEO_MAX_STEPS, RenderView, write_episode_video

TRACK_COLUMNS = ("frame", "id", "x_m", "y_m", "vx_m_s", "vy_m_s", "var_x_m2", "cov_xy_m2", "var_y_m2")
STEP_COLUMNS = (
    "step",
    "action",
    "commanded_pan_deg",
    "commanded_tilt_deg",
    "commanded_zoom",
    "pan_deg",
    "tilt_deg",
    "zoom",
    "tracker_pan_deg",
    "tracker_tilt_deg",
    "tracker_zoom",
    "pose_known",
    "decision_ms",
)
DETECTION_COLUMNS = ("step", "feet_u_px", "feet_v_px", "height_px", "score", "x_m", "y_m", "person")
MOT_COLUMNS = ("frame", "id", "left", "top", "width", "height", "conf", "x", "y", "z")


def metrics_json(metrics: dict) -> bytes:
    """Strict JSON: a figure without a value is null, and ``undefined`` says why."""
    return strict_json(dict(sorted(with_undefined_noted(metrics).items())))


def _csv(header, rows) -> bytes:
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    if header:
        writer.writerow(header)
    writer.writerows(rows)
    return text.getvalue().encode()


def _exact(value: float) -> str:
    """A float printed so that it reads back to the same value."""
    return repr(float(value))


def steps_csv(episode: Episode) -> bytes:
    """One row per step: the action, the commanded, landed and believed poses, the decision time."""
    rows = (
        [step, int(action)]
        + [f"{value:.6g}" for value in (*commanded, *pose, *believed)]
        + [int(known), f"{1e3 * decision_s:.4f}"]
        for step, (action, commanded, pose, believed, known, decision_s) in enumerate(
            zip(
                episode.actions,
                episode.commanded,
                episode.poses,
                episode.tracker_poses,
                episode.pose_known,
                episode.decision_s,
                strict=True,
            )
        )
    )
    return _csv(STEP_COLUMNS, rows)


def detections_csv(episode: Episode) -> bytes:
    """One row per measurement: its feet in the image, height, score, its ground point through the
    pose the tracker used (empty where the feet lie above the horizon), and the true person's index
    where a simulation knows it (else -1)."""
    rows = []
    for step, (detections, pose) in enumerate(zip(episode.detections, episode.tracker_poses, strict=True)):
        ground_xy, on_ground = ground_points(detections.feet_px, episode.camera, pose)
        for feet, height, score, ground, ok, person in zip(
            detections.feet_px, detections.height_px, detections.score, ground_xy, on_ground, detections.person_index,
            strict=True,
        ):  # fmt: skip
            rows.append(
                [step, f"{feet[0]:.4f}", f"{feet[1]:.4f}", f"{height:.4f}", f"{score:.6g}"]
                + ([f"{ground[0]:.6f}", f"{ground[1]:.6f}"] if ok else ["", ""])
                + [int(person)]
            )
    return _csv(DETECTION_COLUMNS, rows)


def mot_rows(frame: int, tracks: Tracks) -> list[list]:
    """One picture's tracks as MOTChallenge rows (``frame, id, -1, -1, -1, -1, 1, x_m, y_m, 0``), the
    positions exact."""
    return [
        [frame, int(track_id), -1, -1, -1, -1, 1, _exact(mean[0]), _exact(mean[1]), 0]
        for track_id, mean in zip(tracks.ids, tracks.mean, strict=True)
    ]


def tracks_mot(episode: Episode) -> bytes:
    """The reported tracks in the MOTChallenge layout, one row per track and step (from 1), no header."""
    return _csv((), (row for step, tracks in enumerate(episode.tracks) for row in mot_rows(step + 1, tracks)))


def truth_mot(episode: Episode) -> bytes:
    """The truth in the MOTChallenge layout, one row per present person and step, ids from 0 by column."""
    positions_m = episode.truth.positions_m
    rows = (
        [
            step + 1,
            person,
            -1,
            -1,
            -1,
            -1,
            1,
            _exact(positions_m[step, person, 0]),
            _exact(positions_m[step, person, 1]),
            0,
        ]
        for step, person in zip(*np.nonzero(episode.truth.present), strict=True)
    )
    return _csv((), rows)


def tracks_csv(episode: Episode) -> bytes:
    """One row per track and frame: position, velocity and position covariance."""
    rows = (
        [frame, int(track_id)]
        + [f"{value:.6f}" for value in mean]
        + [f"{covariance[0, 0]:.6g}", f"{covariance[0, 1]:.6g}", f"{covariance[1, 1]:.6g}"]
        for frame, tracks in enumerate(episode.tracks)
        for track_id, mean, covariance in zip(tracks.ids, tracks.mean, tracks.covariance, strict=True)
    )
    return _csv(TRACK_COLUMNS, rows)


def episode_figure(episode: Episode, title: str = "") -> Figure:
    """Ground-plane picture of the last ``VIDEO_MAX_STEPS`` steps (those of the run's video): true paths
    (grey), tracks (coloured by id), camera footprints over time (outlines)."""
    figure = Figure(figsize=(7, 7))
    axes = figure.add_subplot()
    camera = episode.camera
    first = max(len(episode.poses) - VIDEO_MAX_STEPS, 0)
    footprints = ground_footprint(camera, episode.poses[first:], max_range_m=40.0)
    axes.add_collection(PolyCollection(list(footprints), facecolors="none", edgecolors="tab:blue", alpha=0.25, lw=0.8))
    axes.fill(*footprints[-1].T, color="tab:blue", alpha=0.08, lw=0)
    axes.add_patch(Polygon(episode.area_polygon_m, closed=True, fill=False, ls="--", color="black", lw=1))
    for path in np.swapaxes(episode.truth.positions_m[first:], 0, 1):
        axes.plot(*path.T, color="0.55", lw=3, alpha=0.6, solid_capstyle="round")
    colours = matplotlib.colormaps["tab20"]
    track_paths: dict[int, list] = {}
    for tracks in episode.tracks[first:]:
        for track_id, mean in zip(tracks.ids, tracks.mean, strict=True):
            track_paths.setdefault(int(track_id), []).append(mean[:2])
    for track_id, points in track_paths.items():
        path = np.asarray(points)
        axes.plot(path[:, 0], path[:, 1], ".-", ms=2, lw=1, color=colours(track_id % 20))
        axes.annotate(str(track_id), (path[-1, 0], path[-1, 1]), fontsize=7, color=colours(track_id % 20))
    axes.plot(*camera.centre_m[:2], "k^", ms=9)
    axes.annotate(
        "camera", (camera.centre_m[0], camera.centre_m[1]), xytext=(6, -3), textcoords="offset points", fontsize=8
    )
    margin_m = 2.0
    low_m, high_m = bounds_m(np.vstack([episode.area_polygon_m, camera.centre_m[:2]]))
    axes.set_xlim(low_m[0] - margin_m, high_m[0] + margin_m)
    axes.set_ylim(low_m[1] - margin_m, high_m[1] + margin_m)
    axes.set_aspect("equal")
    axes.set_xlabel("x [m]")
    axes.set_ylabel("y [m]")
    axes.set_title(
        title or "truth (grey), tracks (colour, id at the end), camera footprints (blue outlines, last one shaded)"
    )
    figure.tight_layout()
    return figure


def write_figure(path: Path, figure: Figure) -> None:
    """A Matplotlib figure as a PNG, written atomically and without a timestamp (same data, same bytes)."""
    png = io.BytesIO()
    figure.savefig(png, format="png", dpi=110, metadata={"Software": None})
    write_atomically(Path(path), png.getvalue())


def write_outputs(
    directory: Path,
    episode: Episode,
    metrics: dict,
    title: str = "",
    render_view: RenderView | None = None,
    with_truth: bool = True,
) -> None:
    """Write the files of ``RUN_FILES`` into ``directory`` (created if needed): episode.mp4 only with
    ``render_view`` (see :mod:`ptztrack.view.video`), truth_mot.txt only ``with_truth`` (a real camera's
    run has none); the pictures captioned with ``title``."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    write_atomically(directory / "metrics.json", metrics_json(metrics))
    for name, contents in (
        ("steps.csv", steps_csv),
        ("detections.csv", detections_csv),
        ("tracks.csv", tracks_csv),
        ("tracks_mot.txt", tracks_mot),
        *([(TRUTH_MOT_FILE, truth_mot)] if with_truth else []),
    ):
        write_atomically(directory / name, contents(episode))
    write_figure(directory / "episode.png", episode_figure(episode, title))
    if render_view is not None:
        write_episode_video(directory / "episode.mp4", episode, render_view, title)
