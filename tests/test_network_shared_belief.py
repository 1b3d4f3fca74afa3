import numpy as np

from ptztrack.geometry.ptz import PTZCamera, apply_homography, feet_jacobian, ground_to_image, look_at
from ptztrack.network.shared_belief import SharedBelief
from ptztrack.track import kalman
from ptztrack.track.lifecycle import start_ground_tracks
from ptztrack.track.parameters import TrackerParameters
from ptztrack.track.tracker import EkfTracker
from ptztrack.types import Detections

SOUTH = PTZCamera((7.5, -6.0, 2.5), 640, 480, 325.0)
EAST = PTZCamera((21.0, 7.5, 4.0), 640, 480, 325.0)
PERSON_M = np.array([6.0, 8.0])
V_SOUTH, V_EAST = 4.0 * np.eye(2), np.diag([9.0, 1.0])


def network(tracks=None) -> SharedBelief:
    # No camera counts on finding anybody: a miss takes no existence away (the tracker's own tests check that).
    trackers = tuple(
        EkfTracker(camera, 0.2, V, TrackerParameters(), lambda mean, cov, pose: np.zeros(len(mean)))
        for camera, V in ((SOUTH, V_SOUTH), (EAST, V_EAST))
    )
    return SharedBelief(trackers) if tracks is None else SharedBelief(trackers, tracks)


def seen_at(camera: PTZCamera, ground_m) -> tuple[np.ndarray, Detections]:
    """The view centred on ``ground_m`` and the detection of feet exactly there."""
    pose = look_at(camera, ground_m, 2.0)
    feet_px = apply_homography(ground_to_image(camera, pose), np.reshape(ground_m, (1, 2)))
    return pose, Detections(feet_px, np.array([80.0]), np.array([0]))


def test_updating_in_turn_is_the_joint_update_of_independent_linear_measurements():
    """Two linear measurements of one state, independent noises: in turn, in either order, they give the
    closed form P+^-1 = P^-1 + sum C^T V^-1 C, x+ = x + P+ sum C^T V^-1 (z - C x)."""
    rng = np.random.default_rng(3)
    root = rng.normal(size=(4, 4))
    P, x = root @ root.T + np.eye(4), rng.normal(size=4)
    C = rng.normal(size=(2, 2, 4))
    V = np.stack([V_SOUTH, V_EAST])
    z = rng.normal(size=(2, 2))
    information = np.linalg.inv(P) + sum(C[k].T @ np.linalg.inv(V[k]) @ C[k] for k in range(2))
    P_joint = np.linalg.inv(information)
    x_joint = x + P_joint @ sum(C[k].T @ np.linalg.inv(V[k]) @ (z[k] - C[k] @ x) for k in range(2))
    for order in ((0, 1), (1, 0)):
        mean, covariance = x[None], P[None]
        for k in order:
            mean, covariance = kalman.update(mean, covariance, (z[k] - C[k] @ mean[0])[None], C[k][None], V[k])
        np.testing.assert_allclose(covariance[0], P_joint, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(mean[0], x_joint, rtol=1e-9, atol=1e-12)


def test_two_cameras_update_one_track_through_their_own_poses_and_noises_as_the_joint_update():
    """A detection where the track is predicted leaves its mean, so both cameras linearise at the same
    state and the shared belief's covariance is the joint closed form with each camera's Jacobian and V."""
    prior = start_ground_tracks(PERSON_M[None], np.eye(2)[None], 0.9, first_id=0, existence=0.9)
    belief = network(prior)
    poses = {}
    for index, camera in enumerate((SOUTH, EAST)):
        poses[index], detections = seen_at(camera, PERSON_M)
        belief.updater(index).update(detections, poses[index], lambda: None)
    information = np.linalg.inv(prior.covariance[0])
    for index, (camera, V) in enumerate(((SOUTH, V_SOUTH), (EAST, V_EAST))):
        C = np.concatenate([feet_jacobian(camera, poses[index], PERSON_M[None])[0], np.zeros((2, 2))], axis=-1)
        information += C.T @ np.linalg.inv(V) @ C
    assert len(belief.tracks) == 1 and belief.tracks.hits[0] == 3
    np.testing.assert_allclose(belief.tracks.mean[0, :2], PERSON_M, atol=1e-9)
    np.testing.assert_allclose(belief.tracks.covariance[0], np.linalg.inv(information), rtol=1e-7, atol=1e-12)


def test_a_new_person_seen_by_two_cameras_is_one_track_and_ids_stay_unique():
    belief = network()
    belief.predict()
    for index, camera in enumerate((SOUTH, EAST)):
        pose, detections = seen_at(camera, PERSON_M)
        belief.updater(index).update(detections, pose, lambda: None)
    assert belief.tracks.ids.tolist() == [0] and belief.tracks.hits.tolist() == [2]
    other_m = PERSON_M + [4.0, 3.0]
    pose, detections = seen_at(EAST, other_m)
    belief.predict()
    belief.updater(1).update(detections, pose, lambda: None)
    assert sorted(belief.tracks.ids.tolist()) == [0, 1]


def test_each_cameras_picture_weighs_the_time_since_that_cameras_last_one():
    """The belief's clock runs for every camera: once a step, each camera's picture is a whole look;
    with the cameras' pictures interleaved 0.05 s apart after that, each camera's picture 0.1 s after
    its last is half of one (a 0.2 s step), the first one, 0.05 s after, a quarter."""
    belief = network()
    for _ in range(2):
        belief.predict()
        for index, camera in enumerate((SOUTH, EAST)):
            assert belief.cameras[index].look_weight() == 1.0
            pose, detections = seen_at(camera, PERSON_M)
            belief.updater(index).update(detections, pose, lambda: None)
    weights = []
    for index, camera in (0, SOUTH), (1, EAST), (0, SOUTH), (1, EAST):
        belief.predict(0.05)
        weights.append(belief.cameras[index].look_weight())
        pose, detections = seen_at(camera, PERSON_M)
        belief.updater(index).update(detections, pose, lambda: None)
    np.testing.assert_allclose(weights, [0.25, 0.5, 0.5, 0.5])


def test_a_track_only_one_camera_that_needs_a_second_has_detected_is_reported_once_another_detects_it():
    """EAST needs a second camera: its person alone is not reported, SOUTH's is; after SOUTH detects
    EAST's person once, both are. Two cameras that both need a second one report a person both detect."""
    beside_m = PERSON_M + [4.0, 3.0]
    plain, ruled, both = network(), network(), network()
    ruled.needs_a_second_camera = frozenset({1})
    both.needs_a_second_camera = frozenset({0, 1})
    for _ in range(5):
        for belief in (plain, ruled, both):
            belief.predict()
            for index, camera, person_m in ((1, EAST, PERSON_M), (0, SOUTH, beside_m)):
                pose, detections = seen_at(camera, person_m)
                belief.updater(index).update(detections, pose, lambda: None)
    east_only, south_only = plain.tracks.ids.tolist()
    assert sorted(plain.reported().ids.tolist()) == [east_only, south_only]
    assert ruled.reported().ids.tolist() == [south_only]
    assert both.reported().ids.tolist() == []
    for belief in (ruled, both):
        belief.predict()
        pose, detections = seen_at(SOUTH, PERSON_M)
        belief.updater(0).update(detections, pose, lambda: None)
    assert sorted(ruled.reported().ids.tolist()) == [east_only, south_only]
    assert both.reported().ids.tolist() == [east_only]
