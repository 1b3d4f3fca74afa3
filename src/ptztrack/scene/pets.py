"""PETS 2009 S2.L1 and recordings like it: video frames and ground truth.

Two ground-truth formats are read: MOTChallenge rows with world positions in
metres (``frame,id,left,top,width,height,conf,x_m,y_m,z``, frames from 1),
and CVML XML with pixel boxes (``<frame number>`` from 0). Any problem gets a
:class:`DatasetError` naming the file and what is wrong.
"""

import io
import re
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from ptztrack.files import InputError, read_text, read_xml_root, require_file, shown
from ptztrack.geometry.calibration import PinholeCalibration, in_image, project_pinhole
from ptztrack.scene.synthetic import GroundTruth

MOT_COLUMNS = 10
GROUND_TRUTH_MAX_BYTES = 200_000_000
"""An annotation file's size limit: 4 million MOTChallenge rows, far beyond any public benchmark."""


class DatasetError(InputError):
    """A dataset file that cannot be used; the message names the file and the problem."""


@dataclass(frozen=True)
class Annotations:
    """Annotated people, one row per person and frame.

    frame : (K,) 0-based video frame; person_id : (K,);
    box_px : (K, 4) as (left, top, width, height);
    ground_m : (K, 2) feet on the ground plane in metres (NaN where the format has none);
    line : (K,) each row's line in its file, where the format has rows (MOTChallenge), else None.
    """

    frame: np.ndarray
    person_id: np.ndarray
    box_px: np.ndarray
    ground_m: np.ndarray
    line: np.ndarray | None = None

    @property
    def feet_px(self) -> np.ndarray:
        """(K, 2) bottom centre of each box."""
        return box_feet_px(self.box_px)

    def select(self, keep) -> "Annotations":
        line = None if self.line is None else self.line[keep]
        return Annotations(self.frame[keep], self.person_id[keep], self.box_px[keep], self.ground_m[keep], line)


def box_feet_px(boxes_px) -> np.ndarray:
    """Where the people of boxes (K, 4+) px (left, top, width, height, ...) stand: their bottom centres (K, 2) px."""
    boxes_px = np.asarray(boxes_px, dtype=float)
    return np.stack([boxes_px[:, 0] + boxes_px[:, 2] / 2, boxes_px[:, 1] + boxes_px[:, 3]], axis=-1)


