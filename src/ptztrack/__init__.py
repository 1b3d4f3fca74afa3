"""ptztrack: multi-person tracking with cameras that move.

The public API is flat: ``from ptztrack import run_episode, scenario_from_dict``. One runner per mode,
each with one camera or many: ``run_episode`` (simulated) and ``run_live_episode`` (live cameras); and
``serve`` (with ``load_service_config``), the cameras of a service until stopped.
Names are imported on first use (from the modules named relative to this package), so
``import ptztrack`` stays cheap.

Roles (protocols a new implementation follows): ``CameraBackend``, ``Detector``,
``Tracker``, ``Policy``; the data they exchange: ``Detections``,
``PeopleInView``, ``GroundTruth``, ``Tracks``, ``TrackUpdate``,
``DecisionContext``; names for implementations: ``register``,
``registered_names``.
"""

import os
from importlib import import_module
from typing import TYPE_CHECKING

from ptztrack.names import VERSION as __version__

# FFmpeg's decoders print several lines of their own for each damaged frame (a truncated video's last);
# every bad video gets one line of ptztrack's. OpenCV reads this once, when it first uses FFmpeg.
os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")

_HOME = {
    # configuration
    "Scenario": ".config",
    "ScenarioError": ".config",
    "load_scenario": ".config",
    "scenario_from_dict": ".config",
    "load_dataset": ".config",
    "pets_scenario": ".builders.recording",
    "pets_follow_scenario": ".builders.recording",
    "dataset_scenario": ".builders.recording",
    "render_dataset": ".builders.render",
    # the roles and their data
    "CameraBackend": ".roles",
    "Detector": ".roles",
    "Tracker": ".roles",
    "Policy": ".roles",
    "DecisionContext": ".types",
    "Detections": ".types",
    "GroundTruth": ".types",
    "PeopleInView": ".types",
    "Tracks": ".types",
    "TrackUpdate": ".types",
    # models
    "PTZCamera": ".geometry.ptz",
    "ActionGrid": ".camera.actions",
    # running
    "World": ".loop.steps",
    "Episode": ".loop.steps",
    "NetworkWorld": ".loop.simulated",
    "NetworkEpisode": ".loop.simulated",
    "BuiltScene": ".builders.world",
    "build_world": ".builders.world",
    "episode_world": ".builders.episode",
    "network_world": ".builders.network",
    "run_episode": ".builders.episode",
    "run_live_episode": ".builders.live",
    "serve": ".service",
    "load_service_config": ".service",
    "network_metrics": ".evaluate.metrics",
    "Cell": ".experiments.cells",
    "synthetic_cells": ".experiments.ptz_tables",
    "recording_cells": ".experiments.ptz_tables",
    "cell_metrics": ".experiments.cells",
    "execute_cells": ".loop.executors",
    "summarise": ".experiments.ptz_tables",
    "format_table": ".experiments.ptz_tables",
    "episode_metrics": ".evaluate.metrics",
    "write_outputs": ".evaluate.report",
    "score_files": ".evaluate.score",
}
_RENAMED = {"register": (".registry", "register"), "registered_names": (".registry", "names")}

__all__ = ["__version__", *_HOME, *_RENAMED]

if TYPE_CHECKING:
    from .builders.episode import episode_world, run_episode
    from .builders.live import run_live_episode
    from .builders.network import network_world
    from .builders.recording import dataset_scenario, pets_follow_scenario, pets_scenario
    from .builders.render import render_dataset
    from .builders.world import BuiltScene, build_world
    from .camera.actions import ActionGrid
    from .config import Scenario, ScenarioError, load_dataset, load_scenario, scenario_from_dict
    from .evaluate.metrics import episode_metrics, network_metrics
    from .evaluate.report import write_outputs
    from .evaluate.score import score_files
    from .experiments.cells import Cell, cell_metrics
    from .experiments.ptz_tables import format_table, recording_cells, summarise, synthetic_cells
    from .geometry.ptz import PTZCamera
    from .loop.executors import execute_cells
    from .loop.simulated import NetworkEpisode, NetworkWorld
    from .loop.steps import Episode, World
    from .registry import names as registered_names
    from .registry import register
    from .roles import CameraBackend, Detector, Policy, Tracker
    from .service import load_service_config, serve
    from .types import DecisionContext, Detections, GroundTruth, PeopleInView, Tracks, TrackUpdate


def __getattr__(name: str):
    if name in _HOME:
        return getattr(import_module(_HOME[name], __name__), name)
    if name in _RENAMED:
        module, attribute = _RENAMED[name]
        return getattr(import_module(module, __name__), attribute)
    raise AttributeError(f"module 'ptztrack' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
