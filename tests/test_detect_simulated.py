"""Tests of the simulated detectors in ptztrack.detect.simulated."""

import numpy as np
import pytest

from overhead import CAMERA as OVERHEAD_CAMERA
from ptztrack.detect.parameters import DetectorPriorParameters
from ptztrack.detect.simulated import RecallDetector, RecallModel, detection_probability
from ptztrack.geometry.occlusion import occluded_fraction, occlusion_in_centred_views
from ptztrack.geometry.ptz import (
    apply_homography,
    image_to_ground,
    inside_image,
    look_at,
    person_in_view,
    project_people,
)
from ptztrack.types import PeopleInView

# Hand-computed cases for the overhead camera (7 m up).
CAMERA = OVERHEAD_CAMERA
SIZE = (CAMERA.image_width_px, CAMERA.image_height_px)
# The scenario's default detectors: the paper's realistic curve, and the ideal one.
# The paper's recall curve (its Caltech fit of HOG), and the ideal detector's recall of 1.
CALTECH = RecallModel(DetectorPriorParameters.recall_kd, DetectorPriorParameters.recall_r0_px)
REALISTIC = RecallDetector(CALTECH, 2.0, 0.0, SIZE)
IDEAL = RecallDetector(RecallModel(CALTECH.kd_per_px, CALTECH.r0_px, perfect=True), 2.0, 0.0, SIZE)


# ---------------------------------------------------------------------------
# recall


def test_realistic_recall():
    assert REALISTIC.recall.r0_px == 21.29 and REALISTIC.recall.kd_per_px == 0.0098
    below = REALISTIC.recall(np.array([0.0, 5.0, 21.0, 21.2899]))
    np.testing.assert_array_equal(below, 0.0)
    assert REALISTIC.recall(21.29) == 0.0
    value = REALISTIC.recall(100.0)
    np.testing.assert_allclose(value, 1 - np.exp(-0.0098 * (100 - 21.29)), rtol=1e-14)
    np.testing.assert_allclose(value, 0.5376, atol=5e-5)
    heights = np.array([30.0, 50.0, 200.0, 480.0])
    np.testing.assert_allclose(REALISTIC.recall(heights), 1 - np.exp(-0.0098 * (heights - 21.29)), rtol=1e-14)
    np.testing.assert_allclose(REALISTIC.recall(1e5), 1.0, rtol=1e-12)


def test_recall_is_monotone_and_keeps_shape():
    heights = np.linspace(0, 1000, 5001)
    values = REALISTIC.recall(heights)
    assert values.shape == heights.shape
    assert np.all(np.diff(values) >= 0)
    assert np.all(np.diff(values[heights > 21.29]) > 0)
    assert np.all((values >= 0) & (values < 1))
    grid = REALISTIC.recall(heights[:5000].reshape(50, 100))
    np.testing.assert_array_equal(grid, values[:5000].reshape(50, 100))
    other = RecallDetector(RecallModel(0.05, 10.0), 2.0, 0.0, SIZE)
    np.testing.assert_allclose(other.recall(30.0), 1 - np.exp(-0.05 * 20.0), rtol=1e-14)
    assert other.recall(9.99) == 0.0


def test_ideal_recall_is_one():
    heights = np.array([[0.0, 1.0, 21.0], [100.0, 1e4, 3.5]])
    np.testing.assert_array_equal(IDEAL.recall(heights), np.ones((2, 3)))


# ---------------------------------------------------------------------------
# detection_probability on a camera

# Looking at (7.5, 8) with zoom 2 from the scenario camera: a 1.75 m person there is
# ~93 px tall (p ~ 0.50). Persons 2 and 3 stand farther along the same pan line.
POSE = look_at(CAMERA, (7.5, 8.0), 2.0)
ALL = np.ones(4, dtype=bool)


def scene():
    xy = np.array([[7.5, 8.0], [7.5, 10.0], [7.5, 9.6], [12.0, 8.0]])
    heights = np.array([1.75, 1.75, 0.8, 1.75])
    return project_people(CAMERA, POSE, xy, heights, 0.5)


def hidden_of(people, present):
    """Occluded fractions in the view the people were projected in (they stand near its centre)."""
    return occluded_fraction(people.box_px, people.range_m, present & people.in_front)


def in_view(people, present):
    """What a simulated camera knows of projected people, seen in the view they were projected in."""
    index = np.broadcast_to(np.arange(people.feet_px.shape[-2]), people.height_px.shape)
    visible = present & person_in_view(CAMERA, people)
    return PeopleInView(index, people.feet_px, people.height_px, visible, hidden_of(people, present))


class FixedView:
    """A camera backend that always shows the same people."""

    def __init__(self, people):
        self.shown = people

    def image(self, step, pose):
        return None

    def people(self, step, pose):
        return self.shown


