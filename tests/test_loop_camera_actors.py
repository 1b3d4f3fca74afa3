import importlib.util

import numpy as np
import pytest

from ptztrack.builders.episode import run_episode
from ptztrack.config import scenario_from_dict
from ptztrack.loop.executors import connect_ray

pytestmark = [
    pytest.mark.skipif(importlib.util.find_spec("ray") is None, reason="needs the ray extra"),
    pytest.mark.xdist_group("ray"),
]

# Three PTZ cameras around the default area (south, north, east); a few people, a few steps.
NETWORK = {
    "frames": 6,
    "people": {"count": 8},
    "cameras": [
        {"position_m": (7.5, -6.0, 2.5)},
        {"position_m": (7.5, 21.0, 2.5)},
        {"position_m": (21.0, 7.5, 4.0)},
    ],
}


@pytest.fixture(scope="module")
def local_ray():
    ray = connect_ray(num_cpus=2)
    yield ray
    ray.shutdown()


@pytest.mark.slow
def test_the_cameras_in_ray_actors_give_the_in_process_episode(local_ray):
    """Each worker takes its streams into its actor, so the episode is the same bit for bit; two actors
    for three cameras, so one actor hosts two."""
    assert [node["NodeManagerAddress"] for node in local_ray.nodes()] == ["127.0.0.1"]
    scenario = scenario_from_dict(NETWORK)
    here = run_episode(scenario, "intg", 5)
    there = run_episode(scenario, "intg", 5, cameras_on="ray", cameras_per_actor=2)
    for a, b in zip(here.cameras, there.cameras, strict=True):
        np.testing.assert_array_equal(a.actions, b.actions)
        np.testing.assert_array_equal(a.poses, b.poses)
        for seen, seen_there in zip(a.detections, b.detections, strict=True):
            np.testing.assert_array_equal(seen.feet_px, seen_there.feet_px)
    assert sum(len(tracks) for tracks in here.tracks) > 0
    for a, b in zip(here.tracks, there.tracks, strict=True):
        np.testing.assert_array_equal(a.ids, b.ids)
        np.testing.assert_array_equal(a.mean, b.mean)
        np.testing.assert_array_equal(a.covariance, b.covariance)
    assert here.update_s.shape == there.step_s.shape == (6,)
