"""One closed-loop episode of a scenario: build its world, its policy and its tracker, run the loop."""

from collections.abc import Callable

import numpy as np

from ptztrack.builders.world import CameraSpec, DetectorSpec, build_world, resolve
from ptztrack.config import Scenario, ScenarioError
from ptztrack.loop import Episode, StepObserver, World, episode_seeds, run_loop
from ptztrack.roles import Policy, Tracker

PolicySpec = str | Policy | Callable[[Scenario, World], Policy]
"""A policy: a registered name, an object, or a factory ``(scenario, world) -> policy``."""
TrackerSpec = str | Tracker | Callable[[Scenario, World], Tracker]
"""A tracker: a registered name, an object, or a factory ``(scenario, world) -> tracker``."""


def episode_world(
    scenario: Scenario, seed: int, camera: CameraSpec | None = None, detector: DetectorSpec | None = None
) -> World:
    """The world that ``run_episode(scenario, any_policy, seed)`` runs in: the same people."""
    if scenario.cameras:
        raise ScenarioError(
            "the scenario lists cameras: a camera network runs as one (ptztrack.builders.network.run_network_episode)"
        )
    streams = episode_seeds(seed)
    scene_rng = np.random.default_rng(streams[0])
    return build_world(scenario, scene_rng, camera, detector, tracker_seed=streams[4], model_seed=streams[5])


def make_policy(spec: PolicySpec, scenario: Scenario, world: World) -> Policy:
    """A policy for one episode in ``world``: a fresh one for a name or a factory, ``spec`` itself for an object."""
    return resolve("policies", spec, scenario, world, "choose")


def make_tracker(spec: TrackerSpec | None, scenario: Scenario, world: World) -> Tracker:
    """A tracker for one episode in ``world``, by default ``tracker.kind`` of the scenario."""
    return resolve("trackers", spec or scenario.tracker.kind, scenario, world, "update")


def run_episode(
    scenario: Scenario,
    policy: PolicySpec,
    seed: int,
    world: World | None = None,
    *,
    camera: CameraSpec | None = None,
    detector: DetectorSpec | None = None,
    tracker: TrackerSpec | None = None,
    observer: StepObserver | None = None,
) -> Episode:
    """Run one closed-loop episode of the scenario: at most ``scenario.frames`` steps.

    policy : a name (``ptztrack.registry.names("policies")``), a policy object (its state carries
    over from earlier episodes, if it keeps any), or a factory ``(scenario, world) -> policy``.
    world : ``episode_world(scenario, seed)``, when the caller has built it already (it is built
    otherwise, with ``camera`` and ``detector`` in place of the scenario's when given); a caller
    that also draws the episode's views needs it, and building it may mean building a reference index.
    tracker : in place of the scenario's ``tracker.kind``.
    observer : called after every step (a live view, say): ``ptztrack.loop.StepObserver``.
    """
    world = world or episode_world(scenario, seed, camera, detector)
    return run_loop(world, make_policy(policy, scenario, world), make_tracker(tracker, scenario, world), seed, observer)