def detect(people, present, detector, rng):
    return detector.detect(FixedView(in_view(people, present)), 0, POSE, rng)


def box_area(box):
    return (box[2] - box[0]) * (box[3] - box[1])


def intersection_area(a, b):
    width = max(0.0, min(a[2], b[2]) - max(a[0], b[0]))
    height = max(0.0, min(a[3], b[3]) - max(a[1], b[1]))
    return width * height


def test_unoccluded_person_in_middle_has_recall_probability():
    people = project_people(CAMERA, POSE, np.array([[7.5, 8.0], [12.0, 8.0]]), 1.75, 0.5)
    np.testing.assert_allclose(people.feet_px[0], [320.0, 240.0], atol=1e-9)
    assert 80 < people.height_px[0] < 110
    p = detection_probability(in_view(people, np.ones(2, dtype=bool)), REALISTIC.recall)
    np.testing.assert_allclose(p, REALISTIC.recall(people.height_px), rtol=1e-14)
    assert 0.4 < p[0] < 0.6
    np.testing.assert_array_equal(
        detection_probability(in_view(people, np.ones(2, dtype=bool)), IDEAL.recall), [1.0, 1.0]
    )
    # a person who is not present is never detected and does not count
    np.testing.assert_array_equal(
        detection_probability(in_view(people, np.array([False, True])), IDEAL.recall), [0.0, 1.0]
    )


def test_person_behind_another_is_reduced_by_visible_fraction():
    people = scene()
    box = people.box_px
    assert np.all(np.diff(people.depth_m[:2]) > 0)
    # person 1 (farther, same column) is partly covered by person 0 only
    c1 = intersection_area(box[1], box[0]) / box_area(box[1])
    assert 0.2 < c1 < 0.8
    # person 2 (a 0.8 m child right behind person 0) is entirely inside person 0's box
    assert box[0, 0] <= box[2, 0] and box[2, 2] <= box[0, 2] and box[0, 1] <= box[2, 1] and box[2, 3] <= box[0, 3]

    hidden = occluded_fraction(box, people.range_m, ALL)
    np.testing.assert_allclose(hidden[:3], [0.0, c1, 1.0], rtol=1e-12, atol=1e-12)

    r = REALISTIC.recall(people.height_px)
    p = detection_probability(in_view(people, ALL), REALISTIC.recall)
    np.testing.assert_allclose(p, [r[0], r[1] * (1 - c1), 0.0, r[3]], rtol=1e-12, atol=1e-12)
    p_ideal = detection_probability(in_view(people, ALL), IDEAL.recall)
    np.testing.assert_allclose(p_ideal, [1.0, 1 - c1, 0.0, 1.0], rtol=1e-12, atol=1e-12)

    # without the front person, the child is fully visible and now it alone hides part of person 1
    assert people.depth_m[2] < people.depth_m[1]
    c1_child = intersection_area(box[1], box[2]) / box_area(box[1])
    assert 0 < c1_child < c1
    present = np.array([False, True, True, True])
    p_alone = detection_probability(in_view(people, present), REALISTIC.recall)
    np.testing.assert_allclose(p_alone, [0.0, r[1] * (1 - c1_child), r[2], r[3]], rtol=1e-12)
    # and without both, person 1 is fully visible
    present = np.array([False, True, False, True])
    p_free = detection_probability(in_view(people, present), REALISTIC.recall)
    np.testing.assert_allclose(p_free, [0.0, r[1], 0.0, r[3]], rtol=1e-12)


def test_person_outside_image_or_cut_off_is_never_detected():
    # person 3 at (12, 8) is in view at zoom 2 but off the right border at zoom 3
    xy = np.array([[12.0, 8.0]])
    zoom2 = project_people(CAMERA, POSE, xy, 1.75, 0.5)
    zoom3 = project_people(CAMERA, POSE * [1, 1, 1.5], xy, 1.75, 0.5)
    assert inside_image(CAMERA, zoom2.feet_px).all() and not inside_image(CAMERA, zoom3.feet_px).any()
    assert detection_probability(in_view(zoom2, np.ones(1, bool)), IDEAL.recall)[0] == 1.0
    assert detection_probability(in_view(zoom3, np.ones(1, bool)), IDEAL.recall)[0] == 0.0

    to_ground = image_to_ground(CAMERA, POSE)
    # feet 10 px below the top border: the head is above the image
    top = apply_homography(to_ground, np.array([[320.0, 10.0]]))
    cut = project_people(CAMERA, POSE, top, 1.75, 0.5)
    assert inside_image(CAMERA, cut.feet_px).all() and cut.head_px[0, 1] < 0
    assert detection_probability(in_view(cut, np.ones(1, bool)), IDEAL.recall)[0] == 0.0
    # feet just below the bottom border: head inside, feet outside
    bottom = apply_homography(to_ground, np.array([[320.0, 485.0]]))
    low = project_people(CAMERA, POSE, bottom, 1.75, 0.5)
    assert inside_image(CAMERA, low.head_px).all() and not inside_image(CAMERA, low.feet_px).any()
    assert detection_probability(in_view(low, np.ones(1, bool)), IDEAL.recall)[0] == 0.0


