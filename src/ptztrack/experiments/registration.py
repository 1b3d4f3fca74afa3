"""The scale-invariant tracking paper's registration experiment: live PTZ views of a recording
registered against its reference views, and the closed loop on the poses a pose source gives.

The views: :func:`registration_views` (errors per view by
:func:`ptztrack.evaluate.registration.registration_errors`), their summary
(:func:`summarise_registration`) and table (:func:`format_registration`). The closed loop: one cell
per pose source (:func:`closed_loop_cells`), the camera landing off its commands, and its table
(:func:`format_closed_loop`).
"""

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ptztrack.builders.episode import run_episode
from ptztrack.builders.recording import recorded_size_px
from ptztrack.builders.registration import (
    LIVE_GAP_S,
    live_view_model,
    reference_frames,
    registration_camera,
    scenario_reference_poses,
)
from ptztrack.builders.world import action_grid
from ptztrack.config import PoseError, Scenario, ScenarioError
from ptztrack.evaluate.metrics import episode_metrics
from ptztrack.evaluate.registration import GROUND_ERRORS, registration_errors
from ptztrack.experiments.cells import Cell, cell_policy
from ptztrack.geometry.registration import ReferenceIndex
from ptztrack.loop.steps import Episode
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
            f"({live_gap_frames(scenario)} frames, {LIVE_GAP_S:g} s, after the last reference view's): the "
            "experiment needs a longer recording"
        )
    frames = np.sort(rng.integers(first_frame, last_frame + 1, views))
    video = RecordedVideo(
        scenario.required_video("the registration experiment"),
        recorded_size_px(recording),
        int(frames[-1]) + 1,
    )
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
        "min_gap_frames": live_gap_frames(scenario),
        "first_live_frame": first_live_frame(scenario, whole_frame_pose),
    }


def live_gap_frames(scenario: Scenario) -> int:
    """``LIVE_GAP_S`` in the recording's frames (its frame rate: the step rate times the frame step)."""
    recording = scenario.required_recording("the registration experiment")
    return math.ceil(LIVE_GAP_S * scenario.frame_rate_hz * recording.frame_step)


def first_live_frame(scenario: Scenario, whole_frame_pose) -> int:
    """The first frame a live view of the registration experiment may show: :func:`live_gap_frames`
    after the last reference view's frame."""
    sweep = reference_frames(len(scenario_reference_poses(scenario, whole_frame_pose)))
    return int(sweep[-1] + live_gap_frames(scenario))


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
    assert isinstance(episode, Episode), "registration runs one camera"
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


def summarise_registration(rows: Sequence[dict]) -> dict:
    """Medians and 90th percentiles of the errors over the views.

    A view that was not registered counts as an error larger than any, so it raises the percentiles
    rather than vanishing from them; percentiles are order statistics (no interpolation with such
    views), None when they fall on such a view. A view that sees none of the walkable area has no
    ground errors and is left out of their statistics only.
    """
    registered = np.array([row["registered"] for row in rows])

    def percentile(values, q):
        value = float(np.percentile(values, q, method="inverted_cdf")) if len(values) else np.inf
        return value if np.isfinite(value) else None

    summary: dict[str, float | None] = {"views": len(rows), "registered": int(registered.sum())}
    for key, needs_registration in {"focal_err_pct": True, **GROUND_ERRORS}.items():
        # None: a view that sees nothing (NaN, left out), or one not registered (inf, when that counts).
        values = np.array([row[key] if row["registered"] or not needs_registration else np.inf for row in rows], float)
        values = values[~np.isnan(values)]
        name, unit = key.rsplit("_", 1)
        summary[f"{name}_median_{unit}"] = percentile(values, 50)
        summary[f"{name}_p90_{unit}"] = percentile(values, 90)
    roll_err_deg = [abs(row["roll_err_deg"]) for row in rows if row["registered"]]
    summary["roll_err_median_deg"] = float(np.median(roll_err_deg)) if roll_err_deg else None
    summary["register_ms_median"] = float(1e3 * np.median([row["seconds"] for row in rows]))
    return summary


def format_registration(summary: dict, settings: dict, reference_views: int, image_size_px) -> str:
    """The registration's table: how many of the views registered against ``reference_views`` at
    ``image_size_px`` (width, height), the live views (:func:`describe_live_views` of ``settings``),
    then the median and 90th percentile of each error of ``summary`` (:func:`summarise_registration`)
    and the median time per view."""
    lines = [
        f"Registration of {summary['views']} live views at random reachable poses, "
        f"{image_size_px[0]} x {image_size_px[1]} px, "
        f"against {reference_views} reference views: {summary['registered']} registered",
        f"  {describe_live_views(settings)}",
    ]
    for name, key, unit in (
        ("focal length error", "focal_err", "pct"),
        ("ground error", "ground_err", "m"),
        ("  with true pose", "oracle_ground_err", "m"),
        ("  with lens", "lens_ground_err", "m"),
    ):
        median, p90 = (_unless_failed(summary[f"{key}_{which}_{unit}"]) for which in ("median", "p90"))
        symbol = "%" if unit == "pct" else unit
        lines.append(f"  {name:<19} median {median} {symbol}   p90 {p90} {symbol}")
    lines.append(f"  time per view       median {summary['register_ms_median']:.0f} ms")
    return "\n".join(lines)


def format_closed_loop(rows: Sequence[dict], policy: str, scenario: Scenario, pose_error: PoseError) -> str:
    """The closed loop's table: a line per pose source (:func:`run_closed_loop_cell`'s rows) of
    ``policy`` in ``scenario``, the camera landing off its commands by ``pose_error``."""
    lines = [
        f"Closed loop: {policy}, {scenario.detector.kind} detector, {scenario.tracker.association} association, "
        f"camera off its commands by {pose_error.pan_tilt_sigma_deg:g} deg and {100 * pose_error.zoom_sigma:g} % "
        "zoom (1 sigma)"
    ]
    width = max(len(name) for name in POSE_SOURCES)
    lines.append(f"  {'pose source':<{width + 2}} MOTA     MOTP [m]  pose known  tracker pose error (pan, tilt, zoom)")
    for row in rows:
        lines.append(
            f"  {row['pose_source']:<{width + 2}} {row['mota']:6.1%}   {row['motp_m']:.3f}     {row['pose_known']:6.1%}"
            f"      {row['tracker_pan_err_deg']:.3f} deg, {row['tracker_tilt_err_deg']:.3f} deg, "
            f"{row['tracker_zoom_err_pct']:.2f} %"
        )
    return "\n".join(lines)


def describe_live_views(settings: dict) -> str:
    """One line on the registration experiment's live views (see ``live_view_settings``)."""
    frames = (
        f"reference views of frames {settings['reference_frames'][0]}-{settings['reference_frames'][1]}, "
        f"live views of frames {settings['first_live_frame']} on"
    )
    if settings["exact"]:
        return f"exact pinhole live views; {frames}"
    k1 = f"k1 {settings['k1_wide']:g} at zoom 1 to {settings['k1_tele']:g} at zoom {settings['tele_zoom']:g}"
    return (
        f"live views rolled up to {settings['roll_max_deg']:g} deg, principal point up to "
        f"{settings['principal_offset_max_px']:g} px off, {k1}, gain {settings['gain'][0]:g}-{settings['gain'][1]:g}, "
        f"brightness +-{settings['brightness_max']:g}, JPEG quality {settings['jpeg_quality']}; {frames}"
    )


def _unless_failed(error: float | None) -> str:
    """An error statistic, or what it means when it fell on views that were not registered."""
    return "(unregistered views)" if error is None else f"{error:.3f}"
