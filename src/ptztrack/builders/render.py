"""A scenario rendered into a multi-view dataset (``ptztrack render``): each camera's video, the
calibration, the ground truth in metres and the dataset file that names them.

The people are the scenario's (:func:`~ptztrack.builders.world.build_scene`, drawn from the scene's
stream of ``seed``: the people ``ptztrack run --seed`` simulates on the same scenario); the cameras are
its ``cameras`` (each with its own or the ``camera`` section's image size and focal length) or, without
them, its one ``camera``, each fixed and aimed at the area's centre on the ground at its widest focal
length (``f_min_px``), without distortion (:func:`~ptztrack.geometry.calibration.aimed_pinhole`). They
stand on an open paved place around the area and the cameras (:func:`~ptztrack.scene.render.stage_around`)
and are drawn by the scene's renderer (:mod:`ptztrack.scene.render`).

The folder (``out_dir``) is written whole or not at all (:func:`ptztrack.files.run_folder`)::

    dataset.yaml       the multi-view dataset file (docs: reference, dataset files)
    calibration.json   every view's pinhole calibration {view: {K, dist, R, t [mm]}}
    <view>.avi         each view's frames, Motion JPEG (FFmpeg's, as OpenCV writes it)
    gt_<view>.txt      each view's annotations: MOTChallenge rows frame (from 1), id, left, top, width,
                       height, 1, x_m, y_m, 0 of the people whose feet are in its image, their boxes in
                       its pixels (:func:`~ptztrack.scene.render.person_boxes`)
"""

import functools
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import yaml

from ptztrack.builders.world import build_scene
from ptztrack.config import Scenario, ScenarioError, pets_dataset
from ptztrack.files import run_folder, write_atomically, write_json
from ptztrack.geometry.calibration import PinholeCalibration, aimed_pinhole, pinhole_document
from ptztrack.loop.streams import episode_streams
from ptztrack.names import PEOPLE_LOOKS
from ptztrack.scene.cutouts import CutoutTrack, cut_people
from ptztrack.scene.pets import RecordedVideo, load_mot_ground_truth
from ptztrack.scene.render import SceneRenderer, person_boxes, stage_around
from ptztrack.types import GroundTruth
from ptztrack.view.video import write_video

DATASET_FILE = "dataset.yaml"
CALIBRATION_FILE = "calibration.json"
VIDEO_FOURCC = "MJPG"
PETS_CUTOUT_VIEW = "View_001"
RENDER_STREAM = 1
"""The renderer's textures, outfits and noise come from seed ``[seed, RENDER_STREAM]``, apart from the
people's walks (the episode's scene stream of ``seed``)."""


@dataclass(frozen=True)
class RenderedView:
    """One fixed camera of a rendered dataset: its name, calibration (world in mm) and image (width, height) px."""

    name: str
    calibration: PinholeCalibration
    image_size_px: tuple[int, int]


def rendered_views(scenario: Scenario) -> list[RenderedView]:
    """The scenario's cameras as fixed views aimed at the area's centre: ``cameras`` (named camera_1,
    camera_2, ... in their order) or else the one ``camera`` (camera_1)."""
    centre_m = np.asarray(scenario.area_m, dtype=float) / 2
    section = scenario.camera
    mounts = [
        (camera.position_m, camera.image_size_px or section.image_size_px, camera.f_min_px or section.f_min_px)
        for camera in scenario.cameras
    ] or [(section.position_m, section.image_size_px, section.f_min_px)]
    return [
        RenderedView(
            f"camera_{index + 1}",
            aimed_pinhole(position_m, centre_m, focal_px, size_px),
            (int(size_px[0]), int(size_px[1])),
        )
        for index, (position_m, size_px, focal_px) in enumerate(mounts)
    ]


def rendered_truth(scenario: Scenario, seed: int) -> GroundTruth:
    """The scenario's people as ``ptztrack run --seed`` simulates them; a height or width the scenario
    leaves unknown (NaN) is the middle of ``people.height_m``, or ``people.width_m``."""
    if scenario.recording is not None:
        raise ScenarioError("render: the scenario has a recording; render takes a scenario without one (recording)")
    truth = build_scene(scenario, np.random.default_rng(episode_streams(seed).scene)).truth
    heights_m = np.where(np.isnan(truth.heights_m), np.mean(scenario.people.height_m), truth.heights_m)
    widths_m = np.where(np.isnan(truth.widths_m), scenario.people.width_m, truth.widths_m)
    return replace(truth, heights_m=heights_m, widths_m=widths_m)


@functools.cache
def pets_cutouts() -> tuple[CutoutTrack, ...]:
    """The pedestrians of the built-in PETS 2009 S2.L1 View_001, cut out with its annotated boxes
    (:func:`~ptztrack.scene.cutouts.cut_people`; read once per process)."""
    dataset = pets_dataset()
    view = next(view for view in dataset.views if view.name == PETS_CUTOUT_VIEW)
    ground_truth = view.ground_truth or dataset.ground_truth
    assert view.video is not None and ground_truth is not None  # the built-in dataset's View_001
    annotations = load_mot_ground_truth(ground_truth)
    video = RecordedVideo(view.video)
    frames = ((index, video.frame(index)) for index in range(video.frame_count))
    return tuple(cut_people(frames, video.frame_count, annotations.frame, annotations.person_id, annotations.box_px))