def box_iou(a, b) -> np.ndarray:
    """Intersection over union of boxes (..., 4) (left, top, width, height); broadcasts."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    low = np.maximum(a[..., :2], b[..., :2])
    high = np.minimum(a[..., :2] + a[..., 2:], b[..., :2] + b[..., 2:])
    intersection = np.prod(np.clip(high - low, 0.0, None), axis=-1)
    union = np.prod(a[..., 2:], axis=-1) + np.prod(b[..., 2:], axis=-1) - intersection
    return np.where(union > 0, intersection / np.where(union > 0, union, 1.0), 0.0)


FIT_BOX_HEIGHTS = 0.5
"""The median distance, in box heights, from annotated people's ground positions projected into a view
to their boxes' feet beyond which the calibration is taken not to fit the view: half a person's height
(the measured values on PETS are on the bad-inputs page)."""


def refuse_annotations_off_the_view(
    path: str | Path, annotations: Annotations, calibration: PinholeCalibration, size_px, calibration_path
) -> str | None:
    """Check annotations whose rows carry both a box (K, 4) px and a ground position (K, 2) m against the
    view's calibration (its image (width, height) px): raise :class:`DatasetError` if no ground position
    projects into the image at all; return a warning line if the projected positions lie a median of
    more than ``FIT_BOX_HEIGHTS`` box heights from their own boxes' feet (the calibration is most likely
    not the view's, or the world coordinates not the boxes' people); else None."""
    points_mm = np.c_[1000.0 * annotations.ground_m, np.zeros(len(annotations.frame))]
    seen = in_image(calibration, size_px, points_mm)
    if len(annotations.frame) and not seen.any():
        x_m, y_m = annotations.ground_m[0]
        raise DatasetError(
            f"{path}: none of its {len(seen)} ground positions (columns 8-9; the first ({x_m:g}, {y_m:g}) m) "
            f"lies in the image of {Path(calibration_path).name}: expected its boxes' people, in metres"
        )
    heights_px = annotations.box_px[seen, 3]
    sized = heights_px > 0
    if not sized.any():
        return None
    distance_px = np.linalg.norm(project_pinhole(calibration, points_mm[seen]) - annotations.feet_px[seen], axis=-1)
    median = float(np.median(distance_px[sized] / heights_px[sized]))
    if median <= FIT_BOX_HEIGHTS:
        return None
    return (
        f"{path}: its people's ground positions project a median {median:.2g} box heights from their boxes' feet "
        f"in {Path(calibration_path).name} (expected under {FIT_BOX_HEIGHTS:g}): is this the view's calibration?"
    )


def load_mot_ground_truth(path: str | Path) -> Annotations:
    """Read MOTChallenge ground truth with world coordinates (frames from 1 become 0-based).

    Frames and ids must be whole numbers, each (frame, id) appear once, and every number be finite.
    """
    table, line = read_mot_rows(path, "ground-truth")
    frame, person_id = table[:, 0].astype(np.int64), table[:, 1].astype(np.int64)
    refuse_repeated_annotations(Path(path), frame, person_id, line)
    return Annotations(frame - 1, person_id, table[:, 2:6], table[:, 7:9], line)


def read_mot_rows(path: str | Path, what: str) -> tuple[np.ndarray, np.ndarray]:
    """The rows (K, 10) of a MOTChallenge file (ground truth or detections; ``.gz`` compressed or not),
    checked: ten finite numbers a line, whole frames and ids, frames from 1; and the line (K,) of each
    in the file. ``what`` names the kind of file in errors."""
    text = read_text(path, what, GROUND_TRUTH_MAX_BYTES, DatasetError)
    return number_rows(path, text, what, MOT_COLUMNS, 1, "in MOTChallenge files")


def number_rows(
    path: str | Path,
    text: str,
    what: str,
    columns: int,
    first_frame: int,
    numbered: str,
    separator: str = ",",
    layout: str = "",
) -> tuple[np.ndarray, np.ndarray]:
    """The rows (K, ``columns``) of the ``text`` of the file ``path``, whose lines are a frame, an id and
    more numbers, split at the regular expression ``separator`` (blank lines skipped), checked:
    ``columns`` finite numbers a line, whole frames and ids, frames from ``first_frame``; and the line
    (K,) of each in the file. ``what`` names the kind of file in errors, ``numbered`` the files whose
    frames are counted from ``first_frame`` (e.g. "in MOTChallenge files"), ``layout`` (e.g.
    " (frame id x y)") follows the count of columns expected. Comma-separated text is parsed by NumPy at
    once; line by line only where a line is wrong, to name it."""
    path = Path(path)
    if separator == ",":
        parsed = _comma_rows(text, columns, first_frame)
        if parsed is not None:
            return parsed
    rows, lines = [], []
    for number, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        fields = re.split(separator, line.strip())
        if len(fields) != columns:
            raise DatasetError(f"{path}: line {number} has {len(fields)} fields, expected {columns}{layout}")
        try:
            values = [float(field) for field in fields]
        except ValueError:
            raise DatasetError(f"{path}: line {number} has a field that is not a number") from None
        if not all(np.isfinite(values)):
            raise DatasetError(f"{path}: line {number} has a NaN or infinite field, expected finite numbers")
        if values[0] != round(values[0]) or values[1] != round(values[1]):
            raise DatasetError(
                f"{path}: line {number}: frame and id must be whole numbers "
                f"(got {shown(fields[0])}, {shown(fields[1])})"
            )
        if values[0] < first_frame:
            raise DatasetError(
                f"{path}: line {number}: frame {shown(fields[0])}; frames are numbered from {first_frame} {numbered}"
            )
        rows.append(values)
        lines.append(number)
    if not rows:
        raise DatasetError(f"{path}: no {what} rows")
    return np.asarray(rows), np.asarray(lines)


def _comma_rows(text: str, columns: int, first_frame: int) -> tuple[np.ndarray, np.ndarray] | None:
    """:func:`number_rows` of comma-separated ``text`` in one pass of NumPy's reader, or None where a line
    is not as expected there (or there is none), for the line-by-line reading to name it."""
    lines = np.flatnonzero([bool(line.strip()) for line in text.splitlines()]) + 1
    if not len(lines):
        return None
    try:
        table = np.loadtxt(io.StringIO(text), dtype=float, delimiter=",", comments=None, ndmin=2)
    except ValueError:
        return None
    if table.shape != (len(lines), columns) or not np.all(np.isfinite(table)):
        return None
    frame_and_id = table[:, :2]
    if np.any(frame_and_id != np.round(frame_and_id)) or np.any(table[:, 0] < first_frame):
        return None
    return table, lines


def refuse_rows_beyond(path: str | Path, frame, line, frames: int, recording: str) -> None:
    """A :class:`DatasetError` naming the first row of a MOTChallenge file whose frame the recording
    does not have: frame (K,) 0-based, line (K,) each row's line, ``frames`` how many the recording has,
    ``recording`` those frames in words (e.g. "the 795 frames of the video v.avi")."""
    beyond = np.flatnonzero(np.asarray(frame) >= frames)
    if len(beyond):
        first = beyond[np.argmin(np.asarray(line)[beyond])]
        raise DatasetError(f"{path}: line {line[first]}: frame {frame[first] + 1} is beyond {recording}")


def refuse_repeated_annotations(
    path: str | Path, frame: np.ndarray, person_id: np.ndarray, line: np.ndarray | None = None
) -> None:
    """A :class:`DatasetError` if a person is annotated twice in a frame: frame (K,) numbered as in the
    file, person_id (K,); line (K,) each row's line, if the file has rows, to name the second one."""
    pairs, inverse, counts = np.unique(np.c_[frame, person_id], axis=0, return_inverse=True, return_counts=True)
    if np.any(counts > 1):
        first = int(np.argmax(counts > 1))
        repeated_frame, repeated_id = pairs[first]
        where = "" if line is None else f" line {np.sort(line[inverse.ravel() == first])[1]}:"
        raise DatasetError(
            f"{path}:{where} person {repeated_id} is annotated {counts[first]} times in frame {repeated_frame}, "
            "expected once"
        )


