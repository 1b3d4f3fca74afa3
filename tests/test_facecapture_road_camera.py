"""The road camera: units and their blobs zoomed out, the followed unit zoomed in, and the face-capture model."""

import numpy as np
import pytest

from ptztrack.facecapture.parameters import RoadCameraParameters
from ptztrack.facecapture.road_camera import RoadCamera, Zoom
from ptztrack.facecapture.roads import RoadScene

CENTRE_M = (20.0, 20.0)


def straight_scene(starts_m, headings, steps, group_id=None, speed_m_s=1.0, rate_hz=5.0):
    """Walkers on straight lines from ``starts_m`` (N, 2) along unit ``headings`` (N, 2), in a 40 m area."""
    headings = np.asarray(headings, float) / np.linalg.norm(headings, axis=1, keepdims=True)
    time_s = np.arange(steps)[:, None, None] / rate_hz
    positions_m = np.asarray(starts_m, float)[None] + headings[None] * speed_m_s * time_s
    heading = np.broadcast_to(headings, positions_m.shape).copy()
    group_id = np.full(positions_m.shape[:2], -1) if group_id is None else group_id
    return RoadScene(positions_m, group_id, heading, np.full(len(starts_m), speed_m_s), rate_hz, 40.0, 10.0)


def camera(scene, seed=0):
    return RoadCamera(scene, CENTRE_M, np.random.default_rng(seed))


def test_zoomed_out_it_sees_every_unit_and_keeps_its_blob_until_it_joins_or_splits():
    group_id = np.full((30, 3), -1)
    group_id[10:20, :2] = 0  # 0 and 1 walk together for steps 10-19
    scene = straight_scene([[5, 5], [5, 5], [30, 10]], [[1, 1], [1, 1], [0, 1]], 30, group_id)
    cam = camera(scene)
    observations = [cam.observe(step) for step in range(30)]
    counts = [sorted(unit.count for unit in obs.units) for obs in observations]
    assert counts[:10] == [[1, 1, 1]] * 10 and counts[10:20] == [[1, 2]] * 10 and counts[20:] == [[1, 1, 1]] * 10
    blobs = [{unit.blob for unit in obs.units} for obs in observations]
    assert blobs[0] == blobs[9] and blobs[10] == blobs[19] and blobs[20] == blobs[29]
    (group,) = [unit for unit in observations[10].units if unit.count == 2]
    assert set(group.came_from) == blobs[9] - blobs[10], "the group came from the two walkers"
    after = [unit for unit in observations[20].units if unit.came_from]
    assert len(after) == 2 and all(unit.came_from == (group.blob,) for unit in after)
    assert all(not unit.came_from for obs in observations[1:] for unit in obs.units if unit.blob in blobs[obs.step - 1])
    (third,) = [unit for unit in observations[29].units if cam.blobs[unit.blob].members == {2}]
    np.testing.assert_allclose(third.position_m, scene.positions_m[29, 2])
    np.testing.assert_allclose(third.heading, [0, 1])
    assert {cam.blobs[group.blob].members} == {frozenset({0, 1})}
    assert (cam.blobs[group.blob].first_step, cam.blobs[group.blob].steps) == (10, 10)


def test_zoomed_in_it_sees_only_the_followed_unit_and_the_others_come_back_as_new_blobs():
    scene = straight_scene([[5, 5], [10, 5], [30, 10]], [[1, 1], [1, 1], [0, 1]], 20)
    cam = camera(scene)
    before = {unit.blob: unit for unit in cam.observe(0).units}
    (followed,) = [blob for blob in before if cam.blobs[blob].members == {2}]
    zoom = Zoom(followed, tuple(scene.positions_m[5, 2]), capture_step=5)
    zoomed = [cam.observe(step, zoom) for step in range(1, 6)]
    assert all([unit.blob for unit in obs.units] == [followed] and obs.zoomed_in for obs in zoomed)
    back = cam.observe(6)
    assert not back.zoomed_in and len(back.units) == 3
    assert all(unit.blob not in before and not unit.came_from for unit in back.units if unit.blob != followed)


def capture_at(scene, step, aim_m, seed=0):
    """The face capture of walker 0 at ``step`` with the camera aimed at ``aim_m``, or None."""
    cam = camera(scene, seed)
    (blob,) = [unit.blob for unit in cam.observe(0).units if cam.blobs[unit.blob].members == {0}]
    zoom = Zoom(blob, aim_m, capture_step=step)
    return [cam.observe(s, zoom) for s in range(1, step + 1)][-1].capture


def test_a_face_is_captured_when_aimed_right_and_never_from_behind_or_in_a_group():
    towards = straight_scene([[5, 20]], [[1, 0]], 20)
    capture = capture_at(towards, 10, towards.positions_m[10, 0])
    assert capture is not None and capture.face == 0
    away = straight_scene([[25, 20]], [[1, 0]], 20)
    assert capture_at(away, 10, away.positions_m[10, 0]) is None
    group_id = np.full((20, 2), -1)
    group_id[5:] = 0
    grouped = straight_scene([[5, 20], [5, 20]], [[1, 0], [1, 0]], 20, group_id)
    assert capture_at(grouped, 10, grouped.positions_m[10, 0]) is None
    assert (
        capture_at(towards, 10, towards.positions_m[10, 0] + [0, 6 * RoadCameraParameters.zoomed_half_width_m]) is None
    )


def test_the_capture_succeeds_with_probability_exp_of_minus_half_the_squared_error_in_half_widths():
    scene = straight_scene([[5, 20]], [[1, 0]], 5)
    aim_m = scene.positions_m[3, 0] + [0, RoadCameraParameters.zoomed_half_width_m]  # off by one half-width
    captured = np.mean([capture_at(scene, 3, aim_m, seed) is not None for seed in range(600)])
    assert captured == pytest.approx(np.exp(-0.5), abs=4 * np.sqrt(0.61 * 0.39 / 600))


def test_the_same_seed_gives_the_same_observations_and_steps_come_in_order():
    scene = straight_scene([[5, 20], [20, 5]], [[1, 0], [0, 1]], 10)
    first, second = camera(scene, 3), camera(scene, 3)
    assert [first.observe(step) for step in range(10)] == [second.observe(step) for step in range(10)]
    with pytest.raises(ValueError, match="step by step"):
        camera(scene).observe(1)
