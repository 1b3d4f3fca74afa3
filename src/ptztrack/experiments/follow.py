"""The robot-cameraman paper's follow experiment: every person followed by every tracker in the closed
loop, and the trackers alone on the still recording (the OTB one-pass protocol); per tracker, the
means over the people of their figures, and the tables.

Each cell is a function of its inputs (the seed fixes the particle filter's
draws), so every executor gives the same rows; but not MIL's: OpenCV's MIL
tracker gives other boxes on the same frames from run to run (also with
``cv2.setRNGSeed`` and one thread), CSRT the same.
"""

import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np

from ptztrack.builders.episode import episode_world, make_policy, run_episode
from ptztrack.builders.follow import framing_parameters, refuse_unknown_people, target_scenario, target_source
from ptztrack.builders.recording import recorded_size_px
from ptztrack.camera.recorded import RecordedPTZ
from ptztrack.config import Scenario, ScenarioError
from ptztrack.follow.evaluation import follow_metrics, one_pass_scores, target_in_views
from ptztrack.geometry.calibration import load_calibration, standing_height_px
from ptztrack.loop.steps import Episode, StepObserver, World
from ptztrack.loop.streams import episode_streams
from ptztrack.names import OTB_TRACKS
from ptztrack.roles import Policy
from ptztrack.scene.pets import Annotations, RecordedVideo, load_mot_ground_truth

# The tables' rows: the closed loop's figures (follow_metrics', with follow_row's ground error and zoom),
# and the one-pass scores with the tracker's frames per second.
FOLLOW_FIGURES = (
    "in_view_fraction",
    "target_point_error",
    "losses",
    "recoveries",
    "lost_steps",
    "jitter_deg",
    "height_sd_ratio",
    "ground_error_m",
    "zoom",
)
OTB_FIGURES = ("success_auc", "precision_20px", "fps")


@dataclass(frozen=True)
class FollowCell:
    """One person (``target_id``) followed by one tracker ('particle', 'csrt', 'mil') in ``scenario``
    (a follow scenario, :func:`ptztrack.builders.recording.pets_follow_scenario`); ``seed`` fixes the run's draws."""

    scenario: Scenario
    tracker: str
    target_id: int
    seed: int = 0


def annotated_people(scenario: Scenario) -> np.ndarray:
    """The ids of the recording's annotated people, longest annotated first (ties by id)."""
    annotations = load_mot_ground_truth(scenario.required_recording("the follow experiment").ground_truth)
    ids, frames = np.unique(annotations.person_id, return_counts=True)
    return ids[np.lexsort((ids, -frames))]


def follow_cells(scenario: Scenario, trackers, targets=None, seed: int = 0) -> list[FollowCell]:
    """Every tracker on every person (all annotated people by default, by id); a person the recording
    does not annotate is refused before any runs."""
    annotated = annotated_people(scenario)
    if targets is not None:
        refuse_unknown_people(scenario.required_recording("the follow experiment").ground_truth, annotated, targets)
    people = sorted(annotated.tolist()) if targets is None else list(targets)
    return [FollowCell(scenario, tracker, int(person), seed) for tracker in trackers for person in people]


def follow_run(
    cell: FollowCell, observe: Callable[[World, Policy], StepObserver | None] | None = None
) -> tuple[Scenario, World, Episode]:
    """The cell's scenario narrowed to its person, its world and its episode.

    observe : ``observe(world, policy)`` gives the run's step observer (a live view, say).
    """
    scenario = target_scenario(cell.scenario.model_copy(update={"tracker": _tracker(cell)}), cell.target_id)
    world = episode_world(scenario, cell.seed)
    policy = make_policy("follow", scenario, world)
    observer = None if observe is None else observe(world, policy)
    return scenario, world, run_episode(scenario, policy, cell.seed, world, observer=observer)


def _tracker(cell: FollowCell):
    return cell.scenario.tracker.model_copy(update={"kind": cell.tracker})


def target_boxes(world: World, target_id: int) -> np.ndarray:
    """(T, 4) the person's annotated box (left, top, width, height) at every step, NaN where not annotated."""
    backend = world.backend
    assert isinstance(backend, RecordedPTZ)
    scene = backend.scene
    return _boxes_by_frame(scene.annotations, target_id, scene.video_frame)