def load_cvml(path: str | Path) -> Annotations:
    """Read CVML XML boxes (``<frame number><objectlist><object id><box h w xc yc>``)."""
    path = Path(path)
    root = read_xml_root(path, "annotation", GROUND_TRUTH_MAX_BYTES, DatasetError)
    rows = []
    for frame_element in root.iter("frame"):
        for person in frame_element.iter("object"):
            box = person.find("box")
            try:
                values = [float(box.get(name, "")) for name in ("xc", "yc", "w", "h")]  # type: ignore[union-attr]
                rows.append([int(frame_element.get("number", "")), int(person.get("id", "")), *values])
            except (AttributeError, ValueError):
                raise DatasetError(
                    f"{path}: frame {shown(frame_element.get('number'))} object {shown(person.get('id'))} needs "
                    "integer number and id and a <box> with numeric xc, yc, w, h"
                ) from None
    if not rows:
        raise DatasetError(f"{path}: no annotated objects")
    table = np.asarray(rows)
    if not np.all(np.isfinite(table)) or np.any(table[:, 0] < 0):
        raise DatasetError(f"{path}: a frame number below 0 or a NaN or infinite box; expected finite boxes")
    frame, person_id = table[:, 0].astype(np.int64), table[:, 1].astype(np.int64)
    refuse_repeated_annotations(path, frame, person_id)
    centre, size = table[:, 2:4], table[:, 4:6]
    return Annotations(
        frame=frame,
        person_id=person_id,
        box_px=np.concatenate([centre - size / 2, size], axis=1),
        ground_m=np.full((len(table), 2), np.nan),
    )


def read_video(path: str | Path, expected_frames: int | None = None, expected_size_px=None) -> np.ndarray:
    """All frames of a video as (T, height, width, 3) uint8 BGR, checked against what is expected.

    expected_size_px : (width, height), e.g. from the calibration.
    """
    path = Path(path)
    require_file(path, "video", DatasetError)
    capture = cv2.VideoCapture(str(path))
    frames = []
    while True:
        ok, frame = capture.read()
        if not ok:
            break
        frames.append(frame)
    capture.release()
    if not frames:
        raise DatasetError(f"{path}: OpenCV could not read any frame")
    video = np.stack(frames)
    if expected_frames is not None and len(video) != expected_frames:
        raise DatasetError(f"{path}: {len(video)} frames, expected {expected_frames}")
    if expected_size_px is not None and tuple(video.shape[2:0:-1]) != tuple(expected_size_px):
        width, height = expected_size_px
        raise DatasetError(f"{path}: frames are {video.shape[2]}x{video.shape[1]} px, expected {width}x{height}")
    return video


