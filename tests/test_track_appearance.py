from pathlib import Path

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ptztrack.scene.pets import RecordedVideo, load_mot_ground_truth
from ptztrack.track.appearance import search, similarity, spatiogram

EXCERPT = Path(__file__).parent / "data" / "pets_s2l1_excerpt"

PERSON_WIDTH_PX, PERSON_HEIGHT_PX = 20, 50
BGR_SKIN, BGR_RED, BGR_BLUE = (150, 180, 230), (40, 40, 200), (170, 70, 30)


def random_image(seed, height_px, width_px) -> np.ndarray:
    return np.random.default_rng(seed).integers(0, 256, (height_px, width_px, 3), dtype=np.uint8)


def person_on_noise(feet_px, seed) -> np.ndarray:
    """A 640 x 480 noise image with a 20 x 50 px person (head, red shirt, blue trousers) standing at integer feet."""
    rng = np.random.default_rng(seed)
    image = rng.integers(0, 256, (480, 640, 3), dtype=np.uint8)
    left, bottom = feet_px[0] - PERSON_WIDTH_PX // 2, feet_px[1]
    for top, rows, bgr in [(bottom - 50, 10, BGR_SKIN), (bottom - 40, 20, BGR_RED), (bottom - 20, 20, BGR_BLUE)]:
        texture = rng.integers(-12, 13, (rows, PERSON_WIDTH_PX, 3))
        image[top : top + rows, left : left + PERSON_WIDTH_PX] = np.clip(np.add(bgr, texture), 0, 255)
    return image


def box_at(feet_px, width_px, height_px):
    """(left, top, width, height) of a box standing on ``feet_px``."""
    return (feet_px[0] - width_px / 2, feet_px[1] - height_px, width_px, height_px)


def pets_person(frame, person_id):
    """The annotated box (left, top, width, height) and feet (2,) px of a person in a frame of the excerpt."""
    truth = load_mot_ground_truth(EXCERPT / "gt_mot15.txt")
    row = np.flatnonzero((truth.frame == frame) & (truth.person_id == person_id))[0]
    return truth.box_px[row], truth.feet_px[row]


@pytest.fixture(scope="module")
def pets_frames():
    video = RecordedVideo(EXCERPT / "View_001.avi", (768, 576))
    return {index: video.frame(index) for index in (0, 4)}


boxes_on_small_images = st.tuples(
    st.integers(0, 2**32 - 1),  # image seed
    st.floats(-5.0, 15.0),  # left px
    st.floats(-5.0, 25.0),  # top px
    st.floats(6.0, 20.0),  # width px: at least one pixel of the 20 x 30 image inside
    st.floats(6.0, 30.0),  # height px
)


def spatiogram_of(case, image_shape=(30, 20)):
    seed, left, top, width, height = case
    return spatiogram(random_image(seed, *image_shape), (left, top, width, height))


def test_a_spatiogram_is_normalised_and_has_similarity_one_with_itself(pets_frames):
    box, _ = pets_person(0, 9)
    person = spatiogram(pets_frames[0], box)
    assert person.counts.sum() == pytest.approx(1.0)
    occupied = person.counts > 0
    assert np.all((person.mean_box[occupied] >= 0) & (person.mean_box[occupied] <= 1))
    assert similarity(person, person) == pytest.approx(1.0, abs=1e-12)


@settings(max_examples=60, deadline=None)
@given(boxes_on_small_images, boxes_on_small_images)
def test_similarity_is_symmetric_in_zero_one_and_one_with_itself(case_a, case_b):
    a, b = spatiogram_of(case_a), spatiogram_of(case_b)
    assert similarity(a, b) == pytest.approx(similarity(b, a), abs=1e-12)
    assert 0.0 <= similarity(a, b) <= 1.0
    assert similarity(a, a) == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("person_id", [9, 15, 19])
def test_a_spatiogram_hardly_changes_when_image_and_box_are_resized_twofold(pets_frames, person_id):
    box, _ = pets_person(0, person_id)
    enlarged = cv2.resize(pets_frames[0], None, fx=2, fy=2, interpolation=cv2.INTER_LINEAR)
    assert similarity(spatiogram(pets_frames[0], box), spatiogram(enlarged, 2 * box)) > 0.95