def test_person_behind_the_camera_is_never_detected():
    # at a shallow tilt the sky part of the image shows (mirrored) points behind the camera
    pose = np.array([0.0, 5.0, 1.0])
    behind = project_people(CAMERA, pose, np.array([[7.5, -104.0]]), 1.75, 0.5)
    assert behind.depth_m[0] < 0
    assert inside_image(CAMERA, behind.feet_px).all() and inside_image(CAMERA, behind.head_px).all()
    assert detection_probability(in_view(behind, np.ones(1, bool)), IDEAL.recall)[0] == 0.0


def test_detection_probability_batched_over_poses():
    poses = np.array([POSE, POSE * [1, 1, 1.5], look_at(CAMERA, (5.0, 5.0), 1.0)])
    xy = np.array([[7.5, 8.0], [7.5, 10.0], [7.5, 9.6], [12.0, 8.0]])
    heights = np.array([1.75, 1.75, 0.8, 1.75])
    present = np.array([True, True, True, False])
    batch = project_people(CAMERA, poses, np.broadcast_to(xy, (3, 4, 2)), heights, 0.5)
    p = detection_probability(in_view(batch, np.broadcast_to(present, (3, 4))), REALISTIC.recall)
    assert p.shape == (3, 4)
    for k, pose in enumerate(poses):
        single = project_people(CAMERA, pose, xy, heights, 0.5)
        np.testing.assert_allclose(p[k], detection_probability(in_view(single, present), REALISTIC.recall), rtol=1e-12)


# ---------------------------------------------------------------------------
# detect: sampling


FRAMES, ROW = 2000, 10
DRAWS = FRAMES * ROW  # 20000 person draws


@pytest.fixture(scope="module")
def many_draws():
    """2000 images of ten people side by side (p ~ 0.50 each): 20000 independent draws.

    They stand on a ground line across the view at exactly the same depth, so they have
    the same height in pixels and (disjoint boxes, equal depth) do not hide each other.
    """
    xy = np.stack([7.5 + np.linspace(-4.68, 4.68, ROW), np.full(ROW, 8.0)], axis=-1)
    people = project_people(CAMERA, POSE, xy, 1.75, 0.5)
    present = np.ones(ROW, dtype=bool)
    rng = np.random.default_rng(20240611)
    frames = [detect(people, present, REALISTIC, rng) for _ in range(FRAMES)]
    return people, present, frames


def test_empirical_detection_rate_matches_probability(many_draws):
    people, present, frames = many_draws
    p = detection_probability(in_view(people, present), REALISTIC.recall)
    np.testing.assert_allclose(p, p[0], rtol=1e-12)
    assert 0.4 < p[0] < 0.6
    np.testing.assert_array_equal(occluded_fraction(people.box_px, people.depth_m, present), 0.0)
    index = np.concatenate([f.person_index for f in frames])
    assert np.all((index >= 0) & (index < ROW))
    # each person at most once per image, reported in index order
    assert all(np.all(np.diff(f.person_index) > 0) for f in frames)
    np.testing.assert_array_equal(np.concatenate([f.height_px for f in frames]), people.height_px[index])
    rate = len(index) / DRAWS
    standard_error = np.sqrt(p[0] * (1 - p[0]) / DRAWS)
    assert abs(rate - p[0]) < 4 * standard_error, (rate, p[0])
    # and every person separately (2000 draws each)
    per_person = np.bincount(index, minlength=ROW) / FRAMES
    assert np.all(np.abs(per_person - p) < 4 * np.sqrt(p * (1 - p) / FRAMES)), per_person


def test_pixel_noise_matches_detector(many_draws):
    people, _, frames = many_draws
    residuals = np.concatenate([f.feet_px - people.feet_px[f.person_index] for f in frames])
    assert residuals.shape[1] == 2 and len(residuals) > 5000
    std = residuals.std(axis=0, ddof=1)
    np.testing.assert_allclose(std, REALISTIC.pixel_noise_px, rtol=0.05)
    # zero-mean noise: 4 standard errors
    assert np.all(np.abs(residuals.mean(axis=0)) < 4 * REALISTIC.pixel_noise_px / np.sqrt(len(residuals)))
    # noise on u and v is uncorrelated
    assert abs(np.corrcoef(residuals.T)[0, 1]) < 4 / np.sqrt(len(residuals))


