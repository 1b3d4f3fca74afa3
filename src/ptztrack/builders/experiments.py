"""The papers' experiments as data: cells of (scenario, strategy, seed), each a function of its inputs.

The executors of :mod:`ptztrack.evaluate.executors` run the cells; the
tables of :mod:`ptztrack.evaluate.tables` summarise their rows.
"""

import copy
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ptztrack import registry
from ptztrack.builders.episode import PolicySpec, run_episode
from ptztrack.builders.registration import (
    LIVE_GAP_FRAMES,
    live_view_model,
    reference_frames,
    registration_camera,
    scenario_reference_poses,
)
from ptztrack.builders.world import CameraSpec, DetectorSpec, action_grid, build_world
from ptztrack.config import PoseError, Scenario, ScenarioError
from ptztrack.evaluate.metrics import episode_metrics
from ptztrack.evaluate.registration import registration_errors
from ptztrack.geometry.registration import ReferenceIndex
from ptztrack.loop import episode_seeds
from ptztrack.names import POSE_SOURCES, STRATEGIES
from ptztrack.scene.pets import RecordedVideo, load_mot_ground_truth

# The paper's column names; 'rnd' is the 'random' policy.
POLICY_OF_STRATEGY = {"rnd": "random"}
INFORMATION_STRATEGIES = ("intg", "smpl")
# The strategies that draw from their random stream (the others are deterministic given the detections).
RANDOM_STRATEGIES = ("rnd", "smpl")
GROUND_GRID_POINTS = 25


def strategy_name(strategy: PolicySpec) -> str:
    """A strategy's column name: itself for a name, else the object's ``name`` or its type's name."""
    if isinstance(strategy, str):
        return strategy
    name = getattr(strategy, "name", None) or getattr(strategy, "__name__", None)
    return str(name or type(strategy).__name__)


@dataclass(frozen=True)
class Cell:
    """One episode of an experiment: a scenario run with one strategy and one sequence seed.

    strategy : a table name (``STRATEGIES``, 'rnd' for the 'random' policy), a registered policy,
        a policy object (each cell runs a fresh copy) or a policy factory.
    label : the table column it belongs to (the strategy, with beta where the table has several).
    camera, detector : in place of the scenario's (see :func:`ptztrack.builders.world.build_world`).
    fold : which scoring of a table under a protocol with several (:mod:`ptztrack.builders.pets`).
    """

    scenario: Scenario
    strategy: PolicySpec
    seed: int
    label: str = ""
    camera: CameraSpec | None = None
    detector: DetectorSpec | None = None
    fold: int | None = None

    @property
    def column(self) -> str:
        return self.label or strategy_name(self.strategy)


def _check_strategies(strategies: Sequence[PolicySpec]) -> None:
    known = set(STRATEGIES) | set(registry.names("policies"))
    unknown = sorted(s for s in strategies if isinstance(s, str) and s not in known)
    if unknown:
        raise ValueError(f"unknown strategies {unknown}; expected some of {', '.join(sorted(known))}")


def synthetic_cells(
    scenario: Scenario,
    sequences: int,
    strategies: Sequence[PolicySpec] = STRATEGIES,
    camera: CameraSpec | None = None,
    detector: DetectorSpec | None = None,
) -> list[Cell]:
    """The paper's synthetic protocol: every strategy on the same ``sequences`` sequences (seeds 0..n-1)."""
    _check_strategies(strategies)
    return [
        Cell(scenario, strategy, seed, camera=camera, detector=detector)
        for strategy in strategies
        for seed in range(sequences)
    ]


def seed_matters(scenario: Scenario, strategy: PolicySpec) -> bool:
    """Whether a run of ``strategy`` depends on its seed: a strategy that draws, a detector that does
    (every one but OpenCV's HOG, which finds the same people in the same image), or an information-gain
    strategy planning with draws of a detector model it learns."""
    learning = scenario.detector.model not in ("a-priori", "true") and scenario.detector.kind != "ideal"
    return (
        strategy in RANDOM_STRATEGIES
        or scenario.detector.kind != "hog"
        or (strategy in INFORMATION_STRATEGIES and learning)
    )