def _boxes_by_frame(annotations: Annotations, target_id: int, frames) -> np.ndarray:
    boxes = np.full((len(frames), 4), np.nan)
    mine = annotations.select(annotations.person_id == target_id)
    step = np.searchsorted(frames, mine.frame)
    found = (step < len(frames)) & (frames[np.minimum(step, len(frames) - 1)] == mine.frame)
    boxes[step[found]] = mine.box_px[found]
    return boxes


def follow_row(scenario: Scenario, world: World, episode: Episode) -> dict:
    """The figures of one followed person (:func:`ptztrack.follow.evaluation.follow_metrics`) and the
    mean ground distance of the track from the person while the tracker was not lost (``ground_error_m``)."""
    target_id = scenario.follow.target_id
    assert target_id is not None
    backend = world.backend
    assert isinstance(backend, RecordedPTZ)
    centres_px, heights_px = target_in_views(backend.virtual, target_boxes(world, target_id), episode.poses)
    lost = np.array([tracks.existence[0] == 0 for tracks in episode.tracks])
    camera = world.camera
    target_point_px = framing_parameters(scenario, camera).target_point_px
    metrics = follow_metrics(
        centres_px,
        heights_px,
        episode.commanded,
        lost,
        (camera.image_width_px, camera.image_height_px),
        target_point_px,
    )
    column = int(np.searchsorted(backend.scene.person_id, target_id))
    truth_m = episode.truth.positions_m[:, column]
    tracked_m = np.array([tracks.mean[0, :2] for tracks in episode.tracks])
    seen = ~lost & np.isfinite(truth_m[:, 0])
    ground_error_m = float(np.linalg.norm(tracked_m[seen] - truth_m[seen], axis=1).mean()) if seen.any() else np.nan
    return {
        "tracker": scenario.tracker.kind,
        "target_id": target_id,
        "steps": len(episode.poses),
        **metrics,
        "ground_error_m": ground_error_m,
        "zoom": float(episode.poses[:, 2].mean()),
    }


def run_follow_cell(cell: FollowCell) -> dict:
    """Run one person with one tracker in the closed loop; its figures (:func:`follow_row`)."""
    return follow_row(*follow_run(cell))


@dataclass(frozen=True)
class OnePassCell:
    """One tracker on one person's frames of the still recording (the OTB one-pass protocol)."""

    scenario: Scenario
    tracker: str
    target_id: int
    seed: int = 0


def otb_cells(scenario: Scenario, trackers, tracks: int = OTB_TRACKS, seed: int = 0) -> list[OnePassCell]:
    """Every tracker on the ``tracks`` longest annotated people (from 1 to all of them)."""
    people = annotated_people(scenario)
    if not 1 <= tracks <= len(people):
        ground_truth = scenario.required_recording("the one-pass benchmark").ground_truth
        raise ScenarioError(
            f"--otb-tracks {tracks}: expected 1 to {len(people)}, as {ground_truth} annotates {len(people)} people"
        )
    return [OnePassCell(scenario, tracker, int(person), seed) for tracker in trackers for person in people[:tracks]]


def run_otb_cell(cell: OnePassCell) -> dict:
    """One tracker over the recorded frames of one person, from their first annotated box to their last
    annotated frame, the camera still; scores over the annotated frames (the first included) and the
    frames per second of the tracker's own updates (decoding not counted)."""
    recording = cell.scenario.required_recording("the one-pass benchmark")
    annotations = load_mot_ground_truth(recording.ground_truth)
    mine = annotations.frame[annotations.person_id == cell.target_id]
    frames = np.arange(mine.min(), mine.max() + 1)
    boxes = _boxes_by_frame(annotations, cell.target_id, frames)
    video = RecordedVideo(
        cell.scenario.required_video("the one-pass benchmark"),
        recorded_size_px(recording),
        int(frames[-1]) + 1,
    )
    rng = np.random.default_rng(episode_streams(cell.seed).tracker)
    source = target_source(cell.scenario, cell.tracker, rng)
    still = np.eye(3)
    calibration = load_calibration(recording.calibration, recording.view)
    standing = partial(standing_height_px, calibration, height_m=cell.scenario.control.person_height_m)
    tracked = np.zeros((len(frames), 4))
    elapsed_s = 0.0
    for index, frame in enumerate(frames):
        image = video.frame(int(frame))
        started = time.perf_counter()
        estimate = source.start(image, boxes[0]) if index == 0 else source.step(image, still, standing)
        elapsed_s += time.perf_counter() - started
        tracked[index] = estimate.box_px
    annotated = np.all(np.isfinite(boxes), axis=1)
    scores = one_pass_scores(tracked[annotated], boxes[annotated])
    return {"tracker": cell.tracker, "target_id": cell.target_id, **scores, "fps": len(frames) / elapsed_s}


