"""The PTZ paper's Tables 1-4: its strategies on the synthetic scene and on a recording (PETS 2009 S2.L1
built in, any dataset file's view).

The cells are (scenario, strategy, seed), one episode each (:class:`~ptztrack.experiments.cells.Cell`);
a table is, per column (a strategy, with its beta where the table has several), the mean over its runs
of the paper's figures (MOTA, MOTP in m, height in px, detections, zoom).

The recording tables' protocols (the paper's section 5.2), nothing learnt from the frames a table scores:

* ``a-priori``: every parameter as fixed before looking at the recording: the
  scenario's defaults, the paper's Caltech recall curve (Kd 0.0098, r0
  21.29 px) for the policies' model of HOG, and the walkable area from the
  calibrated view (:func:`ptztrack.builders.world.visible_ground_m`).
* ``two-fold``: the recording split in two halves by time; the detector's
  model is fitted on one half and the table scored on the other, then the
  other way round. Fitted on the training half: the detector's pixel noise
  (the spread of its feet around the pixel of each person's true ground
  point), for a detector with a recall curve its Kd and r0 by maximum
  likelihood (:mod:`ptztrack.detect.recall_fit`), and people's width (the
  annotated boxes' median width / height, at the policies' person height).
  Everything else stays a priori.
"""

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ptztrack import registry
from ptztrack.builders.budget import refuse_if_too_large
from ptztrack.builders.episode import PolicySpec, run_episode
from ptztrack.builders.world import CameraSpec, DetectorSpec, build_world
from ptztrack.config import Scenario, scenario_from_dict
from ptztrack.detect.recall_fit import detection_trials, fit_recall
from ptztrack.evaluate.metrics import DISPLAY, standard_error
from ptztrack.experiments.cells import INFORMATION_STRATEGIES, Cell, Execution, cell_metrics, run_experiment_cells
from ptztrack.loop.steps import Episode
from ptztrack.loop.streams import episode_streams
from ptztrack.names import KEPT_DETECTOR_MODELS, PROTOCOLS, PetsProtocol, SyntheticProtocol
from ptztrack.scene.pets import load_mot_ground_truth

# The strategies that draw from their random stream (the others are deterministic given the detections).
RANDOM_STRATEGIES = ("rnd", "smpl")
# The detectors that find the same people in the same view: OpenCV's HOG, a recording's precomputed boxes.
DETERMINISTIC_DETECTORS = ("hog", "detections")
# The paper's rows.
SUMMARY_KEYS = ("mota", "motp_m", "height_px", "detections", "zoom")


def _checked_strategies(strategies: Sequence[PolicySpec]) -> list[PolicySpec]:
    """The strategies with their current names (a former name: with a warning line); raises naming any
    unknown one."""
    current = [registry.current_name("policies", s) if isinstance(s, str) else s for s in strategies]
    known = registry.names("policies")
    unknown = sorted(s for s in current if isinstance(s, str) and s not in known)
    if unknown:
        raise ValueError(f"unknown strategies {unknown}; expected some of {', '.join(sorted(known))}")
    return current


def synthetic_cells(
    scenario: Scenario,
    sequences: int = SyntheticProtocol.sequences,
    strategies: Sequence[PolicySpec] = SyntheticProtocol.strategies,
    camera: CameraSpec | None = None,
    detector: DetectorSpec | None = None,
) -> list[Cell]:
    """The paper's synthetic protocol: every strategy on the same ``sequences`` sequences (seeds 0..n-1)."""
    strategies = _checked_strategies(strategies)
    return [
        Cell(scenario, strategy, seed, camera=camera, detector=detector)
        for strategy in strategies
        for seed in range(sequences)
    ]


def seed_matters(scenario: Scenario, strategy: PolicySpec) -> bool:
    """Whether a run of ``strategy`` depends on its seed: a strategy that draws, a detector that does
    (every one but :data:`DETERMINISTIC_DETECTORS`, which find the same people in the same view), or an information-gain
    strategy planning with draws of a detector model it learns."""
    learning = scenario.detector.model not in KEPT_DETECTOR_MODELS and scenario.detector.kind != "ideal"
    return (
        strategy in RANDOM_STRATEGIES
        or scenario.detector.kind not in DETERMINISTIC_DETECTORS
        or (strategy in INFORMATION_STRATEGIES and learning)
    )