def render_dataset(
    scenario: Scenario,
    out_dir: str | Path,
    seed: int = 0,
    progress: Callable[[int, int], None] | None = None,
    overwrite: bool = False,
    people_look: str = PEOPLE_LOOKS[0],
) -> Path:
    """Render ``scenario`` into the dataset folder ``out_dir`` (see the module's docstring) and return
    the path of its ``dataset.yaml``.

    seed : the people's walks and the rendering (textures, clothes, noise): the same seed writes the
    same files. progress : called with (images done, images) as the views' frames are rendered, view
    after view. overwrite : replace a folder that is not empty (else an
    :class:`~ptztrack.files.InputError`, the folder untouched). people_look : one of PEOPLE_LOOKS: 'cones'
    (cone bodies, :func:`~ptztrack.scene.render.draw_people`) or 'pets-cutouts' (PETS 2009's pedestrians,
    :func:`pets_cutouts`); cones by default, to HOG the closer to PETS's people (docs: results, rendered
    people and HOG). The folder appears only once every file is written and each video read back.
    """
    out_dir = Path(out_dir)
    if people_look not in PEOPLE_LOOKS:
        raise ValueError(f"people_look {people_look!r}: expected one of {', '.join(PEOPLE_LOOKS)}")
    truth = rendered_truth(scenario, seed)
    views = rendered_views(scenario)
    cameras = [view.calibration for view in views]
    area_m = ((0.0, 0.0), (float(scenario.area_m[0]), float(scenario.area_m[1])))
    render_seed = int(np.random.SeedSequence([seed, RENDER_STREAM]).generate_state(1)[0])
    renderer = SceneRenderer(
        cameras,
        [view.image_size_px for view in views],
        stage_around(area_m, cameras),
        truth,
        render_seed,
        pets_cutouts() if people_look == "pets-cutouts" else None,
    )
    frames = truth.positions_m.shape[0]
    with run_folder(out_dir, overwrite) as folder:
        _write_videos(folder, views, renderer, scenario.frame_rate_hz, progress)
        write_json(folder / CALIBRATION_FILE, {view.name: pinhole_document(view.calibration) for view in views})
        for view in views:
            write_atomically(folder / _ground_truth_file(view), _ground_truth_rows(view, truth).encode())
        name = out_dir.absolute().name or "rendered"
        document = _dataset_document(name, scenario.frame_rate_hz, frames, area_m, views, seed, people_look)
        write_atomically(folder / DATASET_FILE, document.encode())
    return out_dir / DATASET_FILE


def _write_videos(
    folder: Path,
    views: list[RenderedView],
    renderer: SceneRenderer,
    frame_rate_hz: float,
    progress: Callable[[int, int], None] | None,
) -> None:
    """Every view's frames into ``<view>.avi``, each read back: it must have every frame at the size."""
    frames = renderer.truth.positions_m.shape[0]
    for index, view in enumerate(views):

        def images(index=index):
            for frame in range(frames):
                yield renderer.image(index, frame)
                if progress is not None:
                    progress(index * frames + frame + 1, len(views) * frames)

        path = folder / f"{view.name}.avi"
        write_video(path, images(), frame_rate_hz, view.image_size_px, VIDEO_FOURCC)
        video = RecordedVideo(path, view.image_size_px, frames)
        if video.frame_count != frames:
            raise RuntimeError(f"{path.name}: OpenCV wrote {video.frame_count} frames, not {frames}")


def _ground_truth_file(view: RenderedView) -> str:
    return f"gt_{view.name}.txt"


def _ground_truth_rows(view: RenderedView, truth: GroundTruth) -> str:
    """The view's MOTChallenge rows: every frame's people whose feet are in its image, ids from 1."""
    lines = []
    for frame, positions_m in enumerate(truth.positions_m):
        present = np.flatnonzero(~np.isnan(positions_m[:, 0]))
        boxes, seen = person_boxes(
            view.calibration,
            view.image_size_px,
            positions_m[present],
            truth.heights_m[present],
            truth.widths_m[present],
        )
        for person, (left, top, width, height), (x_m, y_m) in zip(
            present[seen], boxes[seen], positions_m[present[seen]], strict=True
        ):
            lines.append(
                f"{frame + 1},{person + 1},{left:.3f},{top:.3f},{width:.3f},{height:.3f},1,{x_m:.6f},{y_m:.6f},0\n"
            )
    return "".join(lines)


def _dataset_document(
    name: str, frame_rate_hz: float, frames: int, area_m, views: list[RenderedView], seed: int, people_look: str
) -> str:
    """The dataset file naming the folder's files (relative to it), and how they were made in its comment."""
    data = {
        "name": name,
        "frame_rate_hz": float(frame_rate_hz),
        "frames": frames,
        "area_m": [list(corner) for corner in area_m],
        "ground_truth": _ground_truth_file(views[0]),
        "views": [
            {
                "name": view.name,
                "calibration": CALIBRATION_FILE,
                "calibration_view": view.name,
                "image_size_px": list(view.image_size_px),
                "video": f"{view.name}.avi",
                "ground_truth": _ground_truth_file(view),
            }
            for view in views
        ],
    }
    header = (
        f"# A rendered recording (ptztrack render, seed {seed}, people drawn as {people_look}): not a real one\n"
        "# (docs/reference/render.md). ground_truth: the first view's annotations (its people); each view's\n"
        "# own, boxes in its pixels, are its ground_truth.\n"
    )
    return header + yaml.safe_dump(data, sort_keys=False, default_flow_style=None)