def test_noise_free_detector_reports_exact_feet():
    people = scene()
    detector = RecallDetector(IDEAL.recall, 0.0, 0.0, SIZE)
    everyone = np.ones(4, dtype=bool)
    found = detect(people, everyone, detector, np.random.default_rng(3))
    # ideal detector: everyone except the fully hidden child (2); person 1 with probability 1 - c
    assert 0 in found.person_index and 3 in found.person_index and 2 not in found.person_index
    np.testing.assert_array_equal(found.feet_px, people.feet_px[found.person_index])
    np.testing.assert_array_equal(found.height_px, people.height_px[found.person_index])


def test_false_positives():
    rate = 1.5
    detector = RecallDetector(REALISTIC.recall, 2.0, rate, SIZE)
    people = scene()
    absent = np.zeros(4, dtype=bool)
    rng = np.random.default_rng(99)
    frames = [detect(people, absent, detector, rng) for _ in range(4000)]
    counts = np.array([len(f) for f in frames])
    standard_error = np.sqrt(rate / len(counts))
    assert abs(counts.mean() - rate) < 4 * standard_error
    # Poisson: the variance equals the mean (4 standard errors of the sample variance)
    assert abs(counts.var(ddof=1) - rate) < 4 * np.sqrt((rate + 2 * rate**2) / len(counts))
    feet = np.concatenate([f.feet_px for f in frames])
    assert np.all(np.concatenate([f.person_index for f in frames]) == -1)
    assert np.all(np.isnan(np.concatenate([f.height_px for f in frames])))
    assert np.all(inside_image(CAMERA, feet))
    # uniform over the image: mean at the centre (4 standard errors of a uniform)
    spread = np.array([640.0, 480.0]) / np.sqrt(12 * len(feet))
    assert np.all(np.abs(feet.mean(axis=0) - [320.0, 240.0]) < 4 * spread)

    # with a true person present, false positives come after the hits
    present = np.array([True, False, False, True])
    ideal = RecallDetector(IDEAL.recall, 2.0, rate, SIZE)
    mixed = [detect(people, present, ideal, rng) for _ in range(50)]
    for frame in mixed:
        true = frame.person_index >= 0
        assert np.all(true[: true.sum()]) and not np.any(true[true.sum() :])
        assert np.all(np.isfinite(frame.height_px[true])) and np.all(np.isnan(frame.height_px[~true]))
        np.testing.assert_array_equal(frame.person_index[true], [0, 3])


def test_same_seed_gives_identical_detections():
    people = scene()
    detector = RecallDetector(REALISTIC.recall, 2.0, 2.0, SIZE)
    present = np.ones(4, dtype=bool)
    first = [detect(people, present, detector, np.random.default_rng(7)) for _ in range(3)]
    again = detect(people, present, detector, np.random.default_rng(7))
    for frame in first:
        np.testing.assert_array_equal(frame.feet_px, again.feet_px)
        np.testing.assert_array_equal(frame.height_px, again.height_px)
        np.testing.assert_array_equal(frame.person_index, again.person_index)

    # a stream of draws is reproducible too, and different seeds differ
    def stream(seed):
        rng = np.random.default_rng(seed)
        return np.concatenate([detect(people, present, detector, rng).feet_px.ravel() for _ in range(20)])

    np.testing.assert_array_equal(stream(11), stream(11))
    assert not np.array_equal(stream(11), stream(12))


def test_occlusion_in_centred_views_matches_the_view_on_the_scene():
    xy = np.array([[7.5, 8.0], [7.5, 10.0], [7.5, 9.6], [12.0, 8.0]])
    heights = np.array([1.75, 1.75, 0.8, 1.75])
    centred = occlusion_in_centred_views(CAMERA, xy, heights, np.full(4, 0.5), ALL)
    np.testing.assert_allclose(centred, hidden_of(scene(), ALL), atol=0.05)
    assert centred[2] == pytest.approx(1.0) and centred[0] == 0.0 and centred[3] == 0.0
    nobody_in_front = occlusion_in_centred_views(
        CAMERA, xy, heights, np.full(4, 0.5), np.array([False, True, True, True])
    )
    assert nobody_in_front[2] == 0.0


def test_a_person_seen_at_a_grazing_angle_hides_nobody():
    """At pan 45, tilt 15 the head of a person far to the left lies almost in the image plane:
    its box is thousands of pixels wide, but it cannot hide people in the centre of the view."""
    xy = np.array([[0.5, 1.0], [13.0, 12.0]])
    heights = np.full(2, 1.75)
    centred = occlusion_in_centred_views(CAMERA, xy, heights, np.full(2, 0.5), np.ones(2, bool))
    np.testing.assert_array_equal(centred, 0.0)
