"""PETS 2009 S2.L1 and recordings like it: video frames and ground truth.

Two ground-truth formats are read: MOTChallenge rows with world positions in
metres (``frame,id,left,top,width,height,conf,x_m,y_m,z``, frames from 1),
and CVML XML with pixel boxes (``<frame number>`` from 0). Any problem gets a
:class:`DatasetError` naming the file and what is wrong.
"""

import gzip
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from ptztrack.geometry.calibration import read_xml_root
from ptztrack.scene.synthetic import GroundTruth

MOT_COLUMNS = 10


class DatasetError(ValueError):
    """A dataset file that cannot be used; the message names the file and the problem."""


@dataclass(frozen=True)
class Annotations:
    """Annotated people, one row per person and frame.

    frame : (K,) 0-based video frame; person_id : (K,);
    box_px : (K, 4) as (left, top, width, height);
    ground_m : (K, 2) feet on the ground plane in metres (NaN where the format has none).
    """

    frame: np.ndarray
    person_id: np.ndarray
    box_px: np.ndarray
    ground_m: np.ndarray

    @property
    def feet_px(self) -> np.ndarray:
        """(K, 2) bottom centre of each box."""
        return np.stack([self.box_px[:, 0] + self.box_px[:, 2] / 2, self.box_px[:, 1] + self.box_px[:, 3]], axis=-1)

    def select(self, keep) -> "Annotations":
        return Annotations(self.frame[keep], self.person_id[keep], self.box_px[keep], self.ground_m[keep])


def load_mot_ground_truth(path: str | Path) -> Annotations:
    """Read MOTChallenge ground truth with world coordinates (frames from 1 become 0-based)."""
    table = read_mot_rows(path, "ground-truth")
    return Annotations(
        frame=table[:, 0].astype(int) - 1,
        person_id=table[:, 1].astype(int),
        box_px=table[:, 2:6],
        ground_m=table[:, 7:9],
    )


def read_mot_rows(path: str | Path, what: str) -> np.ndarray:
    """The rows (K, 10) of a MOTChallenge file (ground truth or detections; ``.gz`` compressed or not),
    checked: ten numeric fields a line, frames from 1. ``what`` names the kind of file in errors."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise DatasetError(f"{path}: no such {what} file") from None
    try:
        lines = (gzip.decompress(data) if path.suffix == ".gz" else data).decode("utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        raise DatasetError(f"{path}: not a text file (or not gzip-compressed text)") from None
    rows = []
    for number, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        fields = line.split(",")
        if len(fields) != MOT_COLUMNS:
            raise DatasetError(f"{path}: line {number} has {len(fields)} fields, expected {MOT_COLUMNS}")
        try:
            rows.append([float(field) for field in fields])
        except ValueError:
            raise DatasetError(f"{path}: line {number} has a field that is not a number") from None
    if not rows:
        raise DatasetError(f"{path}: no {what} rows")
    table = np.asarray(rows)
    if np.any(table[:, 0] < 1):
        raise DatasetError(f"{path}: frames are numbered from 1 in MOTChallenge files")
    return table


def load_cvml(path: str | Path) -> Annotations:
    """Read CVML XML boxes (``<frame number><objectlist><object id><box h w xc yc>``)."""
    path = Path(path)
    root = read_xml_root(path, DatasetError, "annotation")
    rows = []
    for frame in root.iter("frame"):
        for person in frame.iter("object"):
            box = person.find("box")
            try:
                values = [float(box.get(name)) for name in ("xc", "yc", "w", "h")]
                rows.append([int(frame.get("number")), int(person.get("id")), *values])
            except (AttributeError, TypeError, ValueError):
                raise DatasetError(
                    f"{path}: frame {frame.get('number')!r} object {person.get('id')!r} needs "
                    "integer number and id and a <box> with numeric xc, yc, w, h"
                ) from None
    if not rows:
        raise DatasetError(f"{path}: no annotated objects")
    table = np.asarray(rows)
    centre, size = table[:, 2:4], table[:, 4:6]
    return Annotations(
        frame=table[:, 0].astype(int),
        person_id=table[:, 1].astype(int),
        box_px=np.concatenate([centre - size / 2, size], axis=1),
        ground_m=np.full((len(table), 2), np.nan),
    )


def read_video(path: str | Path, expected_frames: int | None = None, expected_size_px=None) -> np.ndarray:
    """All frames of a video as (T, height, width, 3) uint8 BGR, checked against what is expected.

    expected_size_px : (width, height), e.g. from the calibration.
    """
    path = Path(path)
    if not path.is_file():
        raise DatasetError(f"{path}: no such video file")
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
    annotations: Annotations, frame_step: int, steps: int, frame_rate_hz: float, width_m: float = 0.5
) -> RecordedScene:
    """Every ``frame_step``-th annotated frame, from the first, for ``steps`` steps (fewer if the recording ends).

    The people's heights are not annotated; ``GroundTruth.heights_m`` holds
    NaN, which nothing on this path reads (detections come from the boxes).
    """
    video_frame = np.arange(0, annotations.frame.max() + 1, frame_step)[:steps]
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

    def __init__(self, path: str | Path, expected_size_px=None):
        self.path = Path(path)
        if not self.path.is_file():
            raise DatasetError(f"{self.path}: no such video file")
        self.expected_size_px = expected_size_px
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
            raise DatasetError(f"{self.path}: the video ends before frame {index}")
        self._next += 1
        if self.expected_size_px is not None and tuple(image.shape[1::-1]) != tuple(self.expected_size_px):
            raise DatasetError(
                f"{self.path}: frames are {image.shape[1]}x{image.shape[0]} px, "
                f"expected {self.expected_size_px[0]}x{self.expected_size_px[1]}"
            )
        self._last = image
        return image