def recording_cells(
    scenario: Scenario,
    betas: Sequence[float] = PetsProtocol.betas,
    strategies: Sequence[PolicySpec] = PetsProtocol.strategies,
    seeds: int = 1,
    fold: int | None = None,
) -> list[Cell]:
    """The paper's realistic protocol (section 5.2): each strategy over the recording, the
    information-gain ones once per ``beta`` of the patrolling term; with seeds 0..``seeds``-1 where the
    run depends on its seed (:func:`seed_matters`), else once."""
    strategies = _checked_strategies(strategies)
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
    ``execute_cells``' ``together``): the information-gain strategies of one fold and beta, whose runs differ
    only in their seed (smpl's Monte Carlo samples) or in how the same objective is computed (intg), so
    that most of their steps choose the same action as each other. Every other cell has a key of its own.
    """
    if cell.strategy in INFORMATION_STRATEGIES:
        return (cell.fold, cell.scenario.control.beta)
    return (cell.fold, cell.column, cell.seed)


# The fit looks at every 20th step of the training half, at every zoom of the grid's views within 2 pan
# and 1 tilt steps of the whole-frame view (people are fully visible there, at every size the policies
# meet).
FIT_EVERY_STEPS = 20
FIT_POSE_SPAN = (2, 1)


@dataclass(frozen=True)
class Fold:
    """One scoring of a table: the scenario it runs and what was fitted for it.

    index : the fold (None under the a-priori protocol); scenario : restricted to the frames scored;
    fitted : {field: value} fitted on the other frames (empty a priori): the detector's
    ``pixel_noise_px``, ``recall_kd``, ``recall_r0_px`` and the people's ``width_m``.
    """

    index: int | None
    scenario: Scenario
    fitted: dict


def halves(scenario: Scenario) -> tuple[tuple[int, int], tuple[int, int]]:
    """The recording's annotated frames cut in two by time, [first, stop) each, both starting on a
    frame the experiment steps through."""
    recording = scenario.required_recording("the two-fold protocol")
    stop = int(load_mot_ground_truth(recording.ground_truth).frame.max()) + 1
    middle = recording.frame_step * math.ceil(stop / 2 / recording.frame_step)
    return (0, middle), (middle, stop)


PEOPLE_FIELDS = ("width_m",)


def with_frames(scenario: Scenario, frame_range: tuple[int, int], fields: dict) -> Scenario:
    """The scenario on the frames ``frame_range``, with ``fields`` of the detector and the people set;
    validated like a scenario file, so that a fitted value out of its field's range is refused."""
    overrides = {f"{'people' if name in PEOPLE_FIELDS else 'detector'}.{name}": value for name, value in fields.items()}
    return scenario_from_dict(scenario.model_dump(), "fold", **{"recording.frame_range": frame_range, **overrides})


def fit_detector(scenario: Scenario, frame_range: tuple[int, int]) -> dict:
    """The models fitted on the frames ``frame_range`` of the recording: ``pixel_noise_px``, for a
    detector other than the ideal one ``recall_kd`` and ``recall_r0_px``, and ``width_m``."""
    noiseless = with_frames(scenario, frame_range, {"pixel_noise_px": 0.0})
    world = build_world(noiseless, np.random.default_rng(0))
    grid = world.grid
    centre = grid.axis_indices[world.start_action, :2]
    near = np.all(np.abs(grid.axis_indices[:, :2] - centre) <= FIT_POSE_SPAN, axis=1)
    steps = range(0, world.truth.positions_m.shape[0], FIT_EVERY_STEPS)
    occluded_above = scenario.required_recording("fitting a detector").occluded_above
    trials = detection_trials(
        world.backend, world.detector, world.camera, world.truth, grid.poses[near], steps, occluded_above
    )
    boxes_px = annotated_boxes_px(noiseless)
    width_m = float(np.median(boxes_px[:, 2] / boxes_px[:, 3])) * scenario.control.person_height_m
    fitted = {"pixel_noise_px": trials.pixel_noise_px, "width_m": width_m}
    if scenario.detector.kind != "ideal":
        fitted["recall_kd"], fitted["recall_r0_px"] = fit_recall(trials.height_px, trials.detected)
    return fitted


def annotated_boxes_px(scenario: Scenario) -> np.ndarray:
    """The annotated boxes (K, 4) (left, top, width, height) px of the scenario's frames."""
    recording = scenario.required_recording("the annotations")
    annotations = load_mot_ground_truth(recording.ground_truth)
    first, stop = recording.frame_range or (0, int(annotations.frame.max()) + 1)
    return annotations.box_px[(annotations.frame >= first) & (annotations.frame < stop)]


def protocol_folds(scenario: Scenario, protocol: str) -> list[Fold]:
    """The scorings of a PETS table under ``protocol`` (see the module's docstring)."""
    if protocol == "a-priori":
        return [Fold(None, scenario, {})]
    if protocol != "two-fold":
        raise ValueError(f"unknown protocol {protocol!r}; expected one of {', '.join(PROTOCOLS)}")
    first, second = halves(scenario)
    folds = []
    for index, (fitted_on, scored) in enumerate(((first, second), (second, first))):
        fitted = fit_detector(scenario, fitted_on)
        folds.append(Fold(index, with_frames(scenario, scored, fitted), fitted))
    return folds


def run_table(cells: list[Cell], strategies: Sequence[str], execution: Execution, together=None) -> list[dict]:
    """The cells run on ``execution`` and summarised (:func:`summarise`); refused before any work when
    the runs it holds at once would not fit in the memory available, estimated for the worst of the
    ``strategies`` (names). ``together`` as :func:`ptztrack.loop.executors.execute_cells`' (for a
    PETS table, :func:`shared_views_key`)."""
    runs_at_once = 1 if execution.executor == "serial" else min(len(cells), execution.workers or os.cpu_count() or 1)
    refuse_if_too_large(cells[0].scenario, tuple(strategies), runs_at_once)
    return summarise(run_experiment_cells(cells, cell_metrics, execution, together=together))


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


def format_report(summary: Sequence[dict], title: str = "", spread: str = "mota_se") -> str:
    """The table (:func:`format_table`) and, where smpl and intg both ran on several sequences, their
    paired MOTA difference (:func:`paired_difference`) in points."""
    lines = [format_table(summary, title, spread)]
    labels = {row["label"] for row in summary}
    if {"smpl", "intg"} <= labels and summary[0]["sequences"] > 1:
        mean, error, count = paired_difference(summary, "smpl", "intg")
        paired = f"paired over {count} sequences, standard error"
        lines.append(f"smpl - intg: {100 * mean:+.1f} +- {100 * error:.1f} MOTA points ({paired})")
    return "\n".join(lines)


def synthetic_title(scenario_name: str, scenario: Scenario, sequences: int) -> str:
    """The title of a synthetic table: the scene named ``scenario_name``, its detector and model, beta
    and the ``sequences`` run."""
    return (
        f"{scenario_name} scene, {scenario.detector.kind} detector, beta {scenario.control.beta:g}, "
        f"detector model {scenario.detector.model} (prior shifted {scenario.detector.prior_shift_px:g} px), "
        f"{sequences} sequences of {scenario.frames} frames (means over sequences)"
    )


def recording_title(scenario: Scenario, protocol: str, seeds: int) -> str:
    """The title of a recording's table under ``protocol``, with ``seeds`` runs where a run depends on its seed."""
    recording = scenario.required_recording("a recording's table")
    every = "every frame" if recording.frame_step == 1 else f"a step every {recording.frame_step} frames"
    return (
        f"{recording.name}, {scenario.detector.kind} detector ({scenario.detector.model} model), {every} "
        f"({scenario.frame_rate_hz:.4g} Hz steps), protocol {protocol}, "
        f"{seeds} seeds where a run depends on its seed (MOTA +- standard deviation over seeds and folds)"
    )


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
        assert isinstance(episode, Episode), "the table's scenario has one camera"
        world = build_world(ideal, np.random.default_rng(episode_streams(seed).scene))
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
