import pickle
from pathlib import Path

import numpy as np
import pytest

from ptztrack.camera.virtual import MM_PER_M, virtual_ptz
from ptztrack.geometry.calibration import load_pinhole, project_pinhole, standing_height_px
from ptztrack.geometry.ptz import apply_homography, ground_to_image, image_to_ground
from ptztrack.scene.pets import load_mot_ground_truth

EXCERPT = Path(__file__).parent / "data" / "pets_s2l1_excerpt"
RECORDING = load_pinhole(EXCERPT / "pinhole.json")
VIRTUAL, CENTRE_POSE = virtual_ptz(RECORDING)
POSES = [CENTRE_POSE, CENTRE_POSE + [4.0, 2.0, 1.0], CENTRE_POSE + [-6.0, -1.5, 3.0]]


def test_the_virtual_camera_stands_at_the_recording_camera_and_sees_its_frame_at_zoom_1():
    centre_mm = -RECORDING.R.T @ RECORDING.t
    np.testing.assert_allclose(np.array(VIRTUAL.camera.position_m) * MM_PER_M, centre_mm)
    assert VIRTUAL.camera.f_min_px == pytest.approx(RECORDING.K[0, 0] * 160 / 768, rel=0.01)
    np.testing.assert_allclose(VIRTUAL.recorded_to_virtual([[384.0, 288.0]], CENTRE_POSE), [[80.0, 60.0]], atol=1e-6)


@pytest.mark.parametrize("pose", POSES)
def test_recorded_pixels_map_to_where_the_virtual_camera_sees_the_same_ground_point(pose):
    truth = load_mot_ground_truth(EXCERPT / "gt_mot15.txt")
    recorded = project_pinhole(RECORDING, np.c_[truth.ground_m * MM_PER_M, np.zeros(len(truth.frame))])
    expected = apply_homography(ground_to_image(VIRTUAL.camera, pose), truth.ground_m)
    np.testing.assert_allclose(VIRTUAL.recorded_to_virtual(recorded, pose), expected, atol=1e-5)


@pytest.mark.parametrize("pose", POSES)
def test_each_virtual_pixel_reads_the_recorded_pixel_of_its_ray_with_the_lens_distortion(pose):
    """Distortion is handled in the warp: the virtual view is an exact pinhole image."""
    rows, cols = np.array([5, 60, 110]), np.array([7, 80, 150])
    map_u, map_v = VIRTUAL.sampling_maps(pose)
    virtual_px = np.stack(np.meshgrid(cols + 0.5, rows + 0.5), -1).reshape(-1, 2)
    ground_m = apply_homography(image_to_ground(VIRTUAL.camera, pose), virtual_px)
    recorded = project_pinhole(RECORDING, np.c_[ground_m * MM_PER_M, np.zeros(len(ground_m))])
    sampled = np.stack([map_u[np.ix_(rows, cols)].ravel(), map_v[np.ix_(rows, cols)].ravel()], -1) + 0.5
    np.testing.assert_allclose(sampled, recorded, atol=1e-3)


def test_ignoring_the_distortion_would_misplace_the_corners_of_the_wide_view():
    map_u, map_v = VIRTUAL.sampling_maps(CENTRE_POSE)
    corner_px = np.array([[3.5, 100.5], [156.5, 100.5]])
    ground_m = apply_homography(image_to_ground(VIRTUAL.camera, CENTRE_POSE), corner_px)
    points_mm = np.c_[ground_m * MM_PER_M, np.zeros(2)]
    without_distortion = type(RECORDING)(RECORDING.K, np.zeros(5), RECORDING.R, RECORDING.t)
    shift_px = np.linalg.norm(
        project_pinhole(without_distortion, points_mm) - project_pinhole(RECORDING, points_mm), axis=1
    )
    assert np.all(shift_px > 5.0)
    sampled = np.stack([map_u[100, [3, 156]], map_v[100, [3, 156]]], -1) + 0.5
    np.testing.assert_allclose(sampled, project_pinhole(RECORDING, points_mm), atol=1e-3)


