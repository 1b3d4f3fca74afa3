import numpy as np

from ptztrack.builders.episode import run_episode
from ptztrack.builders.network import camera_scenario, network_world
from ptztrack.config import scenario_from_dict
from ptztrack.control.baselines import area_coverage
from ptztrack.evaluate.metrics import episode_metrics, network_metrics

SOUTH, NORTH, EAST = (7.5, -6.0, 2.5), (7.5, 21.0, 2.5), (21.0, 7.5, 4.0)


def test_a_network_of_the_one_default_camera_is_the_one_camera_run():
    """Same people, same detector luck, same decisions: the network loop reuses the one-camera steps."""
    one = scenario_from_dict({"frames": 15})
    network = scenario_from_dict({"frames": 15, "cameras": [{"position_m": SOUTH}]})
    alone, together = run_episode(one, "intg", 4), run_episode(network, "intg", 4)
    np.testing.assert_array_equal(alone.actions, together.cameras[0].actions)
    for a, b in zip(alone.tracks, together.tracks, strict=True):
        np.testing.assert_array_equal(a.ids, b.ids)
        np.testing.assert_array_equal(a.mean, b.mean)
    assert episode_metrics(alone) == network_metrics(together)


def test_each_camera_faces_the_area_with_its_own_lens_and_detector_and_a_fixed_one_stays():
    scenario = scenario_from_dict(
        {
            "frames": 8,
            "cameras": [
                {"position_m": SOUTH},
                {"kind": "fixed", "position_m": EAST, "f_min_px": 250.0, "detector": {"kind": "ideal"}},
            ],
        }
    )
    east = camera_scenario(scenario, scenario.cameras[1])
    assert east.camera.f_min_px == 250.0 and east.detector.kind == "ideal" and east.cameras == ()
    assert east.camera.image_size_px == scenario.camera.image_size_px
    np.testing.assert_allclose((east.actions.pan_deg.start, east.actions.pan_deg.stop), (-90 - 45, -90 + 45), atol=1e-9)
    world = network_world(scenario, 1)
    for camera in world.cameras:
        assert camera.truth is world.truth
        assert area_coverage(camera.camera, camera.grid.poses[camera.start_action], world.area_polygon_m) > 0.8
    episode = run_episode(scenario, "intg", 1)
    assert np.all(episode.cameras[1].actions == world.cameras[1].start_action)
    assert len(set(episode.cameras[0].actions.tolist())) > 1


def test_the_same_seed_gives_the_same_network_episode():
    scenario = scenario_from_dict({"frames": 10, "cameras": [{"position_m": SOUTH}, {"position_m": NORTH}]})
    first, again = (run_episode(scenario, "smpl", 2, coordination="joint") for _ in range(2))
    for a, b in zip(first.cameras, again.cameras, strict=True):
        np.testing.assert_array_equal(a.actions, b.actions)
    for a, b in zip(first.tracks, again.tracks, strict=True):
        np.testing.assert_array_equal(a.mean, b.mean)
