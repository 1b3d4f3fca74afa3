"""Recorded people replayed as the synthetic crowd: a file of world positions in metres, interpolated
to the step rate.

Two formats are read, told apart by the first line that is not blank:

* MOTChallenge rows with world positions in metres (ten comma-separated numbers,
  ``frame,id,left,top,width,height,conf,x_m,y_m,z``, frames from 1), as recordings' ground truth
  (:func:`ptztrack.scene.pets.load_mot_ground_truth`); only the frame, the id and columns 8-9 are used;
* four numbers a line, ``frame id x y`` (x and y in metres), separated by whitespace or commas, as
  the public pedestrian-trajectory sets (ETH, UCY) give them; frames from 0 or 1, numbered at any
  pace (ETH's and UCY's frame numbers step by 10).

Neither format says its frame rate: the caller gives the frames per second of the file's frame
numbers, and a sample of frame ``f`` is at ``(f - f0) / frame_rate_hz`` seconds, ``f0`` the file's
first frame; the replay's step 0 is that frame. Any problem gets a :class:`DatasetError` naming the
file, the line and the value; the checks that only warn return their one line.
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ptztrack.files import read_text
from ptztrack.scene.pets import (
    GROUND_TRUTH_MAX_BYTES,
    MOT_COLUMNS,
    DatasetError,
    number_rows,
    refuse_repeated_annotations,
)
from ptztrack.types import GroundTruth

MAX_SPREAD_M = 10_000.0
"""How far a position may lie from the file's median position, in metres: ten times the longest side a
scenario's area may have (1000 m), so that any scene a scenario can hold passes, while a coordinate
in millimetres of a scene wider than 10 m, or a pixel-like 1e6, does not (positions in pixels of a
video are smaller: :func:`trajectories_outside_area` and :func:`trajectories_too_fast` tell those)."""
MAX_GAP_S = 2.0
"""A person unseen for longer than this, in seconds, is absent in between (has left and come back, or
was lost by the annotator) rather than interpolated across: two seconds of walking is about 3 m, past
which a straight line is a guess."""
OUTSIDE_MARGIN_M = 1.0
"""How far outside the area, in metres, a position may lie before :func:`trajectories_outside_area`
warns: a person's width and a step of slack, as people brush past an area's edge."""
MAX_SPEED_M_S = 15.0
"""The median speed between consecutive samples, in metres per second, above which the positions or the
frame rate are taken to be wrong: faster than anyone runs (the scenario's bound on walking speeds)."""
MAX_PEOPLE = 1000
"""The most people a replay may hold, as the synthetic crowd's ``count``: the simulated camera measures
each person's occlusion in a view centred on every other, N^2 a step."""


@dataclass(frozen=True)
class Trajectories:
    """People's positions on the ground, one row per person and sample, as read from ``path``.

    frame : (K,) int, the sample's frame counted from the file's first frame (0);
    person_id : (K,) int; position_m : (K, 2) metres, as in the file;
    line : (K,) each row's line in the file; frame_rate_hz : frames per second of ``frame``.
    """

    path: Path
    frame: np.ndarray
    person_id: np.ndarray
    position_m: np.ndarray
    line: np.ndarray
    frame_rate_hz: float

    @property
    def people(self) -> np.ndarray:
        """(P,) the ids of the file's people, increasing."""
        return np.unique(self.person_id)

    @property
    def time_s(self) -> np.ndarray:
        """(K,) each sample's time from the file's first frame, in seconds."""
        return self.frame / self.frame_rate_hz


def read_trajectories(path: str | Path, frame_rate_hz: float) -> Trajectories:
    """Read a file of people's positions in metres (see the module's docstring for the formats).

    Parameters
    ----------
    path : the file (``.gz`` compressed or not), at most 200 MB.
    frame_rate_hz : frames per second of the file's frame numbers (neither format says it).

    Returns
    -------
    Trajectories
        Every row, frames counted from the file's first.

    Raises
    ------
    DatasetError
        One line naming the file, and the line and value where there is one: an empty or too large
        file, a line of another number of fields, a field that is not a finite number, a frame or id
        that is not whole, a frame below 1 (MOTChallenge) or 0, a person twice in a frame, or a
        position farther than ``MAX_SPREAD_M`` from the file's median position.
    """
    path = Path(path)
    text = read_text(path, "trajectory", GROUND_TRUTH_MAX_BYTES, DatasetError)
    first = next((line for line in text.splitlines() if line.strip()), "")
    if len(first.split(",")) == MOT_COLUMNS:
        table, line = number_rows(path, text, "trajectory", MOT_COLUMNS, 1, "in MOTChallenge files")
        position_m = table[:, 7:9]
    else:
        layout = " (frame id x y, or 10 comma-separated: MOTChallenge)"
        table, line = number_rows(path, text, "trajectory", 4, 0, "in frame id x y files", r"[\s,]+", layout)
        position_m = table[:, 2:4]
    frame, person_id = table[:, 0].astype(np.int64), table[:, 1].astype(np.int64)
    refuse_repeated_annotations(path, frame, person_id, line)
    _refuse_far_positions(path, position_m, line)
    return Trajectories(path, frame - frame.min(), person_id, position_m, line, frame_rate_hz)


def _refuse_far_positions(path: Path, position_m: np.ndarray, line: np.ndarray) -> None:
    """A :class:`DatasetError` naming the farthest position (K, 2) from the median if beyond ``MAX_SPREAD_M``."""
    median_m = np.median(position_m, axis=0)
    distance_m = np.linalg.norm(position_m - median_m, axis=1)
    farthest = int(np.argmax(distance_m))
    if distance_m[farthest] > MAX_SPREAD_M:
        x_m, y_m = position_m[farthest]
        raise DatasetError(
            f"{path}: line {line[farthest]}: position ({x_m:g}, {y_m:g}) lies {distance_m[farthest]:.3g} m from "
            f"the file's median position ({median_m[0]:g}, {median_m[1]:g}), beyond {MAX_SPREAD_M:g} m: "
            "expected metres (not pixels or millimetres)"
        )


def centring_offset_m(trajectories: Trajectories, area_m) -> np.ndarray:
    """The translation (2,) m that puts the centre of the bounding box of every position of the file at
    the centre of the area [0, W] x [0, H], ``area_m`` = (W, H) metres."""
    low, high = trajectories.position_m.min(axis=0), trajectories.position_m.max(axis=0)
    return np.asarray(area_m, dtype=float) / 2 - (low + high) / 2


def trajectories_outside_area(
    trajectories: Trajectories, offset_m, area_m, margin_m: float = OUTSIDE_MARGIN_M
) -> str | None:
    """Check the file's positions, moved by ``offset_m`` (2,) m, against the area [0, W] x [0, H],
    ``area_m`` = (W, H) metres.

    Returns
    -------
    str or None
        A warning line if some positions lie more than ``margin_m`` outside the area, else None.

    Raises
    ------
    DatasetError
        If none of them lies in the area.
    """
    area = np.asarray(area_m, dtype=float)
    moved_m = trajectories.position_m + np.asarray(offset_m, dtype=float)
    inside = np.all((moved_m >= 0) & (moved_m <= area), axis=1)
    outside = np.any((moved_m < -margin_m) | (moved_m > area + margin_m), axis=1)
    where = f"area_m [0, {area[0]:g}] x [0, {area[1]:g}] once moved by ({offset_m[0]:g}, {offset_m[1]:g}) m"
    if not inside.any():
        x_m, y_m = trajectories.position_m[0]
        raise DatasetError(
            f"{trajectories.path}: none of its {len(moved_m)} positions lies in {where} (line "
            f"{trajectories.line[0]}: ({x_m:g}, {y_m:g})): expected metres of ground the area can hold"
        )
    if not outside.any():
        return None
    first = int(np.argmax(outside))
    x_m, y_m = trajectories.position_m[first]
    return (
        f"{trajectories.path}: {outside.sum()} of {len(moved_m)} positions lie more than {margin_m:g} m outside "
        f"{where} (the first, line {trajectories.line[first]}: ({x_m:g}, {y_m:g}))"
    )


def trajectories_too_fast(trajectories: Trajectories, max_gap_s: float = MAX_GAP_S) -> str | None:
    """A warning line if the people move a median speed above ``MAX_SPEED_M_S`` between consecutive
    samples (at most ``max_gap_s`` apart): the positions are not metres, or the frame rate is too high;
    else None."""
    order = np.lexsort((trajectories.frame, trajectories.person_id))
    same = trajectories.person_id[order][1:] == trajectories.person_id[order][:-1]
    step_s = np.diff(trajectories.time_s[order])
    consecutive = same & (step_s <= max_gap_s)
    if not consecutive.any():
        return None
    moved_m = np.linalg.norm(np.diff(trajectories.position_m[order], axis=0), axis=1)
    speed = float(np.median(moved_m[consecutive] / step_s[consecutive]))
    if speed <= MAX_SPEED_M_S:
        return None
    return (
        f"{trajectories.path}: its people move a median {speed:.3g} m/s at {trajectories.frame_rate_hz:g} frames "
        f"per second, faster than anyone runs ({MAX_SPEED_M_S:g} m/s): are the positions metres and the "
        "frame rate right?"
    )


def replay_truth(
    trajectories: Trajectories,
    frames: int,
    step_rate_hz: float,
    heights_m,
    width_m: float,
    offset_m,
    max_gap_s: float = MAX_GAP_S,
) -> GroundTruth:
    """The people of ``trajectories`` at ``frames`` steps of ``step_rate_hz``, as the synthetic scene's truth.

    Step k is at k / ``step_rate_hz`` seconds from the file's first frame. Each person is linearly
    interpolated between their samples; a step exactly at a sample gets the sample itself. A person
    is absent (NaN) before their first sample, after their last, and strictly between two samples
    more than ``max_gap_s`` apart.

    Parameters
    ----------
    trajectories : the file's people (:func:`read_trajectories`).
    frames : steps.
    step_rate_hz : steps per second.
    heights_m : (P,) metres, one per person of ``trajectories.people``.
    width_m : everybody's width, metres.
    offset_m : (2,) metres added to every position.
    max_gap_s : seconds.

    Returns
    -------
    GroundTruth
        positions_m (frames, N, 2) for the N people present at one step at least, in increasing id
        order; their heights_m (N,), widths_m (N,) and frame_rate_hz ``step_rate_hz``.

    Raises
    ------
    DatasetError
        If more than ``MAX_PEOPLE`` people are present during the steps.
    """
    step_s = np.arange(frames) / step_rate_hz
    people, column = np.unique(trajectories.person_id, return_inverse=True)
    order = np.lexsort((trajectories.frame, column))
    time_s, position_m = trajectories.time_s[order], trajectories.position_m[order]
    bounds = np.searchsorted(column[order], np.arange(len(people) + 1))
    first_s, last_s = time_s[bounds[:-1]], time_s[bounds[1:] - 1]
    during = np.flatnonzero((last_s >= step_s[0]) & (first_s <= step_s[-1]))
    if len(during) > MAX_PEOPLE:
        raise DatasetError(
            f"{trajectories.path}: {len(during)} people during the run's {frames} steps, more than the "
            f"{MAX_PEOPLE} a scene may hold (time: the simulated camera measures every pair)"
        )
    positions_m = np.full((frames, len(during), 2), np.nan)
    for index, person in enumerate(during):
        samples = slice(bounds[person], bounds[person + 1])
        positions_m[:, index] = _interpolated(time_s[samples], position_m[samples], step_s, max_gap_s)
    present = ~np.isnan(positions_m[..., 0]).all(axis=0)
    return GroundTruth(
        positions_m=positions_m[:, present] + np.asarray(offset_m, dtype=float),
        heights_m=np.asarray(heights_m, dtype=float)[during[present]],
        widths_m=np.full(int(present.sum()), float(width_m)),
        frame_rate_hz=step_rate_hz,
    )


def _interpolated(time_s: np.ndarray, position_m: np.ndarray, at_s: np.ndarray, max_gap_s: float) -> np.ndarray:
    """One person's positions (T, 2) at ``at_s`` (T,), from samples (S, 2) at increasing ``time_s`` (S,);
    NaN outside the samples and inside gaps longer than ``max_gap_s``."""
    if len(time_s) == 1:
        return np.where((at_s == time_s[0])[:, None], position_m[0], np.nan)
    left = np.clip(np.searchsorted(time_s, at_s, side="right") - 1, 0, len(time_s) - 2)
    left_s, right_s = time_s[left], time_s[left + 1]
    weight = ((at_s - left_s) / (right_s - left_s))[:, None]
    # (1 - w) a + w b rather than a + w (b - a): exactly a at w = 0 and exactly b at w = 1.
    between_m = (1 - weight) * position_m[left] + weight * position_m[left + 1]
    gap = (right_s - left_s > max_gap_s) & (at_s > left_s) & (at_s < right_s)
    absent = (at_s < time_s[0]) | (at_s > time_s[-1]) | gap
    return np.where(absent[:, None], np.nan, between_m)
