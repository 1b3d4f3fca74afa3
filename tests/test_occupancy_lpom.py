import numpy as np
import pytest
from scipy.stats import multivariate_normal

from ptztrack.builders.occupancy_synthetic import room_recording
from ptztrack.occupancy.detectors import LpomDetector, lpom_parameters
from ptztrack.occupancy.locus import PERSON
from ptztrack.occupancy.lpom import (
    GroundGrid,
    LocusSampling,
    block_counts,
    locus_table,
    map_modes,
    most_modes,
    occupancy_map,
    points_map,
    sampled_heights,
    table_map,
)
from ptztrack.occupancy.motion_edges import box_outline_points
from ptztrack.occupancy.parameters import OccupancyParameters
from ptztrack.occupancy.room import RoomLayout, room_cameras


@pytest.mark.slow
def test_a_single_person_in_the_synthetic_room_gives_one_mode_near_the_truth():
    recording = room_recording(people=1, frames=6, seed=3)
    detector = LpomDetector(recording, lpom_parameters(OccupancyParameters()))
    for frame in range(recording.frames):
        pom, modes = detector.detect(frame)
        if frame == 0:
            assert len(modes) == 0  # no previous frame, no motion
            continue
        strong = modes.select(modes.strength >= 0.2)
        assert len(strong) == 1
        truth_m = recording.truth.positions_m[frame, 0]
        assert np.linalg.norm(strong.position_m[0] - truth_m) < 0.1
        assert np.all(np.linalg.eigvalsh(strong.covariance_m2[0]) > 0)
        assert 0.98 < pom.sum() <= 1.0 + 1e-9  # the kernel carries a little past the grid's edges


def test_the_precomputed_table_gives_the_loci_of_the_block_centres():
    layout = RoomLayout(image_size_px=(64, 48), focal_px=40.0)
    camera = room_cameras(layout)[0]
    grid = GroundGrid.covering([[0, 0], [5, 6]], 0.1)
    sampling = LocusSampling(PERSON, sampled_heights(1.6, 1.9, 0.1), 8)
    table = locus_table(camera, layout.image_size_px, grid, sampling, block_px=4)
    mask = np.zeros((48, 64), bool)
    mask[20:24, 8:12] = True  # one whole block, (row 5, column 2)
    mask[40, 60] = True  # one pixel of block (10, 15)
    expected = 16 * points_map(camera, [[10.0, 22.0]], grid, sampling) + points_map(
        camera, [[62.0, 42.0]], grid, sampling
    )
    np.testing.assert_allclose(table_map(table, mask), expected, rtol=1e-5, atol=1e-6)
    assert table.megabytes > 0


def test_block_counts_sum_the_pixels_of_each_block():
    mask = np.zeros((9, 10), bool)
    mask[0, 0] = mask[1, 1] = mask[3, 4] = mask[8, 9] = True
    np.testing.assert_array_equal(block_counts(mask, 2), [[2, 0, 0, 0, 0], [0, 0, 1, 0, 0], [0] * 5, [0] * 5])


def test_each_view_weighs_its_weight_whatever_its_number_of_pixels():
    grid = GroundGrid((0.0, 0.0), 1.0, (1, 3))
    pom = occupancy_map([np.array([100.0, 0, 0]), np.array([0, 0, 1.0])], [1.0, 3.0], grid, kernel_sigma_m=1e-6)
    np.testing.assert_allclose(pom, [[0.25, 0.0, 0.75]])
    assert np.all(occupancy_map([np.zeros(3)], [1.0], grid, 0.5) == 0)


def test_modes_give_mean_and_covariance_of_gaussian_bumps_and_respect_the_separation():
    grid = GroundGrid.covering([[0, 0], [6, 6]], 0.05)
    rows, columns = np.mgrid[0 : grid.shape[0], 0 : grid.shape[1]]
    centres = grid.centre_of(rows, columns)
    covariance = np.array([[0.01, 0.004], [0.004, 0.02]])
    pom = multivariate_normal([2.013, 3.021], covariance).pdf(centres)
    pom += 0.5 * multivariate_normal([4.5, 1.5], 0.01 * np.eye(2)).pdf(centres)
    pom += 0.3 * multivariate_normal([4.5, 1.9], 0.01 * np.eye(2)).pdf(centres)  # 0.4 m from a stronger one
    modes = map_modes(pom, grid, separation_m=0.5, window_m=0.6, min_strength=0.05)
    assert len(modes) == 2
    np.testing.assert_allclose(modes.position_m[0], [2.013, 3.021], atol=2e-3)
    np.testing.assert_allclose(modes.covariance_m2[0], covariance, atol=1.5e-3)
    # Peak heights: 0.5 / (2 pi 0.01) against 1 / (2 pi sqrt(det covariance)), less the grid's sampling.
    assert modes.strength[0] == 1.0
    assert modes.strength[1] == pytest.approx(0.5 * np.sqrt(np.linalg.det(covariance)) / 0.01, abs=0.05)
    assert len(map_modes(pom, grid, 0.5, 0.6, min_strength=0.7)) == 1


def test_no_map_has_more_modes_than_most_modes_bounds():
    """Noise, a map of many local maxima, every one kept: the bound holds, within a factor of 8 (5 to 6.5
    on this noise: the discs of random maxima pack less densely than the bound's squares)."""
    grid = GroundGrid((0.0, 0.0), 0.05, (200, 240))
    noise = np.random.default_rng(0).random(grid.shape)
    for separation_m in (0.05, 0.2, 0.5, 2.0):
        found = len(map_modes(noise, grid, separation_m, 0.1, min_strength=0.0))
        assert found <= most_modes(grid, separation_m) <= 8 * found, separation_m


def test_sampled_heights_are_the_midpoints_of_algorithm_1s_steps():
    assert sampled_heights(1.6, 1.9, 0.1) == pytest.approx((1.65, 1.75, 1.85))
    assert sampled_heights(1.7, 1.7, 0.1) == pytest.approx((1.75,))


def test_box_outline_points_lie_on_the_outline_evenly():
    points = box_outline_points([[10.0, 20.0, 4.0, 6.0], [0.0, 0.0, 1.0, 1.0]], 20)
    assert points.shape == (40, 2)
    first = points[:20]
    on_side = np.isclose(first[:, 0], 10) | np.isclose(first[:, 0], 14) | np.isclose(first[:, 1], 20)
    on_side |= np.isclose(first[:, 1], 26)
    assert np.all(on_side)
    assert np.all((first >= [10, 20]) & (first <= [14, 26]))
    steps = np.linalg.norm(np.diff(np.vstack([first, first[:1]]), axis=0), axis=1)
    assert np.all(steps <= 1.0 + 1e-9)  # perimeter 20 in 20 steps, corners cut short
