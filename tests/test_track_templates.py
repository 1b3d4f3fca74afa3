from importlib import resources

import numpy as np
import pytest

from ptztrack.camera.virtual import virtual_ptz
from ptztrack.geometry.calibration import load_calibration
from ptztrack.geometry.ptz import (
    PTZCamera,
    apply_homography,
    feet_jacobian,
    ground_to_image,
    image_to_ground,
    look_at,
    project_people,
)
from ptztrack.scene.pets import RecordedVideo, load_mot_ground_truth
from ptztrack.track.appearance import pixel_span, similarity, spatiogram
from ptztrack.track.kalman import constant_velocity_model
from ptztrack.track.lifecycle import start_tracks
from ptztrack.track.templates import (
    MIN_SIMILARITY,
    refresh_templates,
    search_radius_px,
    template_box_px,
    template_measurements,
)
from ptztrack.track.tracker import predict_tracks, update_tracks
from ptztrack.types import Tracks
from test_track_tracker import ACCELERATION_SIGMA_M_S2, parameters

PETS = resources.files("ptztrack.data") / "pets2009_s2l1"
CAMERA = PTZCamera((7.5, -4.0, 7.0), 640, 480, 400.0)
POSE = look_at(CAMERA, [7.5, 6.0], 1.0)
HEIGHT_M, WIDTH_M = 1.75, 0.5
V = 0.25 * np.eye(2)
BGR_SKIN, BGR_RED, BGR_BLUE = (150, 180, 230), (40, 40, 200), (170, 70, 30)


def noise_image(seed) -> np.ndarray:
    return np.random.default_rng(seed).integers(0, 256, (CAMERA.image_height_px, CAMERA.image_width_px, 3), np.uint8)


def draw_person(image, feet_px) -> np.ndarray:
    """A copy of the image with a person (head, red shirt, blue trousers) filling the homology's box on ``feet_px``."""
    left, top, width, height = template_box_px(CAMERA, POSE, [feet_px], HEIGHT_M, WIDTH_M)[0]
    image = image.copy()
    col0, col1 = pixel_span(left, left + width, image.shape[1])
    for start, end, bgr in [(0.0, 0.2, BGR_SKIN), (0.2, 0.6, BGR_RED), (0.6, 1.0, BGR_BLUE)]:
        row0, row1 = pixel_span(top + start * height, top + end * height, image.shape[0])
        image[row0:row1, col0:col1] = bgr
    return image


def tracks_at(feet_px, sigma_px=3.0) -> Tracks:
    """Standing tracks (ids 0, 1, ...) on the ground under ``feet_px`` (n, 2), ``sigma_px`` uncertain in the image."""
    ground_m = apply_homography(image_to_ground(CAMERA, POSE), np.asarray(feet_px, dtype=float))
    count = len(ground_m)
    J_inv = np.linalg.inv(feet_jacobian(CAMERA, POSE, ground_m))
    covariance = np.zeros((count, 4, 4))
    covariance[:, :2, :2] = sigma_px**2 * J_inv @ np.swapaxes(J_inv, -1, -2)
    covariance[:, 2:, 2:] = np.eye(2)
    mean = np.concatenate([ground_m, np.zeros((count, 2))], axis=-1)
    return Tracks(np.arange(count), mean, covariance, np.zeros(count, int), np.ones(count, int), count)


def test_a_box_is_the_projected_person_and_twice_as_tall_at_zoom_2():
    ground_m = np.array([[5.0, 4.0], [9.0, 8.0], [7.5, 12.0]])
    boxes = {}
    for zoom in (1.0, 2.0):
        pose = look_at(CAMERA, [7.5, 8.0], zoom)
        feet_px = apply_homography(ground_to_image(CAMERA, pose), ground_m)
        boxes[zoom] = template_box_px(CAMERA, pose, feet_px, HEIGHT_M, WIDTH_M)
        people = project_people(CAMERA, pose, ground_m, HEIGHT_M, WIDTH_M)
        np.testing.assert_allclose(boxes[zoom][:, 3], people.height_px, rtol=1e-9)
        np.testing.assert_allclose(boxes[zoom][:, 1] + boxes[zoom][:, 3], feet_px[:, 1], atol=1e-9)
        np.testing.assert_allclose(boxes[zoom][:, 0] + boxes[zoom][:, 2] / 2, feet_px[:, 0], atol=1e-9)
    np.testing.assert_allclose(boxes[2.0][:, 3], 2 * boxes[1.0][:, 3], rtol=1e-9)
    np.testing.assert_allclose(boxes[1.0][:, 2] / boxes[1.0][:, 3], WIDTH_M / HEIGHT_M)
    assert boxes[1.0][0, 3] > boxes[1.0][2, 3]  # the nearer person is taller


