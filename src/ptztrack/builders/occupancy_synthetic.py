"""The occupancy-map experiment's synthetic recordings: the paper's room and PETS 2009 S2.L1's plaza.

Each is rendered on demand (:mod:`ptztrack.occupancy.room`, :mod:`ptztrack.occupancy.plaza`, through
:class:`~ptztrack.scene.render.SceneRenderer`) into a :class:`~ptztrack.occupancy.multiview.MultiViewRecording`
with its exact ground truth: areas [[x0, y0], [x1, y1]] in m, frame rates in Hz, the plaza with a lead-in
of frames rendered before its first for the background models alone.
"""

import functools
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np

from ptztrack.config import pets_dataset
from ptztrack.geometry.calibration import load_tsai, pinhole_from_tsai
from ptztrack.occupancy.multiview import CameraView, MultiViewRecording
from ptztrack.occupancy.parameters import ForegroundParameters
from ptztrack.occupancy.plaza import PlazaLayout, plaza_stage, plaza_truth
from ptztrack.occupancy.room import RoomLayout, RoomRenderer, room_truth
from ptztrack.scene.pets import load_mot_ground_truth
from ptztrack.scene.render import SceneRenderer

ROOM_AREA_M = ((0.0, 0.0), (5.0, 6.0))
PLAZA_WALKED_PERCENT = 90.0
"""The share of S2.L1's annotated positions, along each axis, inside the plaza's area (a priori: the
band people walk in, without the few positions in the corners)."""
PLAZA_LEAD_IN_FRAMES = ForegroundParameters().history // 2
"""The plaza's lead-in, rendered before its first frame for the background models alone (a priori: the
frames after which MOG2's learning rate, ``1 / min(2 n, history)``, has reached its steady ``1 / history``)."""
# 20 s at 15 Hz per sequence (the paper's were 3.5 and 7 minutes long).
ROOM = RoomLayout()


def room_recording(people: int, frames: int, seed: int, layout: RoomLayout = ROOM) -> MultiViewRecording:
    """The synthetic room with ``people`` walking for ``frames`` frames, rendered on demand."""
    renderer = RoomRenderer(layout, room_truth(layout, people, frames, seed), seed)
    names = [f"camera_{index + 1}" for index in range(len(renderer.cameras))]
    return rendered_recording(f"room-{people}", names, renderer, ROOM_AREA_M, layout.frame_rate_hz)


def plaza_layout() -> PlazaLayout:
    """The plaza where the built-in PETS 2009 S2.L1 dataset's people walk, at its frame rate.

    The area is the central ``PLAZA_WALKED_PERCENT`` of S2.L1's annotated ground positions along each
    axis: its annotators marked the people View_001 sees, who walk in a band that three to seven of the
    seven views see; the dataset's whole area reaches corners that one view sees, or none.
    """
    pets = pets_dataset()
    assert pets.ground_truth is not None  # the built-in dataset has its annotations
    positions_m = load_mot_ground_truth(pets.ground_truth).ground_m
    tail = (100.0 - PLAZA_WALKED_PERCENT) / 2
    low_m, high_m = np.percentile(positions_m, [tail, 100.0 - tail], axis=0)
    area_m = ((float(low_m[0]), float(low_m[1])), (float(high_m[0]), float(high_m[1])))
    return PlazaLayout(area_m=area_m, frame_rate_hz=pets.frame_rate_hz)


def plaza_renderer(people: int, frames: int, seed: int) -> SceneRenderer:
    """The synthetic plaza's renderer (:mod:`ptztrack.occupancy.plaza`): PETS 2009 S2.L1's seven views
    (the built-in dataset's, in its order), each through its official Tsai calibration
    (``View_00N.xml`` beside the dataset file, which states the image size: 768 x 576 or 720 x 576 px),
    watching ``people`` walk for ``frames`` frames."""
    layout = plaza_layout()
    cameras, sizes_px = [], []
    for view in pets_dataset().views:
        tsai = load_tsai(Path(view.calibration).with_name(f"{view.name}.xml"))
        cameras.append(pinhole_from_tsai(tsai))
        sizes_px.append(tsai.image_size_px)
    truth = plaza_truth(layout, people, frames, seed)
    return SceneRenderer(cameras, sizes_px, plaza_stage(layout, cameras), truth, seed)


def plaza_recording(
    people: int, frames: int, seed: int, lead_in_frames: int = PLAZA_LEAD_IN_FRAMES
) -> MultiViewRecording:
    """The synthetic plaza with ``people`` walking for ``frames`` frames at PETS's frame rate over its
    area, rendered on demand (:func:`plaza_renderer`); every view has frames and no detector's boxes.

    The walk starts ``lead_in_frames`` frames before the first frame: the recording's lead-in, which the
    background models learn and nothing scores (a fixed camera has watched its scene before any frame a
    table counts)."""
    layout = plaza_layout()
    names = [view.name for view in pets_dataset().views]
    renderer = plaza_renderer(people, lead_in_frames + frames, seed)
    return rendered_recording(f"plaza-{people}", names, renderer, layout.area_m, layout.frame_rate_hz, lead_in_frames)


def rendered_recording(
    name: str, view_names: list[str], renderer: SceneRenderer, area_m, frame_rate_hz: float, lead_in_frames: int = 0
) -> MultiViewRecording:
    """The recording of a renderer's views (named ``view_names``), its frames rendered on demand, every
    frame of its truth after the first ``lead_in_frames`` (the recording's lead-in: its frames -lead_in_frames
    to -1); area_m : [[x0, y0], [x1, y1]] the ground scored."""
    views = tuple(
        CameraView(view_name, camera, size_px, _view_frames(renderer, index, lead_in_frames), None)
        for index, (view_name, camera, size_px) in enumerate(
            zip(view_names, renderer.cameras, renderer.image_sizes_px, strict=True)
        )
    )
    truth = replace(renderer.truth, positions_m=renderer.truth.positions_m[lead_in_frames:])
    return MultiViewRecording(
        name, views, truth.positions_m.shape[0], frame_rate_hz, np.asarray(area_m), truth, lead_in_frames
    )


def _view_frames(renderer: SceneRenderer, view: int, lead_in_frames: int) -> Callable[[int], np.ndarray]:
    """The view's frames from ``-lead_in_frames``, the last two kept: both detectors ask for each frame, LPOM
    for the one before too."""
    image = functools.lru_cache(maxsize=2)(functools.partial(renderer.image, view))
    return lambda frame: image(frame + lead_in_frames)
