"""Registration of PTZ views: the focal length of equation 2, the pose from a homography, bundle adjustment."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ptztrack.geometry import registration
from ptztrack.geometry.lens import Lens, pixel_directions
from ptztrack.geometry.ptz import PTZCamera, rotation_world_to_camera

CAMERA = PTZCamera((0.0, 0.0, 8.0), 640, 480, 500.0)
CENTRED = np.array([[1.0, 0.0, -320.0], [0.0, 1.0, -240.0], [0.0, 0.0, 1.0]])


def centred_homography(from_pose, to_pose):
    return CENTRED @ registration.rotation_homography(CAMERA, from_pose, to_pose) @ np.linalg.inv(CENTRED)


poses = st.tuples(st.floats(-40, 40), st.floats(5, 40), st.floats(1, 4))


@settings(max_examples=200, deadline=None)
@given(reference=poses, live=poses, scale=st.floats(0.1, 10))
def test_equation_2_gives_the_live_focal_length_from_any_rotation_homography(reference, live, scale):
    H = scale * centred_homography(reference, live)
    assert registration.focal_from_homography(H, reference[2] * CAMERA.f_min_px) == pytest.approx(
        live[2] * CAMERA.f_min_px, rel=1e-9
    )


def test_the_printed_equation_3_is_wrong_and_ours_is_right():
    reference, live = (0.0, 20.0, 1.0), (12.0, 25.0, 2.5)
    H = centred_homography(reference, live)
    f_m = CAMERA.f_min_px
    printed = (f_m**2 * (H[0, 0] ** 2 + H[0, 1] ** 2) + H[0, 2] ** 2) / (
        f_m**2 * (H[1, 0] ** 2 + H[1, 1] ** 2) + H[1, 1] ** 2
    )
    assert abs(np.sqrt(printed) - 2.5 * f_m) > 0.05 * 2.5 * f_m
    assert registration.focal_from_homography(H, f_m) == pytest.approx(2.5 * f_m, rel=1e-12)


@settings(max_examples=100, deadline=None)
@given(pan=st.floats(-170, 170), tilt=st.floats(-60, 60))
def test_pan_and_tilt_come_back_from_the_rotation(pan, tilt):
    assert registration.pose_from_rotation(rotation_world_to_camera(pan, tilt)) == pytest.approx((pan, tilt), abs=1e-9)


def test_bundle_adjustment_recovers_perturbed_poses_from_correspondences():
    rng = np.random.default_rng(0)
    truth = np.array([[p, t, z] for z in (1.0, 2.0) for t in (15.0, 25.0) for p in (-10.0, 0.0, 10.0)])
    matches = []
    for i in range(len(truth)):
        for j in range(i + 1, len(truth)):
            points_i = rng.uniform([0, 0], [640, 480], size=(60, 2))
            H = registration.rotation_homography(CAMERA, truth[i], truth[j])
            mapped = points_i @ H[:, :2].T + H[:, 2]
            points_j = mapped[:, :2] / mapped[:, 2:]
            inside = np.all((points_j >= 0) & (points_j <= [640, 480]), axis=1)
            if inside.sum() >= 12:
                matches.append((i, j, points_i[inside], points_j[inside] + rng.normal(0, 0.3, (inside.sum(), 2))))
    initial = truth + np.c_[rng.normal(0, 1.0, (len(truth), 2)), np.zeros(len(truth))]
    initial[:, 2] *= rng.uniform(0.95, 1.05, len(truth))
    initial[0] = truth[0]
    adjusted = registration.bundle_adjust(CAMERA, initial, matches)
    np.testing.assert_allclose(adjusted[:, :2], truth[:, :2], atol=0.02)
    np.testing.assert_allclose(adjusted[:, 2], truth[:, 2], rtol=2e-3)


def test_an_index_survives_a_save_and_load(tmp_path):
    rng = np.random.default_rng(1)
    index = registration.ReferenceIndex(
        poses=rng.normal(size=(3, 3)),
        keypoints_px=rng.uniform(0, 640, (30, 2)),
        descriptors=rng.uniform(0, 255, (30, 128)).astype(np.float32),
        view=np.repeat(np.arange(3), 10),
        image_size_px=(640, 480),
    )
    registration.save_index(tmp_path / "index.npz", index)
    loaded = registration.load_index(tmp_path / "index.npz")
    for name in ("poses", "keypoints_px", "descriptors", "view"):
        np.testing.assert_array_equal(getattr(loaded, name), getattr(index, name))
    assert loaded.image_size_px == (640, 480)
    with pytest.raises(ValueError, match="no such registration index"):
        registration.load_index(tmp_path / "missing.npz")
    (tmp_path / "bad.npz").write_bytes(b"not an index")
    with pytest.raises(ValueError, match="not a registration index"):
        registration.load_index(tmp_path / "bad.npz")


def test_the_ratio_test_compares_neighbours_within_one_reference_view():
    rng = np.random.default_rng(0)
    point, twin_a, twin_b = (rng.uniform(0, 100, 128) for _ in range(3))
    descriptors = np.vstack(
        [
            point,  # 0, view 0: the live feature's scene point
            point + 0.5,  # 1, view 1: the same point seen in an overlapping view
            twin_a,  # 2, view 2: two features alike, which no ratio test can tell apart
            twin_a + 0.5,  # 3, view 2
            twin_b,  # 4, view 0
            rng.uniform(0, 100, (6, 128)),  # 5-10: others, far from everything
        ]
    ).astype(np.float32)
    view = np.array([0, 1, 2, 2, 0, 0, 1, 1, 2, 2, 0])
    index = registration.ReferenceIndex(np.zeros((3, 3)), np.zeros((len(view), 2)), descriptors, view, (640, 480))
    # Each live feature lies as near to two reference features.
    live = np.vstack([point + 0.25, twin_a + 0.25]).astype(np.float32)
    pairs = {tuple(pair) for pair in registration.within_view_ratio_matches(index, live)}
    # A ratio test over all views at once would reject the first live feature: its second nearest
    # neighbour (1) is as near as its nearest (0).
    assert pairs == {(0, 0), (0, 1)}


def test_views_overlap_when_one_sees_much_of_the_other():
    poses = np.array([[0.0, 20.0, 1.0], [10.0, 20.0, 1.0], [0.0, 20.0, 3.0], [130.0, 20.0, 1.0], [70.0, 20.0, 1.0]])
    pairs = registration.overlapping_pairs(CAMERA, poses)
    # A zoomed view inside a wide one overlaps it fully, though it covers a ninth of it; a view
    # turned 130 degrees away overlaps nothing, and one 60 degrees away (of 65 seen) too little.
    assert pairs == [(0, 1), (0, 2), (1, 2)]


def test_only_views_tied_to_the_first_through_matched_pairs_are_kept():
    matches = [(0, 1, None, None), (1, 3, None, None), (2, 4, None, None)]
    np.testing.assert_array_equal(registration.tied_to_first(6, matches), [True, True, False, True, False, False])


def test_the_refinement_recovers_a_rolled_distorted_view_from_its_correspondences():
    rng = np.random.default_rng(2)
    truth, lens = np.array([12.0, 22.0, 1.3]), Lens(roll_deg=1.7, k1=-0.12)
    # Directions spread over the live view, seen through its lens, with SIFT-like noise.
    pixels = rng.uniform([0, 0], [640, 480], size=(100, 2))
    directions = pixel_directions(CAMERA, truth, lens, pixels)
    live_px = pixels + rng.normal(0.0, 0.3, pixels.shape)
    # From the homography's guess, which knows neither roll nor distortion.
    initial = np.array([12.4, 21.7, 1.3 * 1.02, 0.0, 0.0])
    refined = registration.refine_view(CAMERA, directions, live_px, initial)
    np.testing.assert_allclose(refined[:2], truth[:2], atol=0.01)
    assert refined[2] == pytest.approx(truth[2], rel=1e-3)
    assert refined[3] == pytest.approx(1.7, abs=0.01)
    assert refined[4] == pytest.approx(-0.12, abs=0.01)
    # A narrow view's corners lie near its axis: its distortion is left to the prior (0), harmlessly.
    narrow, narrow_lens = np.array([12.0, 22.0, 4.0]), Lens(roll_deg=-1.0, k1=-0.05)
    directions = pixel_directions(CAMERA, narrow, narrow_lens, pixels)
    refined = registration.refine_view(CAMERA, directions, live_px, np.array([12.1, 22.1, 4.04, 0.0, 0.0]))
    assert abs(refined[4]) < 0.05
    assert refined[2] == pytest.approx(4.0, rel=2e-3) and refined[3] == pytest.approx(-1.0, abs=0.02)
