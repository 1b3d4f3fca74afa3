"""The scale-invariant tracking paper's registration experiment: live PTZ views of a recording
registered against its reference views, and the closed loop on the poses a pose source gives.

The views: :func:`registration_views` (errors per view by
:func:`ptztrack.evaluate.registration.registration_errors`). The closed loop: one cell per pose
source (:func:`closed_loop_cells`), the camera landing off its commands.
"""

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ptztrack.builders.episode import run_episode
from ptztrack.builders.registration import (
    LIVE_GAP_FRAMES,
    live_view_model,
    reference_frames,
    registration_camera,
    scenario_reference_poses,
)
from ptztrack.builders.world import action_grid
from ptztrack.config import PoseError, Scenario, ScenarioError
from ptztrack.evaluate.metrics import episode_metrics
from ptztrack.evaluate.registration import registration_errors
from ptztrack.experiments.cells import Cell, cell_policy
from ptztrack.geometry.registration import ReferenceIndex
from ptztrack.names import POSE_SOURCES
from ptztrack.scene.pets import RecordedVideo, load_mot_ground_truth

GROUND_GRID_POINTS = 25


def registration_views(
    scenario: Scenario,
    index: ReferenceIndex,
    views: int,
    seed: int = 0,
    progress: Callable[[int, int], None] | None = None,
) -> list[dict]:
    """Register ``views`` live views of a recording scenario as its ``camera.live_view`` takes them
    (see :func:`ptztrack.evaluate.registration.registration_errors`).

    The live views are at random reachable poses (pan and tilt uniform over the action grid's
    range, zoom uniform from 1 to the grid's largest) of random frames from :func:`first_live_frame`
    on; the ground errors are measured over a grid over the annotated people's extent.
    """
    recording = scenario.required_recording("the registration experiment")
    virtual, whole_frame_pose = registration_camera(scenario)
    grid = action_grid(scenario)
    annotations = load_mot_ground_truth(recording.ground_truth)
    low, high = annotations.ground_m.min(axis=0), annotations.ground_m.max(axis=0)
    x, y = np.meshgrid(*(np.linspace(low[k], high[k], GROUND_GRID_POINTS) for k in range(2)))
    rng = np.random.default_rng(seed)
    poses = np.c_[
        whole_frame_pose[0] + rng.uniform(grid.pan_deg.min(), grid.pan_deg.max(), views),
        whole_frame_pose[1] + rng.uniform(grid.tilt_deg.min(), grid.tilt_deg.max(), views),
        rng.uniform(1.0, grid.zoom.max(), views),
    ]
    first_frame = first_live_frame(scenario, whole_frame_pose)
    last_frame = int(annotations.frame.max())
    if first_frame > last_frame:
        raise ScenarioError(
            f"the recording ends at frame {last_frame}, before the first live frame {first_frame} "
            f"({LIVE_GAP_FRAMES} frames after the last reference view's)"
        )
    frames = np.sort(rng.integers(first_frame, last_frame + 1, views))
    video = RecordedVideo(scenario.required_video("the registration experiment"), recording.recorded_size_px)
    ground_m = np.c_[x.ravel(), y.ravel()]
    return registration_errors(virtual, index, video, poses, frames, ground_m, live_view_model(scenario), progress)


def live_view_settings(scenario: Scenario) -> dict:
    """The registration experiment's live views, as its JSON records them: ``camera.live_view``'s
    settings (the roll, principal point, distortion, light and compression; ``exact`` when there are
    none), and the frames of the reference sweep and of the live views (the time gap)."""
    _, whole_frame_pose = registration_camera(scenario)
    live_view = scenario.camera.live_view
    sweep = reference_frames(len(scenario_reference_poses(scenario, whole_frame_pose)))
    camera: dict[str, Any] = {"exact": True} if live_view is None else {"exact": False, **live_view.model_dump()}
    if live_view is not None:
        camera["principal_offset_image_size_px"] = list(scenario.pose_feedback.image_size_px)
    return {
        **camera,
        "reference_frames": [int(sweep[0]), int(sweep[-1])],
        "reference_frame_step": int(sweep[1] - sweep[0]) if len(sweep) > 1 else None,
        "min_gap_frames": LIVE_GAP_FRAMES,
        "first_live_frame": first_live_frame(scenario, whole_frame_pose),
    }


def first_live_frame(scenario: Scenario, whole_frame_pose) -> int:
    """The first frame a live view of the registration experiment may show: ``LIVE_GAP_FRAMES``
    after the last reference view's frame."""
    return int(reference_frames(len(scenario_reference_poses(scenario, whole_frame_pose)))[-1] + LIVE_GAP_FRAMES)


def closed_loop_cells(
    scenario: Scenario, pose_error: PoseError, strategy: str = "smpl", sources: Sequence[str] = POSE_SOURCES
) -> list[Cell]:
    """One run of ``strategy`` per pose source, the camera landing off its commands by ``pose_error``."""
    camera = scenario.camera.model_copy(update={"pose_error": pose_error})
    cells = []
    for source in sources:
        feedback = scenario.pose_feedback.model_copy(update={"source": source})
        with_source = scenario.model_copy(update={"camera": camera, "pose_feedback": feedback})
        cells.append(Cell(with_source, strategy, 0, source))
    return cells


def run_closed_loop_cell(cell: Cell) -> dict:
    """One closed-loop run: its metrics, with ``pose_source``, the median error of the tracker's pose
    (``tracker_pan_err_deg``, ``tracker_tilt_err_deg``, ``tracker_zoom_err_pct``) and the fraction of
    steps whose pose the source gave (``pose_known``)."""
    episode = run_episode(cell.scenario, cell_policy(cell), cell.seed)
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
