"""An episode's random streams (:mod:`ptztrack.loop.streams`) draw apart, and the world draws from its own.

A run's users of random numbers (the scene, the detector frame by frame, the policy, the landing errors, the
tracker, the detector model's draws) each have their own stream, so that changing one (another policy,
another tracker) leaves the others' draws as they were: common random numbers across runs."""

from dataclasses import fields

import numpy as np

from ptztrack.builders.episode import episode_world
from ptztrack.config import scenario_from_dict
from ptztrack.loop.streams import episode_streams

USERS = {"scene", "detector", "policy", "landing", "tracker", "detector_model"}


def draws(seed_sequence) -> tuple:
    return tuple(np.random.default_rng(seed_sequence).random(4))


def test_the_streams_of_a_seed_its_detectors_frames_and_another_seeds_streams_all_draw_apart():
    streams = episode_streams(7)
    named = {field.name: getattr(streams, field.name) for field in fields(streams)}
    assert set(named) >= USERS
    frames = {f"detector frame {step}": seeds for step, seeds in enumerate(episode_streams(7).detector.spawn(3))}
    other_seed = {f"{name} of seed 8": getattr(episode_streams(8), name) for name in named}
    drawn = {name: draws(seeds) for name, seeds in {**named, **frames, **other_seed}.items()}
    assert len(set(drawn.values())) == len(drawn)
    # The same seed draws the same.
    assert all(draws(getattr(episode_streams(7), name)) == drawn[name] for name in named)


def test_the_world_of_an_episode_seeds_its_detector_model_and_tracker_with_their_own_streams():
    world = episode_world(scenario_from_dict({"frames": 3, "detector": {"kind": "realistic"}}), 7)
    streams = episode_streams(7)
    assert world.detector_model is not None and world.tracker_seed is not None
    seeded_with = world.detector_model.rng.bit_generator.seed_seq
    assert (seeded_with.entropy, seeded_with.spawn_key) == (7, streams.detector_model.spawn_key)
    assert draws(world.tracker_seed) == draws(streams.tracker)


def test_the_streams_are_the_seeds_children_in_their_order_and_fresh_at_every_call():
    streams = episode_streams(7)
    assert [field.name for field in fields(streams)] == [
        "scene", "detector", "policy", "landing", "tracker", "detector_model",
    ]  # fmt: skip
    # A stream added later leaves the earlier ones as they were: each is the seed's child at its place.
    children = np.random.SeedSequence(7).spawn(len(fields(streams)))
    assert [draws(getattr(streams, field.name)) for field in fields(streams)] == [draws(c) for c in children]
    # What one user spawns does not move another's.
    streams.detector.spawn(3)
    assert episode_streams(7).detector.n_children_spawned == 0
