"""A camera network's parts: the scenario's ``cameras`` built into worlds, a joint or independent network
policy and one shared belief, which :func:`ptztrack.builders.episode.run_episode` runs.

Each camera is built as the one camera of a scenario of its own (:func:`camera_scenario`): its
mount, lens and detector, and the action grid turned to face the area. The people are drawn once,
from the episode's scene stream, so every camera sees the same walkers the one-camera run of the
seed would. The first camera's detector model draws from the one-camera run's stream, every other
camera's from a stream spawned after it.
"""

from collections.abc import Sequence
from dataclasses import replace
from typing import Literal

import numpy as np

from ptztrack.builders.factories import ekf_tracker, information_policy
from ptztrack.builders.world import BuiltScene, action_grid, build_scene, camera_world, ptz_camera
from ptztrack.config import AxisRange, MountedCamera, Scenario, ScenarioError
from ptztrack.control.information_policy import InformationMethod
from ptztrack.geometry.ptz import look_at
from ptztrack.loop.simulated import NetworkWorld
from ptztrack.loop.steps import World
from ptztrack.loop.streams import episode_streams
from ptztrack.network.policy import NetworkCamera, NetworkInformationPolicy
from ptztrack.network.shared_belief import SharedBelief
from ptztrack.track.tracker import EkfTracker

Coordination = Literal["joint", "independent"]


def camera_scenario(scenario: Scenario, mounted: MountedCamera) -> Scenario:
    """The scenario as its camera ``mounted`` alone would run it: its position, lens and detector (the
    scenario's where it gives none), the action grid's pan turned by the bearing of the area's centre,
    and no network."""
    camera = scenario.camera.model_copy(
        update={
            "position_m": mounted.position_m,
            "image_size_px": mounted.image_size_px or scenario.camera.image_size_px,
            "f_min_px": mounted.f_min_px or scenario.camera.f_min_px,
        }
    )
    alone = scenario.model_copy(
        update={"camera": camera, "detector": mounted.detector or scenario.detector, "cameras": ()}
    )
    centre_m = np.asarray(scenario.area_m) / 2
    bearing_deg = float(look_at(ptz_camera(alone), centre_m)[0])
    pan = scenario.actions.pan_deg
    turned = AxisRange(start=pan.start + bearing_deg, stop=pan.stop + bearing_deg, count=pan.count)
    return alone.model_copy(update={"actions": scenario.actions.model_copy(update={"pan_deg": turned})})


def network_world(scenario: Scenario, seed: int) -> NetworkWorld:
    """Every camera's world for the episode of ``seed``: the same people, seen by each camera."""
    if not scenario.cameras:
        raise ScenarioError("a camera network needs the scenario's cameras (cameras: a list of at least one)")
    streams = episode_streams(seed)
    views = [camera_scenario(scenario, mounted) for mounted in scenario.cameras]
    first = build_scene(views[0], np.random.default_rng(streams.scene))
    model_seeds = [streams.detector_model, *streams.detector_model.spawn(len(views) - 1)]
    worlds = []
    for view, model_seed in zip(views, model_seeds, strict=True):
        scene: BuiltScene = replace(first, camera=ptz_camera(view), grid=action_grid(view))
        worlds.append(camera_world(view, scene, model_seed=model_seed))
    return NetworkWorld(tuple(worlds))


def network_policy(
    scenario: Scenario, world: NetworkWorld, coordination: Coordination, method: InformationMethod
) -> NetworkInformationPolicy:
    """The network's policy: each PTZ camera's own information-gain policy ``method``, deciding
    ``coordination`` ('joint' or 'independent'); each fixed camera at its widest view of the area."""
    members = [
        (camera_scenario(scenario, mounted), camera, mounted.kind == "fixed")
        for mounted, camera in zip(scenario.cameras, world.cameras, strict=True)
    ]
    return policy_of_cameras(members, coordination, method)


def policy_of_cameras(
    members: Sequence[tuple[Scenario, World, bool]], coordination: Coordination, method: InformationMethod
) -> NetworkInformationPolicy:
    """The network policy of cameras given as (the scenario the camera alone runs, its world, whether it
    is fixed): each camera's information-gain policy ``method`` (a fixed camera's scores its one view,
    its world's start action), deciding ``coordination``."""
    cameras = [
        NetworkCamera(information_policy(alone, world, method), world.start_action if fixed else None)
        for alone, world, fixed in members
    ]
    return NetworkInformationPolicy(tuple(cameras), joint=coordination == "joint")


def network_tracker(scenario: Scenario, world: NetworkWorld) -> SharedBelief:
    """One belief, updated by each camera's EKF tracker (the scenario's tracker section) in turn."""
    members = [
        (camera_scenario(scenario, mounted), camera)
        for mounted, camera in zip(scenario.cameras, world.cameras, strict=True)
    ]
    return belief_of_cameras(members)


def belief_of_cameras(members: Sequence[tuple[Scenario, World]]) -> SharedBelief:
    """One belief, updated in turn by the EKF tracker of each camera given as (the scenario it alone
    runs, its world)."""
    trackers = []
    for alone, world in members:
        tracker = ekf_tracker(alone, world)
        # The scenario's validation keeps a network to the detector-measured EKF.
        assert isinstance(tracker, EkfTracker)
        trackers.append(tracker)
    return SharedBelief(tuple(trackers))
