"""One closed-loop episode of a scenario, one camera or a network of them: build its world, its policy and
its tracker, run the simulated loop."""

from collections.abc import Callable
from functools import partial
from typing import Literal, TypedDict, Unpack, cast, get_args, overload

import numpy as np

from ptztrack.builders.network import Coordination, network_policy, network_tracker, network_world
from ptztrack.builders.world import CameraSpec, DetectorSpec, build_world, resolve
from ptztrack.config import Scenario, ScenarioError
from ptztrack.control.information_policy import InformationMethod
from ptztrack.loop.camera_actors import RayCameras
from ptztrack.loop.simulated import InProcessCameras, NetworkEpisode, NetworkWorld, run_loop, run_network_loop
from ptztrack.loop.steps import Episode, StepObserver, World
from ptztrack.loop.streams import episode_streams
from ptztrack.roles import NetworkPolicy, NetworkTracker, Policy, Tracker

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
            "the scenario lists cameras: a camera network's world is ptztrack.builders.network.network_world's"
        )
    streams = episode_streams(seed)
    scene_rng = np.random.default_rng(streams.scene)
    return build_world(
        scenario, scene_rng, camera, detector, tracker_seed=streams.tracker, model_seed=streams.detector_model
    )


def make_policy(spec: PolicySpec, scenario: Scenario, world: World) -> Policy:
    """A policy for one episode in ``world``: a fresh one for a name or a factory, ``spec`` itself for an object."""
    return resolve("policies", spec, scenario, world, "choose")


def make_tracker(spec: TrackerSpec | None, scenario: Scenario, world: World) -> Tracker:
    """A tracker for one episode in ``world``, by default ``tracker.kind`` of the scenario."""
    return resolve("trackers", spec or scenario.tracker.kind, scenario, world, "update")


class EpisodeOptions(TypedDict, total=False):
    """:func:`run_episode`'s keywords."""

    camera: CameraSpec | None
    detector: DetectorSpec | None
    tracker: TrackerSpec | NetworkTracker | None
    observer: StepObserver | None
    coordination: Coordination
    cameras_on: Literal["serial", "ray"]
    cameras_per_actor: int


@overload
def run_episode(
    scenario: Scenario, policy: PolicySpec, seed: int, world: World, **options: Unpack[EpisodeOptions]
) -> Episode: ...
@overload
def run_episode(
    scenario: Scenario, policy: str | NetworkPolicy, seed: int, world: NetworkWorld, **options: Unpack[EpisodeOptions]
) -> NetworkEpisode: ...
@overload
def run_episode(
    scenario: Scenario,
    policy: PolicySpec | NetworkPolicy,
    seed: int,
    world: None = None,
    **options: Unpack[EpisodeOptions],
) -> Episode | NetworkEpisode: ...


def run_episode(
    scenario: Scenario,
    policy: PolicySpec | NetworkPolicy,
    seed: int,
    world: World | NetworkWorld | None = None,
    *,
    camera: CameraSpec | None = None,
    detector: DetectorSpec | None = None,
    tracker: TrackerSpec | NetworkTracker | None = None,
    observer: StepObserver | None = None,
    coordination: Coordination = "joint",
    cameras_on: Literal["serial", "ray"] = "serial",
    cameras_per_actor: int = 1,
) -> Episode | NetworkEpisode:
    """Run one closed-loop episode of the scenario, at most ``scenario.frames`` steps, with one camera or
    many: the scenario's camera alone, or its ``cameras`` (or a ``world`` of several) as a network with one
    ground belief; an :class:`~ptztrack.loop.steps.Episode`, or a
    :class:`~ptztrack.loop.simulated.NetworkEpisode` for a network.

    policy : one camera's: a name (``ptztrack.registry.names("policies")``), a policy object (its state
    carries over from earlier episodes, if it keeps any), or a factory ``(scenario, world) -> policy``. A
    network's: 'intg' or 'smpl' (each PTZ camera's information-gain policy deciding ``coordination``,
    :func:`ptztrack.builders.network.network_policy`) or a network policy object.
    world : ``episode_world(scenario, seed)`` (``network_world`` for a network), when the caller has built
    it already (it is built otherwise, with ``camera`` and ``detector`` in place of the scenario's when
    given); a caller that also draws the episode's views needs it, and building it may mean building a
    reference index.
    tracker : in place of the scenario's ``tracker.kind`` (a network: in place of its one belief).
    observer : called after every step (a live view, say): ``ptztrack.loop.steps.StepObserver``.
    cameras_on : where a network's cameras capture and detect: 'serial' in this process, 'ray' as actors on
    a Ray cluster (:class:`~ptztrack.loop.camera_actors.RayCameras`, ``cameras_per_actor`` cameras to an
    actor); the episode is the same.
    """
    if isinstance(world, NetworkWorld) or (world is None and scenario.cameras):
        network = world if isinstance(world, NetworkWorld) else network_world(scenario, seed)
        if isinstance(policy, str) and policy in get_args(InformationMethod):
            policy = network_policy(scenario, network, coordination, cast(InformationMethod, policy))
        elif isinstance(policy, str):
            raise ScenarioError(f"a camera network decides by intg or smpl, not {policy!r}")
        belief = network_tracker(scenario, network) if tracker is None else cast(NetworkTracker, tracker)
        fleet = partial(RayCameras, cameras_per_actor=cameras_per_actor) if cameras_on == "ray" else InProcessCameras
        return run_network_loop(network, cast(NetworkPolicy, policy), belief, seed, fleet, observer)
    alone = world or episode_world(scenario, seed, camera, detector)
    chosen = make_policy(cast(PolicySpec, policy), scenario, alone)
    return run_loop(alone, chosen, make_tracker(cast(TrackerSpec | None, tracker), scenario, alone), seed, observer)