def test_rendered_views_show_the_recording(excerpt_frames):
    frame = excerpt_frames[0]
    wide = VIRTUAL.render(frame, CENTRE_POSE)
    assert wide.shape == (120, 160, 3)
    assert np.mean(wide.sum(axis=-1) == 0) < 0.03
    zoomed = VIRTUAL.render(frame, CENTRE_POSE + [0.0, 0.0, 3.0])
    assert np.mean(zoomed.sum(axis=-1) == 0) == 0.0
    # the zoomed view's centre shows the recorded image's centre, three times larger
    centre = frame[288 - 6 : 288 + 6, 384 - 8 : 384 + 8].astype(float).mean(axis=(0, 1))
    zoomed_centre = (
        zoomed[60 - 6 * 3 // 5 : 60 + 6 * 3 // 5, 80 - 8 * 3 // 5 : 80 + 8 * 3 // 5].astype(float).mean(axis=(0, 1))
    )
    assert np.max(np.abs(centre - zoomed_centre)) < 25


@pytest.mark.parametrize("pose", [CENTRE_POSE + [0.0, 0.0, 0.0], CENTRE_POSE + [-6.0, -1.5, 3.0]])
def test_a_map_interpolated_over_a_grid_of_8_px_is_the_exact_one_to_a_hundredth_of_a_pixel(pose):
    exact_u, exact_v = virtual_ptz(RECORDING, image_size_px=(640, 480))[0].sampling_maps(pose)
    coarse = virtual_ptz(RECORDING, image_size_px=(640, 480), map_grid_px=8)[0]
    coarse_u, coarse_v = coarse.sampling_maps(pose)
    assert coarse_u.shape == exact_u.shape == (480, 640)
    assert np.max(np.hypot(coarse_u - exact_u, coarse_v - exact_v)) < 0.01


def test_a_poses_sampling_maps_are_computed_once_and_the_oldest_are_dropped_beyond_the_budget(monkeypatch):
    virtual, pose = virtual_ptz(RECORDING)
    first = virtual.sampling_maps(pose)
    assert virtual.sampling_maps(list(pose)) is first and not first[0].flags.writeable
    np.testing.assert_array_equal(first[0], VIRTUAL._computed_maps(pose)[0])
    # Room for the maps of two poses: a third pose drops the first one's.
    monkeypatch.setattr("ptztrack.camera.virtual.MAP_CACHE_BYTES", 2 * 2 * first[0].nbytes)
    virtual.sampling_maps(pose + [1.0, 0.0, 0.0])
    virtual.sampling_maps(pose + [2.0, 0.0, 0.0])
    assert virtual.sampling_maps(pose) is not first
    assert pickle.loads(pickle.dumps(virtual)).sampling_maps(pose)[0].shape == (120, 160)


def test_a_person_standing_on_the_recorded_ground_is_as_tall_as_the_projection_of_their_head():
    """The recording's standing height: the feet pixel's ray meets the ground, the head 1.75 m above
    it is projected with the lens distortion; so is it computed by hand from ground points."""
    ground_mm = np.array([[0.0, 0.0, 0.0], [5000.0, 3000.0, 0.0], [-2000.0, 9000.0, 0.0]])
    feet_px = project_pinhole(RECORDING, ground_mm)
    head_px = project_pinhole(RECORDING, ground_mm + [0.0, 0.0, 1750.0])
    np.testing.assert_allclose(
        standing_height_px(RECORDING, feet_px, 1.75), np.linalg.norm(head_px - feet_px, axis=-1), rtol=1e-5
    )
    # The sky holds no one: a pixel far above the horizon.
    assert np.isnan(standing_height_px(RECORDING, [[384.0, -3000.0]], 1.75)).all()