@dataclass(frozen=True)
class RecordedScene:
    """The people of a recording, step by step, for the closed loop.

    truth : positions (T, N, 2) metres, NaN where absent, for the metrics.
    video_frame : (T,) the recorded frame of each step.
    person_id : (N,) the annotation id of each column of ``truth``.
    annotations : the annotations of those frames.
    """

    truth: GroundTruth
    video_frame: np.ndarray
    person_id: np.ndarray
    annotations: Annotations


def recorded_scene(
    annotations: Annotations,
    frame_step: int,
    steps: int,
    frame_rate_hz: float,
    width_m: float = 0.5,
    frame_range: tuple[int, int] | None = None,
) -> RecordedScene:
    """Every ``frame_step``-th frame of ``frame_range`` [first, stop) (default: from frame 0 to the last
    annotated one), for ``steps`` steps at most.

    The people's heights are not annotated; ``GroundTruth.heights_m`` holds
    NaN, which nothing on this path reads (detections come from the boxes).
    """
    first, stop = frame_range if frame_range is not None else (0, annotations.frame.max() + 1)
    # Not arange(first, stop)[:steps]: an annotation of a distant frame would make it gigabytes.
    video_frame = np.arange(first, min(stop, first + steps * frame_step), frame_step)
    kept = annotations.select(np.isin(annotations.frame, video_frame))
    person_id = np.unique(kept.person_id)
    positions_m = np.full((len(video_frame), len(person_id), 2), np.nan)
    step = np.searchsorted(video_frame, kept.frame)
    column = np.searchsorted(person_id, kept.person_id)
    positions_m[step, column] = kept.ground_m
    truth = GroundTruth(
        positions_m=positions_m,
        heights_m=np.full(len(person_id), np.nan),
        widths_m=np.full(len(person_id), width_m),
        frame_rate_hz=frame_rate_hz,
    )
    return RecordedScene(truth, video_frame, person_id, kept)


class RecordedVideo:
    """Frames of a video read forwards on demand, so that a long recording is never held in memory.

    The closed loop asks for increasing frame indices, the same one again
    when a step looks at its frame twice (the last frame is kept); asking for
    an earlier frame reopens the video.
    """

    def __init__(self, path: str | Path, expected_size_px=None, frames_needed: int | None = None):
        """Checks at once that the video is one OpenCV reads, of ``expected_size_px`` (width, height),
        with at least ``frames_needed`` frames, so that a run fails before its first step.

        ``frame_count`` is the header's count, which a truncated file keeps: the last frame needed is
        read to know that it is there.
        """
        self.path = Path(path)
        require_file(self.path, "video", DatasetError)
        self.expected_size_px = expected_size_px
        self._open()
        if not self._capture.isOpened():
            raise DatasetError(f"{self.path}: not a video OpenCV can read")
        self.frame(0)
        self.frame_count = int(self._capture.get(cv2.CAP_PROP_FRAME_COUNT))
        if frames_needed is not None:
            self._require_frame(frames_needed - 1)

    def _require_frame(self, index: int) -> None:
        if index >= self.frame_count:
            raise DatasetError(f"{self.path}: {self.frame_count} frames, the run needs {index + 1}")
        self._capture.set(cv2.CAP_PROP_POS_FRAMES, index)
        if not self._capture.grab():
            raise DatasetError(
                f"{self.path}: the video cannot be read at frame {index}, which the run needs, though its header "
                f"says {self.frame_count} frames (a truncated file?)"
            )
        self._capture.release()  # frames are read forwards from the start: a seek is not exact in every codec
        self._open()

    def _open(self) -> None:
        self._capture = cv2.VideoCapture(str(self.path))
        self._next = 0
        self._last: np.ndarray | None = None

    def frame(self, index: int) -> np.ndarray:
        """Frame ``index`` (0-based) as (height, width, 3) uint8 BGR (do not modify it: it is kept)."""
        if index == self._next - 1 and self._last is not None:
            return self._last
        if index < self._next:
            self._capture.release()
            self._open()
        while self._next < index:
            if not self._capture.grab():
                raise DatasetError(f"{self.path}: the video ends before frame {index}")
            self._next += 1
        ok, image = self._capture.read()
        if not ok:
            raise DatasetError(f"{self.path}: no frame {index}: the video ends or cannot be decoded there")
        self._next += 1
        if self.expected_size_px is not None and tuple(image.shape[1::-1]) != tuple(self.expected_size_px):
            raise DatasetError(
                f"{self.path}: frames are {image.shape[1]}x{image.shape[0]} px, "
                f"expected {self.expected_size_px[0]}x{self.expected_size_px[1]}"
            )
        self._last = image
        return image