def recording_cells(
    scenario: Scenario,
    betas: Sequence[float],
    strategies: Sequence[PolicySpec] = STRATEGIES,
    seeds: int = 1,
    fold: int | None = None,
) -> list[Cell]:
    """The paper's realistic protocol (section 5.2): each strategy over the recording, the
    information-gain ones once per ``beta`` of the patrolling term; with seeds 0..``seeds``-1 where the
    run depends on its seed (:func:`seed_matters`), else once."""
    _check_strategies(strategies)
    columns = [(scenario, strategy, "") for strategy in strategies if strategy not in INFORMATION_STRATEGIES]
    for beta in betas:
        with_beta = scenario.model_copy(update={"control": scenario.control.model_copy(update={"beta": beta})})
        columns += [(with_beta, s, f"{s} b{beta:g}") for s in strategies if s in INFORMATION_STRATEGIES]
    return [
        Cell(column_scenario, strategy, seed, label, fold=fold)
        for column_scenario, strategy, label in columns
        for seed in range(seeds if seed_matters(column_scenario, strategy) else 1)
    ]


def shared_views_key(cell: Cell) -> tuple:
    """A key that the cells of a recording table which look at mostly the same views share (for
    ``run_cells``' ``together``): the information-gain strategies of one fold and beta, whose runs differ
    only in their seed (smpl's Monte Carlo samples) or in how the same objective is computed (intg), so
    that most of their steps choose the same action as each other. Every other cell has a key of its own.
    """
    if cell.strategy in INFORMATION_STRATEGIES:
        return (cell.fold, cell.scenario.control.beta)
    return (cell.fold, cell.column, cell.seed)


def cell_policy(cell: Cell) -> PolicySpec:
    """The policy spec a cell runs: its registered name, or a fresh copy of its object."""
    if isinstance(cell.strategy, str):
        return POLICY_OF_STRATEGY.get(cell.strategy, cell.strategy)
    return copy.deepcopy(cell.strategy)


def run_cell(cell: Cell) -> dict:
    """Run one cell; returns its metrics with ``strategy``, ``label``, ``beta`` (None for baselines) and ``seed``."""
    episode = run_episode(cell.scenario, cell_policy(cell), cell.seed, camera=cell.camera, detector=cell.detector)
    beta = cell.scenario.control.beta if cell.strategy in INFORMATION_STRATEGIES else None
    name = strategy_name(cell.strategy)
    fold = {} if cell.fold is None else {"fold": cell.fold}
    return {"strategy": name, "label": cell.column, "beta": beta, "seed": cell.seed, **fold, **episode_metrics(episode)}


def scene_statistics(scenario: Scenario, sequences: int) -> dict:
    """What a fixed camera sees of a synthetic scene, as the paper describes its own (section 5.1).

    Over the experiment's sequences (seeds 0..n-1), with the 'fix' pose and the ideal detector:
    ``instances`` and ``detected`` (per sequence), ``detected_fraction``, ``height_px`` (mean over the
    detections), and the expected losses as fractions of the instances: ``out_of_view_fraction``
    (head or feet outside the image) and ``hidden_fraction`` (the hidden fractions of those in view,
    which the ideal detector misses in proportion). The paper: 278.3 of 350, at 49.1 px."""
    ideal = scenario.model_copy(update={"detector": scenario.detector.model_copy(update={"kind": "ideal"})})
    instances = detections = height_sum_px = out_of_view = hidden = 0.0
    for seed in range(sequences):
        episode = run_episode(ideal, "fix", seed)
        world = build_world(ideal, np.random.default_rng(episode_seeds(seed)[0]))
        present = world.truth.present
        instances += present.sum()
        detections += sum(len(found) for found in episode.detections)
        height_sum_px += sum(found.height_px.sum() for found in episode.detections)
        for step, pose in enumerate(episode.poses):
            people = world.backend.people(step, pose)
            if people is None:
                raise ValueError("scene statistics need a simulated camera, which knows who is in view")
            out_of_view += (~people.in_view & present[step]).sum()
            hidden += people.hidden[people.in_view].sum()
    return {
        "sequences": sequences,
        "instances": float(instances / sequences),
        "detected": float(detections / sequences),
        "detected_fraction": float(detections / instances),
        "height_px": float(height_sum_px / detections),
        "out_of_view_fraction": float(out_of_view / instances),
        "hidden_fraction": float(hidden / instances),
    }


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