def test_the_search_radius_is_three_sigma_of_the_innovation_clipped():
    S = np.stack([np.diag([4.0, 1.0]), np.diag([0.1, 0.2]), np.diag([1.0, 400.0])])
    np.testing.assert_allclose(search_radius_px(S, min_radius_px=3.0, max_radius_px=20.0), [6.0, 3.0, 20.0])


def test_a_moved_person_is_found_at_the_new_feet():
    before_px, after_px = np.array([320.0, 300.0]), np.array([323.0, 298.0])
    background = noise_image(0)
    image = draw_person(background, before_px)
    templates = refresh_templates({}, [0], image, CAMERA, POSE, [0], [before_px], HEIGHT_M, WIDTH_M)
    later = draw_person(noise_image(1), after_px)
    found = template_measurements(later, CAMERA, POSE, tracks_at([before_px]), templates, V, HEIGHT_M, WIDTH_M)
    np.testing.assert_array_equal(found.track_ids, [0])
    assert np.linalg.norm(found.feet_px[0] - after_px) <= 1.0
    assert found.similarity[0] > 0.9


def test_a_person_gone_gives_no_measurement_unless_any_similarity_will_do():
    feet_px = np.array([320.0, 300.0])
    image = draw_person(noise_image(0), feet_px)
    templates = refresh_templates({}, [0], image, CAMERA, POSE, [0], [feet_px], HEIGHT_M, WIDTH_M)
    empty, tracks = noise_image(1), tracks_at([feet_px])
    assert len(template_measurements(empty, CAMERA, POSE, tracks, templates, V, HEIGHT_M, WIDTH_M).feet_px) == 0
    anything = template_measurements(empty, CAMERA, POSE, tracks, templates, V, HEIGHT_M, WIDTH_M, min_similarity=0.0)
    assert len(anything.feet_px) == 1 and anything.similarity[0] < MIN_SIMILARITY


@pytest.mark.parametrize(
    "ground_m, pose",
    [([-30.0, 6.0], POSE), ([7.5, -4.0 - 7.0 / np.tan(np.deg2rad(10.0))], np.array([0.0, -10.0, 1.0]))],
    ids=["outside the image", "behind the camera, mirrored to the image centre"],
)
def test_a_track_not_predicted_in_the_image_gives_no_measurement(ground_m, pose):
    image = draw_person(noise_image(0), [320.0, 300.0])
    templates = refresh_templates({}, [0], image, CAMERA, POSE, [0], [[320.0, 300.0]], HEIGHT_M, WIDTH_M)
    tracks = tracks_at([[320.0, 300.0]])
    tracks = Tracks(tracks.ids, np.array([[*ground_m, 0.0, 0.0]]), tracks.covariance, tracks.existence, tracks.hits)
    found = template_measurements(image, CAMERA, pose, tracks, templates, V, HEIGHT_M, WIDTH_M, min_similarity=0.0)
    assert len(found.feet_px) == len(found.track_ids) == 0


def test_only_tracks_with_templates_are_searched():
    feet_px = np.array([[200.0, 300.0], [420.0, 300.0]])
    image = draw_person(draw_person(noise_image(0), feet_px[0]), feet_px[1])
    templates = refresh_templates({}, [0, 1], image, CAMERA, POSE, [1], feet_px[1:], HEIGHT_M, WIDTH_M)
    found = template_measurements(image, CAMERA, POSE, tracks_at(feet_px), templates, V, HEIGHT_M, WIDTH_M)
    np.testing.assert_array_equal(found.track_ids, [1])
    np.testing.assert_allclose(found.feet_px, feet_px[1:])


def test_refreshing_retakes_the_given_tracks_keeps_the_other_live_ones_and_drops_the_dead():
    feet_px = np.array([[200.0, 300.0], [420.0, 300.0], [320.0, -40.0]])
    old = refresh_templates({}, [1, 2, 5], noise_image(0), CAMERA, POSE, [1, 2, 5], feet_px, HEIGHT_M, WIDTH_M)
    assert set(old) == {1, 2}  # feet above the image: no template
    image = noise_image(1)
    new = refresh_templates(old, [1, 2, 7, 8], image, CAMERA, POSE, [2, 7, 8], feet_px, HEIGHT_M, WIDTH_M)
    assert set(old) == {1, 2}
    assert set(new) == {1, 2, 7}
    assert new[1] is old[1]
    box_px = template_box_px(CAMERA, POSE, feet_px[1:2], HEIGHT_M, WIDTH_M)[0]
    assert similarity(new[7], spatiogram(image, box_px)) == pytest.approx(1.0)
    assert similarity(new[2], old[2]) < 0.9
    assert set(refresh_templates(new, [7], image, CAMERA, POSE, [], np.zeros((0, 2)), HEIGHT_M, WIDTH_M)) == {7}