def test_rearranged_colours_have_the_same_histogram_but_different_spatiograms():
    red_over_blue = np.zeros((40, 20, 3), np.uint8)
    red_over_blue[:20] = (0, 0, 255)
    red_over_blue[20:] = (255, 0, 0)
    blue_over_red = red_over_blue[::-1].copy()
    a, b = spatiogram(red_over_blue, (0, 0, 20, 40)), spatiogram(blue_over_red, (0, 0, 20, 40))
    np.testing.assert_array_equal(a.counts, b.counts)
    assert similarity(a, b) < 0.5


def test_a_box_without_pixels_in_the_image_has_no_spatiogram():
    with pytest.raises(ValueError, match="holds no pixel"):
        spatiogram(random_image(0, 30, 20), (25.0, 5.0, 10.0, 10.0))


@pytest.mark.parametrize("scale", [1, 2])
def test_search_finds_a_displaced_person_to_a_pixel_at_any_scale(scale):
    before_px, after_px = np.array([300, 250]), np.array([303, 248])
    template = spatiogram(person_on_noise(before_px, seed=1), box_at(before_px, PERSON_WIDTH_PX, PERSON_HEIGHT_PX))
    # The template comes from the unscaled view; only the box size knows the scale.
    later = cv2.resize(person_on_noise(after_px, seed=2), None, fx=scale, fy=scale, interpolation=cv2.INTER_LINEAR)
    feet_px, score = search(
        later, template, scale * before_px, scale * PERSON_HEIGHT_PX, scale * PERSON_WIDTH_PX, radius_px=8 * scale
    )
    assert np.linalg.norm(feet_px - scale * after_px) <= 1.0
    assert score > 0.9


@settings(max_examples=60, deadline=None)
@given(boxes_on_small_images, boxes_on_small_images)
def test_each_search_score_is_the_similarity_of_that_box(template_case, box_case):
    template = spatiogram_of(template_case)
    seed, left, top, width, height = box_case
    image = random_image(seed, 30, 20)
    feet_px = (left + width / 2, top + height)
    found_px, score = search(image, template, feet_px, height, width, radius_px=0.0)
    np.testing.assert_array_equal(found_px, feet_px)
    assert score == pytest.approx(similarity(template, spatiogram(image, box_at(feet_px, width, height))), abs=1e-9)


def test_the_best_search_score_is_the_similarity_at_the_found_feet():
    image = random_image(3, 60, 40)
    template = spatiogram(random_image(4, 60, 40), (10.0, 10.0, 12.0, 30.0))
    found_px, score = search(image, template, (16.0, 40.0), 30.0, 12.0, radius_px=6.0, step_px=1.5)
    assert np.linalg.norm(found_px - (16.0, 40.0)) <= 6.0
    assert score == pytest.approx(similarity(template, spatiogram(image, box_at(found_px, 12.0, 30.0))), abs=1e-9)


def test_a_search_outside_the_image_scores_zero_at_the_prediction():
    template = spatiogram(random_image(0, 30, 20), (0.0, 0.0, 10.0, 20.0))
    found_px, score = search(random_image(1, 30, 20), template, (100.0, -50.0), 20.0, 10.0, radius_px=3.0)
    np.testing.assert_array_equal(found_px, (100.0, -50.0))
    assert score == 0.0


def test_search_finds_a_pets_person_four_frames_later_near_the_annotated_feet(pets_frames):
    box_before, feet_before = pets_person(0, 9)
    _, feet_after = pets_person(4, 9)
    template = spatiogram(pets_frames[0], box_before)
    # The person walked 10.4 px; the box keeps its frame-0 size, as a prediction would.
    feet_px, score = search(pets_frames[4], template, feet_before, box_before[3], box_before[2], radius_px=12.0)
    assert np.linalg.norm(feet_after - feet_before) > 10.0
    assert np.linalg.norm(feet_px - feet_after) < 3.0
    assert score > 0.85
