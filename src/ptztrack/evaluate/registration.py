"""The registration experiment (scale-invariant tracking paper): how well live PTZ views are registered,
and what registration is worth to the closed loop.

Accuracy: reference views over the recording scenario's field of regard
(:func:`ptztrack.camera.pose_feedback.reference_poses`) are rendered from the
recording's first frame and bundle-adjusted from rough poses. Live views at
random reachable poses (pan and tilt uniform over the action grid's range,
zoom uniform from 1 to the grid's largest) are rendered from random later
frames, where people have moved, and registered. The errors are those of the
registered pose against the true one: the focal length in %, and on the
ground (m) the median over a grid of points of the walkable area that the
view sees.

Closed loop: the scenario run with one policy while the camera lands off its
commanded poses, the tracker taking its pose from each source in turn.
"""

import time
from collections.abc import Callable, Sequence

import numpy as np

from ptztrack.camera.pose_feedback import registration_camera
from ptztrack.config import PoseError, Scenario
from ptztrack.episode import run_episode
from ptztrack.evaluate.experiment import Cell
from ptztrack.evaluate.metrics import episode_metrics
from ptztrack.geometry.ptz import apply_homography, ground_to_image, image_to_ground, inside_image
from ptztrack.geometry.registration import ReferenceIndex, register
from ptztrack.scene.pets import RecordedVideo, load_mot_ground_truth

POSE_SOURCES = ("oracle", "commanded", "registered")
# Live views come from frames after this one, so that people have moved since the reference frame.
FIRST_LIVE_FRAME = 50
GROUND_GRID_POINTS = 25


def registration_errors(
    scenario: Scenario,
    index: ReferenceIndex,
    views: int,
    seed: int = 0,
    progress: Callable[[int, int], None] | None = None,
) -> list[dict]:
    """Register ``views`` live views at random reachable poses of a recording scenario.

    One row per view: ``pose`` (pan_deg, tilt_deg, zoom), ``frame``, ``registered`` (bool),
    ``focal_err_pct`` and ``ground_err_m`` (None when not registered, and the ground error also when
    the view sees none of the walkable area), ``seconds`` (of registration).
    """
    recording = scenario.recording
    virtual, whole_frame_pose = registration_camera(scenario)
    camera, grid = virtual.camera, scenario.action_grid()
    annotations = load_mot_ground_truth(recording.ground_truth)
    low, high = annotations.ground_m.min(axis=0), annotations.ground_m.max(axis=0)
    x, y = np.meshgrid(*(np.linspace(low[k], high[k], GROUND_GRID_POINTS) for k in range(2)))
    ground_points_m = np.c_[x.ravel(), y.ravel()]

    rng = np.random.default_rng(seed)
    poses = np.c_[
        whole_frame_pose[0] + rng.uniform(grid.pan_deg.min(), grid.pan_deg.max(), views),
        whole_frame_pose[1] + rng.uniform(grid.tilt_deg.min(), grid.tilt_deg.max(), views),
        rng.uniform(1.0, grid.zoom.max(), views),
    ]
    # Ascending frames: the video is read forwards once.
    frames = np.sort(rng.integers(FIRST_LIVE_FRAME, annotations.frame.max() + 1, views))
    video = RecordedVideo(recording.video, recording.recorded_size_px)
    rows = []
    for number, (pose, frame) in enumerate(zip(poses, frames), start=1):
        image = virtual.render(video.frame(int(frame)), pose)
        start = time.perf_counter()
        result = register(camera, index, image)
        seconds = time.perf_counter() - start
        focal_err_pct = ground_err_m = None
        if result is not None:
            focal_err_pct = 100.0 * abs(result.focal_px / (pose[2] * camera.f_min_px) - 1.0)
            pixels = apply_homography(ground_to_image(camera, pose), ground_points_m)
            seen = inside_image(camera, pixels) & np.all(np.isfinite(pixels), axis=1)
            if seen.any():
                estimated = apply_homography(image_to_ground(camera, result.pose), pixels[seen])
                ground_err_m = float(np.median(np.linalg.norm(estimated - ground_points_m[seen], axis=1)))
        rows.append(
            {
                "pose": pose.tolist(),
                "frame": int(frame),
                "registered": result is not None,
                "focal_err_pct": focal_err_pct,
                "ground_err_m": ground_err_m,
                "seconds": seconds,
            }
        )
        if progress is not None:
            progress(number, views)
    return rows


def summarise_registration(rows: Sequence[dict]) -> dict:
    """Medians and 90th percentiles of the errors over the views.

    A view that was not registered counts as an error larger than any, so it raises the percentiles
    rather than vanishing from them; percentiles are order statistics (no interpolation with such
    views), None when they fall on such a view. A registered view that sees none of the walkable area has no ground error and is left
    out of the ground error's statistics only.
    """
    registered = np.array([row["registered"] for row in rows])
    focal = np.array([row["focal_err_pct"] if row["registered"] else np.inf for row in rows], dtype=float)
    ground = np.array([row["ground_err_m"] if row["registered"] else np.inf for row in rows], dtype=float)
    ground = ground[~np.isnan(ground)]

    def percentile(values, q):
        value = float(np.percentile(values, q, method="inverted_cdf")) if len(values) else np.inf
        return value if np.isfinite(value) else None

    return {
        "views": len(rows),
        "registered": int(registered.sum()),
        "focal_err_median_pct": percentile(focal, 50),
        "focal_err_p90_pct": percentile(focal, 90),
        "ground_err_median_m": percentile(ground, 50),
        "ground_err_p90_m": percentile(ground, 90),
        "register_ms_median": float(1e3 * np.median([row["seconds"] for row in rows])),
    }


def closed_loop_cells(
    scenario: Scenario, pose_error: PoseError, strategy: str = "smpl", sources: Sequence[str] = POSE_SOURCES
) -> list[Cell]:
    """One run of ``strategy`` per pose source, the camera landing off its commands by ``pose_error``."""
    camera = scenario.camera.model_copy(update={"pose_error": pose_error})
    cells = []
    for source in sources:
        feedback = scenario.pose_feedback.model_copy(update={"source": source})
        cells.append(Cell(scenario.model_copy(update={"camera": camera, "pose_feedback": feedback}), strategy, 0, source))
    return cells


def run_closed_loop_cell(cell: Cell) -> dict:
    """One closed-loop run: its metrics, with ``pose_source``, the median error of the tracker's pose
    (``tracker_pan_err_deg``, ``tracker_tilt_err_deg``, ``tracker_zoom_err_pct``) and the fraction of
    steps whose pose the source gave (``pose_known``)."""
    episode = run_episode(cell.scenario, cell.strategy, cell.seed)
    error = np.abs(episode.tracker_poses - episode.poses)
    return {
        "pose_source": cell.scenario.pose_feedback.source,
        "strategy": cell.strategy,
        **episode_metrics(episode),
        "tracker_pan_err_deg": float(np.median(error[:, 0])),
        "tracker_tilt_err_deg": float(np.median(error[:, 1])),
        "tracker_zoom_err_pct": float(100 * np.median(error[:, 2] / episode.poses[:, 2])),
        "pose_known": float(episode.pose_known.mean()),
    }