@pytest.mark.parametrize("association", ["hungarian", "cjpdaf"])
def test_each_detected_or_new_track_is_paired_with_its_detection(association):
    config = parameters(association=association)
    feet_px = np.array([[200.0, 300.0], [420.0, 300.0]])
    F, U = constant_velocity_model(0.2, ACCELERATION_SIGMA_M_S2)
    predicted = predict_tracks(start_tracks(feet_px, CAMERA, POSE, V, config.initial_speed_sigma_m_s, 3), F, U)
    detections_px = np.array([[560.0, 350.0], [202.0, 299.0]])  # somebody new, and track 3 moved
    update = update_tracks(predicted, detections_px, CAMERA, POSE, V, config, np.full(2, 0.5))
    assert set(update.tracks.ids) == {3, 4, 5}
    np.testing.assert_array_equal(update.track_ids, [3, 5])
    np.testing.assert_array_equal(update.measurement_index, [1, 0])


@pytest.mark.parametrize("association, paired", [("hungarian", 1), ("cjpdaf", 0)])
def test_a_detection_the_cjpdaf_shares_between_tracks_is_paired_with_none(association, paired):
    config = parameters(association=association)
    F, U = constant_velocity_model(0.2, ACCELERATION_SIGMA_M_S2)
    feet_px = np.array([[298.0, 300.0], [302.0, 302.0], [302.0, 298.0]])
    predicted = predict_tracks(start_tracks(feet_px, CAMERA, POSE, V, config.initial_speed_sigma_m_s, 0), F, U)
    # Nobody was surely detectable: the missed tracks live on, and the shared detection starts none.
    update = update_tracks(predicted, np.array([[301.0, 300.0]]), CAMERA, POSE, V, config, np.full(3, 0.5))
    assert len(update.track_ids) == len(update.measurement_index) == paired


@pytest.fixture(scope="module")
def pets_view():
    """The annotated PETS View_001 frames 0 and 2 through a 320 x 240 virtual camera showing the whole frame."""
    virtual, pose = virtual_ptz(load_calibration(PETS / "pinhole.json", "View_001"), (768, 576), (320, 240))
    video = RecordedVideo(PETS / "View_001.avi", (768, 576))
    truth = load_mot_ground_truth(PETS / "gt_mot15.txt")
    views, people = {}, {}
    for frame in (0, 2):
        rows = np.flatnonzero(truth.frame == frame)
        views[frame] = virtual.render(video.frame(frame), pose)
        feet_px = virtual.recorded_to_virtual(truth.feet_px[rows], pose)
        people[frame] = (truth.person_id[rows], truth.ground_m[rows], feet_px)
    return virtual.camera, pose, views, people


def test_pets_people_are_found_two_frames_later_near_their_annotated_feet(pets_view):
    camera, pose, views, people = pets_view
    ids, ground_m, feet_px = people[0]
    later_ids, _, later_feet_px = people[2]
    np.testing.assert_array_equal(later_ids, ids)
    count = len(ids)
    covariance = np.zeros((count, 4, 4))
    covariance[:, :2, :2] = 0.3**2 * np.eye(2)  # m^2: search radii of 16-20 px here
    tracks = Tracks(ids, np.c_[ground_m, np.zeros((count, 2))], covariance, np.zeros(count, int), np.ones(count, int))
    templates = refresh_templates({}, ids, views[0], camera, pose, ids, feet_px, HEIGHT_M, WIDTH_M)
    found = template_measurements(views[2], camera, pose, tracks, templates, V, HEIGHT_M, WIDTH_M)
    np.testing.assert_array_equal(found.track_ids, ids)
    # People 15 and 19 walked 4-6 px; the matches lie within 1.5 px of the annotations (measured 1.0-1.5).
    assert np.max(np.linalg.norm(later_feet_px - feet_px, axis=1)) > 4.0
    assert np.all(np.linalg.norm(found.feet_px - later_feet_px, axis=1) < 2.0)
    assert np.all(found.similarity > 0.8)
