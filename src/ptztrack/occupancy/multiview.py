"""Calibrated multi-view recordings: fixed cameras, their frames or detections, and the people on the ground.

A :class:`MultiViewRecording` is what the occupancy-map experiment reads,
whatever it came from: a video, a folder of images or a MOTChallenge
detection file per view, and ground truth in the MOTChallenge layout with
world metres (columns 8-9). The builders assemble one from a dataset file
(:mod:`ptztrack.builders.occupancy`) or from the synthetic room
(:mod:`ptztrack.occupancy.room`). Any problem with a file gets a
:class:`~ptztrack.scene.pets.DatasetError` naming it.
"""

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import PIL.Image

from ptztrack.files import shown
from ptztrack.geometry.calibration import PinholeCalibration
from ptztrack.scene.pets import Annotations, DatasetError, read_mot_rows, recorded_scene, refuse_rows_beyond
from ptztrack.types import GroundTruth

FrameSource = Callable[[int], np.ndarray]
"""``frame(index) -> (height, width, 3) uint8 BGR``: a view's image at a 0-based frame."""

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff")
EXIF_ORIENTATION = 0x0112
TRANSPOSING_ORIENTATIONS = (5, 6, 7, 8)


@dataclass(frozen=True)
class CameraView:
    """One fixed calibrated camera of a recording.

    name : how the view is called; calibration : its pinhole model (world in mm);
    image_size_px : (width, height), None where nothing needs it (a view with boxes only and a
    calibration that does not say); frames : its images, or None where there is no video;
    boxes : per frame, a detector's boxes (K, 5) as (left, top, width, height, score) px, or None;
    weight : its weight ``w_c`` in the occupancy map.
    """

    name: str
    calibration: PinholeCalibration
    image_size_px: tuple[int, int] | None
    frames: FrameSource | None
    boxes: list[np.ndarray] | None
    weight: float = 1.0


@dataclass(frozen=True)
class MultiViewRecording:
    """Fixed cameras watching the same ground.

    views : the cameras; frames : how many frames (0-based indices below this);
    frame_rate_hz : frames per second; area_m : [[x0, y0], [x1, y1]] the ground the map covers
    (people outside it are not scored); truth : the people, positions (frames, N, 2) m, or None;
    lead_in_frames : frames before frame 0 that the views' frame sources also give (indices -lead_in_frames
    to -1), for the background models to learn before the first frame; no detector sees them, nothing
    scores them.
    """

    name: str
    views: tuple[CameraView, ...]
    frames: int
    frame_rate_hz: float
    area_m: np.ndarray
    truth: GroundTruth | None
    lead_in_frames: int = 0


def outside_area(points_m, area_m) -> np.ndarray:
    """Which ground points (..., 2) m lie outside area_m [[x0, y0], [x1, y1]] (its edges are inside):
    (...,) bool, False for NaN (an absent person)."""
    points_m = np.asarray(points_m, dtype=float)
    (x0, y0), (x1, y1) = area_m
    with np.errstate(invalid="ignore"):
        x_m, y_m = points_m[..., 0], points_m[..., 1]
        return (x_m < x0) | (x_m > x1) | (y_m < y0) | (y_m > y1)


def load_mot_detections(
    path: str | Path, max_frames: int, image_size_px: tuple[int, int] | None = None
) -> list[np.ndarray]:
    """A MOTChallenge detection file (``frame,-1,left,top,width,height,score,...``, frames from 1)
    as per-frame boxes (K, 5) ``(left, top, width, height, score)``, from frame 0 to the file's last,
    which may be at most ``max_frames``; with the view's ``image_size_px`` (width, height), every box
    must overlap its image."""
    table, line = read_mot_rows(path, "detection")
    frame = table[:, 0].astype(np.int64) - 1
    refuse_rows_beyond(path, frame, line, max_frames, f"the {max_frames} frames a recording may have (memory)")
    frames = int(frame.max()) + 1
    if np.any((table[:, 4] <= 0) | (table[:, 5] <= 0)):
        raise DatasetError(f"{path}: a box has a width or height that is not positive")
    if image_size_px is not None:
        (width_px, height_px), (left, top, width, height) = image_size_px, table[:, 2:6].T
        outside = (left >= width_px) | (top >= height_px) | (left + width <= 0) | (top + height <= 0)
        if outside.any():
            first = int(np.argmax(outside))
            raise DatasetError(
                f"{path}: line {line[first]}: the box at ({left[first]:g}, {top[first]:g}) px, {width[first]:g} x "
                f"{height[first]:g} px, lies outside the view's {width_px}x{height_px} px image"
            )
    order = np.argsort(frame, kind="stable")
    boxes = table[order][:, 2:7]
    bounds = np.searchsorted(frame[order], np.arange(frames + 1))
    return [boxes[bounds[index] : bounds[index + 1]] for index in range(frames)]


