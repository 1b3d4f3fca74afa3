"""ptztrack: multi-person tracking with cameras that move.

The public API is flat: ``from ptztrack import run_episode, scenario_from_dict``.
Names are imported on first use, so ``import ptztrack`` stays cheap.

Roles (protocols a new implementation follows): ``CameraBackend``, ``Detector``,
``Tracker``, ``Policy``; the data they exchange: ``Detections``,
``PeopleInView``, ``GroundTruth``, ``Tracks``, ``TrackUpdate``,
``DecisionContext``; names for implementations: ``register``,
``registered_names``.
"""

from importlib import import_module
from importlib.metadata import PackageNotFoundError, version
from typing import TYPE_CHECKING

try:
    __version__ = version("ptztrack")
except PackageNotFoundError:  # a source tree that was not installed
    __version__ = "0+unknown"

_HOME = {
    # configuration
    "Scenario": "ptztrack.config",
    "ScenarioError": "ptztrack.config",
    "load_scenario": "ptztrack.config",
    "scenario_from_dict": "ptztrack.config",
    "pets_scenario": "ptztrack.config",
    # the roles and their data
    "CameraBackend": "ptztrack.roles",
    "Detector": "ptztrack.roles",
    "Tracker": "ptztrack.roles",
    "Policy": "ptztrack.roles",
    "DecisionContext": "ptztrack.types",
    "Detections": "ptztrack.types",
    "GroundTruth": "ptztrack.types",
    "PeopleInView": "ptztrack.types",
    "Tracks": "ptztrack.types",
    "TrackUpdate": "ptztrack.types",
    # models
    "PTZCamera": "ptztrack.geometry.ptz",
    "ActionGrid": "ptztrack.camera.actions",
    # running
    "World": "ptztrack.loop",
    "Episode": "ptztrack.loop",
    "run_loop": "ptztrack.loop",
    "BuiltScene": "ptztrack.build.world",
    "build_world": "ptztrack.build.world",
    "episode_world": "ptztrack.build.episode",
    "run_episode": "ptztrack.build.episode",
    "Cell": "ptztrack.build.experiments",
    "synthetic_cells": "ptztrack.build.experiments",
    "recording_cells": "ptztrack.build.experiments",
    "run_cell": "ptztrack.build.experiments",
    "run_cells": "ptztrack.evaluate.executors",
    "summarise": "ptztrack.evaluate.tables",
    "format_table": "ptztrack.evaluate.tables",
    "episode_metrics": "ptztrack.evaluate.metrics",
    "write_outputs": "ptztrack.evaluate.report",
}
_RENAMED = {"register": ("ptztrack.registry", "register"), "registered_names": ("ptztrack.registry", "names")}

__all__ = ["__version__", *_HOME, *_RENAMED]

if TYPE_CHECKING:
    from ptztrack.build.episode import episode_world, run_episode
    from ptztrack.build.experiments import Cell, recording_cells, run_cell, synthetic_cells
    from ptztrack.build.world import BuiltScene, build_world
    from ptztrack.camera.actions import ActionGrid
    from ptztrack.config import Scenario, ScenarioError, load_scenario, pets_scenario, scenario_from_dict
    from ptztrack.evaluate.executors import run_cells
    from ptztrack.evaluate.metrics import episode_metrics
    from ptztrack.evaluate.report import write_outputs
    from ptztrack.evaluate.tables import format_table, summarise
    from ptztrack.geometry.ptz import PTZCamera
    from ptztrack.loop import Episode, World, run_loop
    from ptztrack.registry import names as registered_names
    from ptztrack.registry import register
    from ptztrack.roles import CameraBackend, Detector, Policy, Tracker
    from ptztrack.types import DecisionContext, Detections, GroundTruth, PeopleInView, Tracks, TrackUpdate


def __getattr__(name: str):
    if name in _HOME:
        return getattr(import_module(_HOME[name]), name)
    if name in _RENAMED:
        module, attribute = _RENAMED[name]
        return getattr(import_module(module), attribute)
    raise AttributeError(f"module 'ptztrack' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
