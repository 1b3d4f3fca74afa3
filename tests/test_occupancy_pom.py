import itertools
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.special import expit

from ptztrack.geometry.calibration import aimed_pinhole, project_pinhole
from ptztrack.occupancy.lpom import GroundGrid
from ptztrack.occupancy.multiview import CameraView, MultiViewRecording
from ptztrack.occupancy.parameters import PomParameters
from ptztrack.occupancy.pom import PomDetector, box_sums, integral_image, pom_modes, pom_posterior
from ptztrack.occupancy.pom_rectangles import (
    PersonBoxes,
    boxes_mask,
    fitted_box_scales,
    person_box_px,
    person_boxes,
    scaled_about_feet,
    working_mask,
)
from ptztrack.occupancy.room import RoomLayout, RoomRenderer, room_cameras, room_truth

PARAMETERS = PomParameters()


def one_view(boxes, shape) -> PersonBoxes:
    """PersonBoxes of one view with the given rectangles (K, 4) (left, top, right, bottom), all visible."""
    boxes = np.asarray(boxes, dtype=np.int32)
    return PersonBoxes(boxes[None], np.ones((1, len(boxes)), bool), (shape,), 1)


def psi(mask, synthetic, sigma):
    """The paper's Psi(B, A) = |B (1 - A) + (1 - B) A| / (sigma |A|), summed directly over the pixels."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.sum(mask * (1 - synthetic) + (1 - mask) * synthetic) / (sigma * np.sum(synthetic))


def rectangle_images(boxes, shape) -> np.ndarray:
    """(K, rows, columns) the indicator image A_k of each rectangle."""
    images = np.zeros((len(boxes), *shape))
    for k, (left, top, right, bottom) in enumerate(boxes):
        images[k, top:bottom, left:right] = 1.0
    return images


def direct_iterations(boxes, shape, mask, parameters, iterations) -> np.ndarray:
    """The fixed-point iteration written pixel by pixel from the paper's definitions: for each cell the
    average synthetic images A_{k,xi} = 1 - (1 - xi A_k) prod_{j != k} (1 - q_j A_j), no integral images."""
    rectangles = rectangle_images(boxes, shape)
    q = np.full(len(boxes), parameters.prior)
    log_prior_ratio = np.log((1 - parameters.prior) / parameters.prior)
    for _ in range(iterations):
        change = np.zeros(len(boxes))
        for k in range(len(boxes)):
            others = np.prod(1 - np.delete(q, k)[:, None, None] * np.delete(rectangles, k, axis=0), axis=0)
            present, absent = 1 - (1 - rectangles[k]) * others, 1 - others
            change[k] = psi(mask, present, parameters.sigma) - psi(mask, absent, parameters.sigma)
        q = parameters.damping * q + (1 - parameters.damping) * expit(-(log_prior_ratio + change))
    return q


def test_two_disjoint_cells_reach_the_fixed_point_worked_by_hand():
    # One view of 10 x 20 pixels; cell 0's rectangle holds the person (all 24 of its pixels but 4 are
    # foreground), cell 1's is empty, and 3 foreground pixels lie outside both.
    boxes = [[2, 2, 6, 8], [12, 2, 16, 8]]
    mask = np.zeros((10, 20))
    mask[2:8, 2:6] = 1.0
    mask[2, 2:6] = 0.0
    mask[9, :3] = 1.0

    # With disjoint rectangles the average image is a_0 on R_0, a_1 on R_1 and 0 elsewhere, so
    # |A| = 24 a_0 + 24 a_1, |B A| = 20 a_0 + 0 a_1 and |B| = 23.
    def psi_of(a_0, a_1):
        area = 24 * a_0 + 24 * a_1
        return (23 + area - 2 * 20 * a_0) / (PARAMETERS.sigma * area)

    q = np.full(2, PARAMETERS.prior)
    lam = np.log((1 - PARAMETERS.prior) / PARAMETERS.prior)
    for _ in range(40):
        change = np.array([psi_of(1, q[1]) - psi_of(0, q[1]), psi_of(q[0], 1) - psi_of(q[0], 0)])
        q = PARAMETERS.damping * q + (1 - PARAMETERS.damping) * expit(-(lam + change))
    result = pom_posterior(one_view(boxes, (10, 20)), [mask], replace(PARAMETERS, max_iterations=40, tolerance=0))
    np.testing.assert_allclose(result.q, q, rtol=1e-5, atol=1e-9)
    assert result.q[0] > 0.99 and result.q[1] < 1e-3
    assert result.iterations == 40 and not result.converged  # a tolerance of 0 is never met


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_integral_image_update_is_the_papers_update_pixel_by_pixel(seed):
    rng = np.random.default_rng(seed)
    shape = (16, 24)
    left, top = rng.integers(0, 20, 7), rng.integers(0, 12, 7)
    boxes = np.stack([left, top, left + rng.integers(1, 8, 7), top + rng.integers(1, 8, 7)], axis=-1)
    boxes[:, 2:] = np.minimum(boxes[:, 2:], [24, 16])  # overlapping rectangles, some at the image's edge
    mask = (rng.random(shape) < 0.3).astype(float)
    mask[boxes[0, 1] : boxes[0, 3], boxes[0, 0] : boxes[0, 2]] = rng.random()  # a fractional block
    for iterations in (1, 3, 25):
        parameters = replace(PARAMETERS, max_iterations=iterations, tolerance=0)
        expected = direct_iterations(boxes, shape, mask, parameters, iterations)
        np.testing.assert_allclose(pom_posterior(one_view(boxes, shape), [mask], parameters).q, expected, rtol=1e-5)


@pytest.mark.parametrize("sigma, prior", [(0.01, 0.01), (0.1, 0.1), (0.2, 0.1)])
def test_the_mean_field_agrees_with_the_exact_posterior_over_all_occupancies(sigma, prior):
    # Eight cells in a row whose rectangles overlap their neighbours'; two people, at cells 2 and 5, make
    # the mask, less a few pixels, plus a few pixels of noise.
    boxes = np.array([[4 * k, 2, 4 * k + 6, 14] for k in range(8)])
    shape = (16, 40)
    rectangles = rectangle_images(boxes, shape)
    rng = np.random.default_rng(7)
    mask = np.maximum(rectangles[2], rectangles[5])
    flipped = rng.random(shape) < 0.05
    mask[flipped] = 1.0 - mask[flipped]
    parameters = replace(PARAMETERS, sigma=sigma, prior=prior)
    # The exact posterior: P(X | B) proportional to prod_k P(X_k) exp(-Psi(B, A(X))), over all 2^8 occupancies.
    occupancies = np.array(list(itertools.product([0, 1], repeat=8)))
    log_weight = np.empty(len(occupancies))
    for index, occupied in enumerate(occupancies):
        synthetic = np.max(rectangles * occupied[:, None, None], axis=0)
        prior = np.sum(np.where(occupied, np.log(parameters.prior), np.log(1 - parameters.prior)))
        log_weight[index] = prior - psi(mask, synthetic, sigma) if synthetic.any() else -np.inf
    weight = np.exp(log_weight - log_weight.max())
    exact = weight @ occupancies / weight.sum()
    q = pom_posterior(one_view(boxes, shape), [mask], parameters).q
    people = np.isin(np.arange(8), [2, 5])
    assert np.all(exact[people] > 0.8) and np.all(exact[~people] < 0.15)
    assert np.all(q[people] > 0.8) and np.all(q[~people] < 0.15)
    # A larger sigma softens the posterior; the product law follows it (here a little more certain).
    np.testing.assert_allclose(q, exact, atol=0.1)


def test_without_foreground_every_cell_stays_at_the_prior():
    # Every synthetic pixel is then a false positive: Psi = |A| / (sigma |A|) whatever the occupancy, so
    # the masks say nothing and the fixed point is the prior.
    boxes = np.array([[4 * k, 2, 4 * k + 6, 14] for k in range(8)])
    result = pom_posterior(one_view(boxes, (16, 40)), [np.zeros((16, 40))], PARAMETERS)
    assert result.converged and result.iterations == 1
    np.testing.assert_allclose(result.q, PARAMETERS.prior, rtol=1e-9)


@settings(max_examples=60, deadline=None)
@given(
    image=st.one_of(
        arrays(np.float64, st.tuples(st.integers(1, 12), st.integers(1, 12)), elements=st.floats(-1e3, 1e3)),
        arrays(np.uint8, st.tuples(st.integers(1, 12), st.integers(1, 12))),
        arrays(np.bool_, st.tuples(st.integers(1, 12), st.integers(1, 12))),
    ),
    corners=st.lists(st.tuples(*[st.floats(0, 1)] * 4), min_size=1, max_size=6),
)
def test_integral_image_box_sums_are_the_direct_sums(image, corners):
    rows, columns = image.shape
    integral = integral_image(image)
    assert integral.shape == (rows + 1, columns + 1)
    boxes = []
    for a, b, c, d in corners:
        x = sorted([int(a * columns), int(b * columns)])
        y = sorted([int(c * rows), int(d * rows)])
        boxes.append([x[0], y[0], x[1], y[1]])
    expected = [image[top:bottom, left:right].astype(float).sum() for left, top, right, bottom in boxes]
    np.testing.assert_allclose(box_sums(integral, boxes), expected, rtol=1e-9, atol=1e-9)


def test_the_rectangle_bounds_the_projected_person():
    layout = RoomLayout()
    camera = room_cameras(layout)[0]
    ground_m = np.array([[2.5, 3.0], [1.0, 4.5], [4.2, 1.1], [0.6, 0.7]])
    box = person_box_px(camera, ground_m, 1.75, 0.5)
    for point, (left, top, right, bottom) in zip(ground_m, box, strict=True):
        # The cylinder projected point by point, densely, through the calibration.
        angle = np.linspace(0, 2 * np.pi, 720)
        height = np.linspace(0, 1.75, 50)
        a, h = np.meshgrid(angle, height)
        surface_m = np.stack([point[0] + 0.25 * np.cos(a), point[1] + 0.25 * np.sin(a), h], axis=-1).reshape(-1, 3)
        pixels = project_pinhole(camera, 1000.0 * surface_m)
        np.testing.assert_allclose([left, top], pixels.min(axis=0), atol=0.5)
        np.testing.assert_allclose([right, bottom], pixels.max(axis=0), atol=0.5)
        # Between the boxes of the square prisms inscribed in the cylinder and circumscribing it (8 corners each).
        for half_m, inside in ((0.25 / np.sqrt(2), True), (0.25, False)):
            corners_m = np.array(
                [
                    [point[0] + sx * half_m, point[1] + sy * half_m, z]
                    for sx in (-1, 1)
                    for sy in (-1, 1)
                    for z in (0, 1.75)
                ]
            )
            corner_px = project_pinhole(camera, 1000.0 * corners_m)
            low, high = corner_px.min(axis=0), corner_px.max(axis=0)
            if inside:
                assert np.all([left, top] <= low + 1e-6) and np.all([right, bottom] >= high - 1e-6)
            else:
                assert np.all([left, top] >= low - 1e-6) and np.all([right, bottom] <= high + 1e-6)


def test_rectangles_snap_to_blocks_and_cells_behind_or_beside_the_camera_have_none():
    # A camera at (0, 0, 2 m) looking along +x; cells behind it and far to its side are not seen.
    camera = aimed_pinhole((0.0, 0.0, 2.0), (5.0, 0.0, 1.0), 200.0, (320, 240))
    grid = GroundGrid((-3.0, -10.0), 0.5, (40, 20))  # x from -3 to 7 m, y from -10 to 10 m
    boxes = person_boxes([(camera, (320, 240))], grid, 1.75, 0.5, block_px=4)
    assert boxes.shapes == ((60, 80),)
    centres = grid.centre_of(*np.divmod(np.arange(grid.cells), grid.shape[1]))
    box_px = person_box_px(camera, centres, 1.75, 0.5)
    visible = boxes.visible[0]
    assert not np.any(visible[centres[:, 0] < 0])  # behind the camera
    assert not np.any(visible[(centres[:, 0] > 1) & (np.abs(centres[:, 1]) > 2 * centres[:, 0])])  # beside it
    in_front = visible & (box_px[:, 0] > 0) & (box_px[:, 2] < 320) & (box_px[:, 1] > 0) & (box_px[:, 3] < 240)
    assert in_front.sum() > 10
    # Whole rectangles: the blocks whose centres lie inside the pixel box.
    block = boxes.boxes[0, in_front]
    px = box_px[in_front] / 4
    assert np.all((block[:, :2] + 0.5 >= px[:, :2]) & (block[:, :2] - 0.5 < px[:, :2]))
    assert np.all((block[:, 2:] - 0.5 < px[:, 2:]) & (block[:, 2:] + 0.5 >= px[:, 2:]))


def test_a_lens_that_folds_back_gives_no_rectangle_to_the_cells_beyond_its_fold():
    # k1 = -0.3: r (1 - 0.3 r^2) grows up to r = 1 / sqrt(0.9) and folds back beyond it; a person at
    # r = 2 to the camera's side would otherwise be drawn inside the image, on the other side.
    camera = aimed_pinhole((0.0, 0.0, 2.0), (5.0, 0.0, 2.0), 200.0, (320, 240))
    camera = replace(camera, dist=np.array([-0.3, 0.0, 0.0, 0.0, 0.0]))
    beside_m = np.array([[2.0, 4.0]])  # 4 m to the side at 2 m ahead: r = 2
    raw_px = project_pinhole(camera, 1000.0 * np.array([[2.0, 4.0, 1.0]]))
    assert 0 <= raw_px[0, 0] < 320 and 0 <= raw_px[0, 1] < 240  # the polynomial's fold lands in the image
    assert np.all(np.isnan(person_box_px(camera, beside_m, 1.75, 0.5)))
    ahead_m = np.array([[5.0, 0.5]])
    assert np.all(np.isfinite(person_box_px(camera, ahead_m, 1.75, 0.5)))
    grid = GroundGrid((1.75, 3.75), 0.5, (1, 1))  # the one cell at (2.0, 4.0)
    assert not person_boxes([(camera, (320, 240))], grid, 1.75, 0.5, block_px=4).visible.any()


def test_a_detectors_boxes_make_a_mask_of_the_pixels_whose_centres_they_hold():
    boxes = np.array([[1.0, 2.0, 3.0, 2.0, 0.9], [5.2, 0.0, 1.0, 1.0, 0.3], [7.6, 4.4, 10.0, 10.0, 0.6]])
    mask = boxes_mask(boxes, (10, 6), min_score=0.5)
    expected = np.zeros((6, 10), bool)
    expected[2:4, 1:4] = True  # x in [1, 4): centres 1.5 to 3.5; y in [2, 4): centres 2.5, 3.5
    expected[4:6, 8:10] = True  # x from 7.6: centres from 8.5, clipped at the image's edge; y from 4.4: 4.5
    np.testing.assert_array_equal(mask, expected)
    assert not boxes_mask(np.zeros((0, 5)), (10, 6), 0.5).any()


def test_working_masks_are_the_blocks_foreground_fraction():
    rng = np.random.default_rng(0)
    mask = rng.random((13, 18)) < 0.4
    expected = mask[:12, :18].reshape(4, 3, 6, 3).mean(axis=(1, 3))
    np.testing.assert_allclose(working_mask(mask, 3), expected, rtol=1e-6)


def test_the_strongest_cell_within_the_separation_is_a_candidate_with_its_q():
    grid = GroundGrid((0.0, 0.0), 0.25, (8, 12))
    q_map = np.full(grid.shape, 1e-3)
    q_map[2, 3], q_map[2, 4] = 0.9, 0.3  # a person, and a weaker neighbour (suppressed)
    q_map[6, 9] = 0.6
    q_map[6, 1] = 0.01  # below the candidates' floor
    modes = pom_modes(q_map, grid, separation_m=0.5, window_m=0.1, min_probability=0.02)
    np.testing.assert_allclose(modes.strength, [0.9, 0.6])
    np.testing.assert_allclose(modes.position_m, [grid.centre_of(2, 3), grid.centre_of(6, 9)])
    assert len(pom_modes(q_map, grid, 0.5, 0.1, min_probability=0.95)) == 0
    assert modes.views is None
    view_counts = np.arange(grid.cells)  # cell k seen by k views
    seen = pom_modes(q_map, grid, 0.5, 0.1, min_probability=0.02, view_counts=view_counts)
    np.testing.assert_array_equal(seen.views, [2 * grid.shape[1] + 3, 6 * grid.shape[1] + 9])


def room_detector(layout: RoomLayout, truth, boxes=None) -> PomDetector:
    views = tuple(
        CameraView(f"camera_{index + 1}", camera, layout.image_size_px, None, None if boxes is None else boxes[index])
        for index, camera in enumerate(room_cameras(layout))
    )
    recording = MultiViewRecording("room", views, len(truth.positions_m), 15.0, np.array([[0, 0], [5, 6]]), truth)
    return PomDetector(recording, PARAMETERS)


@pytest.mark.slow
def test_pom_finds_the_people_of_the_rendered_room_from_foreground_masks():
    layout = RoomLayout()
    truth = room_truth(layout, people=2, frames=21, seed=2)
    renderer = RoomRenderer(layout, truth, seed=2)
    detector = room_detector(layout, truth)
    for frame in (0, 10, 20):
        # Foreground: where a frame differs from the empty room by more than the sensor noise allows.
        masks = [
            np.abs(renderer.image(view, frame).astype(int) - renderer.backgrounds[view].astype(int)).max(axis=2) > 25
            for view in range(4)
        ]
        q_map, candidates = detector.detect(frame, masks)
        assert detector.last is not None and detector.last.converged
        found = candidates.select(candidates.strength >= PARAMETERS.min_probability)
        assert len(found) == 2
        distance_m = np.linalg.norm(found.position_m[:, None] - truth.positions_m[frame][None], axis=-1)
        assert np.all(distance_m.min(axis=0) < 0.25)
        assert q_map.shape == detector.grid.shape and np.all((q_map > 0) & (q_map < 1))


def test_boxes_stand_in_for_the_masks_of_views_without_video():
    layout = RoomLayout(image_size_px=(320, 240), focal_px=156.0)
    truth = room_truth(layout, people=1, frames=3, seed=4)
    # Each view's detector finds the person: the box of the model's person, with a ghost of low score.
    boxes = []
    for camera in room_cameras(layout):
        per_frame = []
        for frame in range(3):
            left, top, right, bottom = person_box_px(camera, truth.positions_m[frame], 1.75, 0.5)[0]
            per_frame.append(np.array([[left, top, right - left, bottom - top, 0.9], [10.0, 10.0, 40.0, 90.0, 0.2]]))
        boxes.append(per_frame)
    detector = room_detector(layout, truth, boxes)
    for frame in range(3):
        _, candidates = detector.detect(frame)
        found = candidates.select(candidates.strength >= PARAMETERS.min_probability)
        assert len(found) == 1
        assert np.linalg.norm(found.position_m[0] - truth.positions_m[frame, 0]) < 0.2
    # A view with neither a mask nor boxes is left out; a mask of the wrong size is refused.
    assert room_detector(layout, truth).view_masks(0) == [None] * 4
    with pytest.raises(ValueError, match="working image"):
        detector.solver.posterior([np.zeros((5, 5))] * 4, PARAMETERS)


def test_boxes_scale_about_their_feet():
    # Centre 20 px, bottom 100 px: 1.5 times as wide (30 px), half as tall (40 px).
    scaled = scaled_about_feet(np.array([[10.0, 20.0, 30.0, 100.0]]), (1.5, 0.5))
    np.testing.assert_allclose(scaled, [[5.0, 60.0, 35.0, 100.0]])


def test_a_views_box_scales_are_the_median_ratio_of_its_matched_boxes_to_the_models():
    layout = RoomLayout(image_size_px=(320, 240), focal_px=156.0)
    truth = room_truth(layout, people=2, frames=12, seed=4)
    cameras = room_cameras(layout)
    scale = {0: (1.2, 0.9), 1: (0.8, 1.1), 2: (1.2, 0.9), 3: (1.2, 0.9)}
    boxes = []
    for index, camera in enumerate(cameras):
        per_frame = []
        for frame in range(12):
            model = scaled_about_feet(person_box_px(camera, truth.positions_m[frame], 1.75, 0.5), scale[index])
            found = np.c_[model[:, :2], model[:, 2:] - model[:, :2], np.full(2, 0.9)]
            # A box far from anybody's feet, and one of too low a score: neither is matched.
            per_frame.append(np.r_[found, [[5.0, 5.0, 20.0, 60.0, 0.9], [*found[0, :4], 0.1]]])
        boxes.append(per_frame if index != 3 else per_frame[:4] + [np.zeros((0, 5))] * 8)
    recording = room_detector(layout, truth, boxes).recording
    assert np.all(np.isfinite(person_box_px(cameras[0], truth.positions_m[:12].reshape(-1, 2), 1.75, 0.5)))
    scales = fitted_box_scales(recording, truth.positions_m, range(12), PARAMETERS, views=[1, 2, 3])
    # View 0 is not asked for; view 3 has 8 matches, fewer than a fit needs.
    np.testing.assert_allclose(scales, [[1.0, 1.0], [0.8, 1.1], [1.2, 0.9], [1.0, 1.0]], rtol=1e-9)