def summarise_follow(rows: list[dict], figures) -> list[dict]:
    """One row per tracker (in the order they first appear): the mean over people of each figure (of those
    where it is defined: a person never tracked has no ground error), and ``people``."""
    trackers = list(dict.fromkeys(row["tracker"] for row in rows))
    summary = []
    for tracker in trackers:
        mine = [row for row in rows if row["tracker"] == tracker]
        means = {name: _mean([row[name] for row in mine]) for name in figures}
        summary.append({"tracker": tracker, **means, "people": len(mine)})
    return summary


def _mean(values) -> float:
    values = np.asarray(values, dtype=float)
    return float(np.mean(values[np.isfinite(values)])) if np.isfinite(values).any() else float("nan")


def format_follow_table(summary: list[dict], figures, title: str = "") -> str:
    """A plain-text table: one column per tracker, one row per figure."""
    width = max(len(name) for name in figures) + 2
    lines = [title] if title else []
    lines.append(" " * width + "".join(f"{row['tracker']:>12}" for row in summary))
    for figure in figures:
        lines.append(f"{figure:<{width}}" + "".join(f"{row[figure]:>12.3f}" for row in summary))
    return "\n".join(lines)


def format_follow_people(rows: list[dict]) -> str:
    """One line per person: steps, then per tracker the in-view fraction, the target point error and the
    losses declared / recoveries."""
    trackers = list(dict.fromkeys(row["tracker"] for row in rows))
    by_person: dict[int, dict] = {}
    for row in rows:
        by_person.setdefault(row["target_id"], {})[row["tracker"]] = row
    header = "person  steps" + "".join(f"   {name + ': in view, TPE, losses/rec.':<32}" for name in trackers)
    lines = [header]
    for person, mine in sorted(by_person.items()):
        steps = next(iter(mine.values()))["steps"]
        cells = []
        for name in trackers:
            found = mine.get(name)
            cell = ""
            if found is not None:
                losses = f"{found['losses']:3d}/{found['recoveries']}"
                cell = f"{found['in_view_fraction']:6.1%}  {found['target_point_error']:.3f}  {losses}"
            cells.append(f"   {cell:<32}")
        lines.append(f"{person:>6}  {steps:>5}" + "".join(cells))
    return "\n".join(lines)


def summarise_follow_experiment(people: list[dict], otb_people: list[dict]) -> dict:
    """The experiment's figures: per tracker the means over the people of the closed loop's
    (``closed_loop``, of ``people``: :func:`run_follow_cell`'s rows) and of the one-pass scores
    (``otb``, of ``otb_people``: :func:`run_otb_cell`'s rows), and those rows (``people``, ``otb_people``)."""
    closed_loop, otb = summarise_follow(people, FOLLOW_FIGURES), summarise_follow(otb_people, OTB_FIGURES)
    return {"closed_loop": closed_loop, "otb": otb, "people": people, "otb_people": otb_people}


def format_follow_experiment(scenario: Scenario, summary: dict, trackers) -> str:
    """The experiment's tables (``summary``: :func:`summarise_follow_experiment`'s, of ``trackers`` in
    ``scenario``): a line per person, the closed loop's means over the people, and the one-pass scores."""
    people, otb_people = summary["people"], summary["otb_people"]
    tracks = ", ".join(str(row["target_id"]) for row in otb_people[: len(otb_people) // len(trackers)])
    return "\n".join(
        [
            f"Follow camera, {scenario.camera.image_size_px[0]} x {scenario.camera.image_size_px[1]} view, "
            f"person {scenario.follow.target_height_px:g} px tall wanted; per person:",
            format_follow_people(people),
            format_follow_table(summary["closed_loop"], FOLLOW_FIGURES, "\nMeans over the people:"),
            format_follow_table(
                summary["otb"], OTB_FIGURES, f"\nOne-pass (OTB) on the still recording, people {tracks}:"
            ),
        ]
    )