class ImageFolder:
    """The images of a folder as frames, in the order of their sorted file names (``frame(index)``),
    each checked to be ``expected_size_px`` (width, height) when given.

    Every image is checked at once to have the first one's size, by its header (a few hundredths of a
    millisecond each; decoding took 5 ms), so that a folder with a frame of another size is refused
    before a run that would stop at that frame.
    """

    def __init__(self, path: str | Path, expected_size_px: tuple[int, int] | None = None):
        self.path = Path(path)
        if not self.path.is_dir():
            raise DatasetError(f"{self.path}: no such image folder")
        self.files = sorted(file for file in self.path.iterdir() if file.suffix.lower() in IMAGE_SUFFIXES)
        if not self.files:
            raise DatasetError(f"{self.path}: no images ({', '.join(IMAGE_SUFFIXES)})")
        self.expected_size_px = expected_size_px
        first_px = image_size_px(self.files[0])
        for file in self.files[1:]:
            size_px = image_size_px(file)
            if size_px != first_px:
                raise DatasetError(
                    f"{file}: {size_px[0]}x{size_px[1]} px, but {self.files[0].name} is {first_px[0]}x{first_px[1]} "
                    "px; the frames of an image folder must have one size"
                )

    def __len__(self) -> int:
        return len(self.files)

    def frame(self, index: int) -> np.ndarray:
        image = cv2.imread(str(self.files[index]), cv2.IMREAD_COLOR)
        if image is None:
            raise DatasetError(f"{self.files[index]}: OpenCV cannot read this image")
        if self.expected_size_px is not None and image.shape[1::-1] != tuple(self.expected_size_px):
            raise DatasetError(
                f"{self.files[index]}: {image.shape[1]}x{image.shape[0]} px, expected "
                f"{self.expected_size_px[0]}x{self.expected_size_px[1]} (the calibration's image size)"
            )
        return image


def image_size_px(path: Path) -> tuple[int, int]:
    """(width, height) of an image file as OpenCV decodes it, read from its header (Pillow reads no
    pixels until asked): EXIF orientations 5 to 8, which OpenCV applies, swap the two."""
    try:
        with PIL.Image.open(path) as image:
            width, height = image.size
            orientation = image.getexif().get(EXIF_ORIENTATION, 1)
    except Exception as error:  # noqa: BLE001 - Pillow's of a damaged or hostile file are of several kinds
        raise DatasetError(f"{path}: not an image that can be read ({shown(str(error))})") from None
    return (height, width) if orientation in TRANSPOSING_ORIENTATIONS else (width, height)


def mot_truth(annotations: Annotations, frames: int, frame_rate_hz: float) -> GroundTruth:
    """Ground truth (frames, N, 2) m of the first ``frames`` frames, from MOTChallenge annotations with
    world metres in columns 8-9 (:func:`~ptztrack.scene.pets.load_mot_ground_truth`)."""
    scene = recorded_scene(annotations, 1, frames, frame_rate_hz)
    positions_m = np.full((frames, scene.truth.positions_m.shape[1], 2), np.nan)
    positions_m[scene.video_frame] = scene.truth.positions_m
    return GroundTruth(positions_m, scene.truth.heights_m, scene.truth.widths_m, frame_rate_hz)
