"""A camera's geometry from its own pictures' correspondences (ptztrack.geometry.self_calibration): the
widest focal length from rotations, the zoom's scales, the pose from ground points, and the checks on
those points."""

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ptztrack.config import ScenarioError
from ptztrack.config.ground_points import load_ground_points
from ptztrack.geometry.ptz import PTZCamera, projection_matrix
from ptztrack.geometry.registration import rotation_homography
from ptztrack.geometry.self_calibration import (
    ecc_zoom_ratio,
    fit_head,
    focals_from_ratios,
    ground_points_problem,
    ground_pose,
    zoom_ratio,
)

SIZE_PX = (160, 120)


def test_the_head_of_noisy_turns_is_found_within_one_percent():
    """Eight turns of a 236 px camera looking 17 deg down, by normalised steps of +-0.15 pan and +-0.2
    tilt (both ways and the diagonals) at 90 and -50 deg per unit, 100 points each with 0.3 px noise: the
    focal length within 1 % and its standard deviation honest (the error within three), the degrees per
    unit within 1 %, the depression within 1 deg; a wrongly matched pair is left out."""
    rng = np.random.default_rng(3)
    focal_px, pan_per_unit, tilt_per_unit, tilt_deg = 236.0, 90.0, -50.0, 17.0
    camera = PTZCamera((0.0, 0.0, 5.0), SIZE_PX[0], SIZE_PX[1], focal_px)
    steps = np.array([[1, 0], [-1, 0], [0, 1], [0, -1], [1, 1], [-1, -1], [1, -1], [-1, 1]]) * [0.15, 0.2]
    matches = []
    for step in steps:
        start, turned = (
            np.array([0.0, tilt_deg, 1.0]),
            np.array([pan_per_unit * step[0], tilt_deg + tilt_per_unit * step[1], 1.0]),
        )
        points = rng.uniform([0, 0], SIZE_PX, (100, 2))
        moved = np.c_[points, np.ones(100)] @ rotation_homography(camera, start, turned).T
        moved = moved[:, :2] / moved[:, 2:]
        inside = np.all((moved >= 0) & (moved <= SIZE_PX), axis=1)
        if inside.sum() >= 12:
            noisy = moved[inside] + rng.normal(0, 0.3, (int(inside.sum()), 2))
            matches.append((np.zeros(2), step, points[inside], noisy))
    # A pair RANSAC matched wrongly (a shift no turn of the head makes) is left out.
    wrong = rng.uniform([0, 0], SIZE_PX, (60, 2))
    matches.append((np.zeros(2), np.array([0.15, 0.0]), wrong, wrong + [-20.0, 35.0]))
    fit = fit_head(matches, SIZE_PX, (100.0, -45.0), 160.0)
    assert fit.pairs == len(matches) - 1
    assert abs(fit.focal_px / focal_px - 1) < 0.01
    assert abs(fit.focal_px - focal_px) < 3 * fit.focal_sd_px
    assert fit.pan_deg_per_unit == pytest.approx(pan_per_unit, rel=0.01)
    assert fit.tilt_deg_per_unit == pytest.approx(tilt_per_unit, rel=0.01)
    assert fit.tilt_deg == pytest.approx(tilt_deg, abs=1.0)


def test_a_zoom_about_the_centre_is_measured_exactly():
    rng = np.random.default_rng(0)
    points = rng.uniform([0, 0], SIZE_PX, (50, 2))
    centre = np.array(SIZE_PX) / 2.0
    zoomed = 1.37 * (points - centre) + centre + [0.4, -0.2]
    ratio, ratio_sd = zoom_ratio(points, zoomed, SIZE_PX)
    assert ratio == pytest.approx(1.37, abs=1e-12) and ratio_sd < 1e-9


def test_ecc_measures_a_blurred_zoom_about_the_centre_and_refuses_a_uniform_picture():
    """A smooth texture (160 x 120, features too soft for SIFT) and the same magnified 1.2 times about the
    image centre: ECC's scale within 0.3 % from a start at 1.15; a uniform picture gives None."""
    rng = np.random.default_rng(5)
    texture = cv2.GaussianBlur(rng.normal(128, 40, (120, 160)).astype(np.float32), (0, 0), 2.5)
    wide = cv2.merge([np.clip(texture * 4 - 384, 0, 255).astype(np.uint8)] * 3)
    centre = (159 / 2, 119 / 2)  # OpenCV's pixel centres are at integers
    zoomed = cv2.warpAffine(wide, cv2.getRotationMatrix2D(centre, 0.0, 1.2), (160, 120), flags=cv2.INTER_CUBIC)
    assert ecc_zoom_ratio(wide, zoomed, 1.15) == pytest.approx(1.2, rel=3e-3)
    assert ecc_zoom_ratio(np.full_like(wide, 128), np.full_like(wide, 128), 1.15) is None


def test_focal_lengths_from_scales_one_and_two_steps_apart():
    """Consistent scales give the products exactly; the widest's relative uncertainty carries to every step."""
    focals = np.array([200.0, 260.0, 330.0, 420.0])
    ratios = [(i, j, focals[j] / focals[i], 0.001) for i in range(4) for j in range(i + 1, min(i + 3, 4))]
    found, found_sd = focals_from_ratios(200.0, 2.0, 3, ratios)
    assert np.allclose(found, focals, rtol=1e-12)
    assert np.all(found_sd / found >= 0.01 - 1e-12) and found_sd[0] == pytest.approx(2.0)


@settings(max_examples=25, deadline=None)
@given(
    pan_deg=st.floats(-170, 170),
    tilt_deg=st.floats(10, 40),
    height_m=st.floats(3, 15),
)
def test_the_pose_from_exact_ground_points_round_trips(pan_deg, tilt_deg, height_m):
    """Ground points projected through a level camera give back its position, pan and tilt exactly, and no roll."""
    camera = PTZCamera((3.0, -7.0, height_m), SIZE_PX[0], SIZE_PX[1], 236.0)
    pose = np.array([pan_deg, tilt_deg, 1.0])
    pixels = np.array([[20.0, 70.0], [140.0, 75.0], [30.0, 110.0], [130.0, 112.0], [80.0, 90.0], [60.0, 100.0]])
    # The ground point seen at each pixel: the ray through it met with z = 0.
    P = projection_matrix(camera, pose)
    H = P[:, [0, 1, 3]]
    ground = np.c_[pixels, np.ones(len(pixels))] @ np.linalg.inv(H).T
    ground = ground[:, :2] / ground[:, 2:]
    # Columns of one array, as a ground points file gives them: not contiguous.
    table = np.c_[pixels, ground]
    found = ground_pose(table[:, :2], table[:, 2:], 236.0, SIZE_PX)
    assert np.allclose(found.position_m, camera.position_m, atol=1e-6)
    assert (found.pan_deg - pan_deg + 180) % 360 - 180 == pytest.approx(0.0, abs=1e-6)
    assert found.tilt_deg == pytest.approx(tilt_deg, abs=1e-6)
    assert abs(found.roll_deg) < 1e-6 and found.rms_px < 1e-6


def test_ground_points_that_cannot_place_a_camera_are_named():
    square = np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0], [10.0, 10.0]])
    pixels = np.array([[10.0, 10.0], [150.0, 10.0], [10.0, 110.0], [150.0, 110.0]])
    assert ground_points_problem(pixels, square, SIZE_PX) is None
    assert "at least 4" in ground_points_problem(pixels[:3], square[:3], SIZE_PX)
    line = np.c_[np.arange(4.0), 2 * np.arange(4.0)]
    assert "one line" in ground_points_problem(pixels, line, SIZE_PX)
    outside = pixels + [[0, 0], [20, 0], [0, 0], [0, 0]]
    assert "outside the 160x120 px picture" in ground_points_problem(outside, square, SIZE_PX)
    assert "share" in ground_points_problem(pixels, np.r_[square[:3], square[:1]], SIZE_PX)


def test_ground_points_files_in_yaml_and_csv(tmp_path):
    (tmp_path / "points.csv").write_text("u_px,v_px,x_m,y_m\n1,2,3,4\n5,6,7,8\n")
    points = load_ground_points(tmp_path / "points.csv")
    assert points.pixels_px.tolist() == [[1, 2], [5, 6]] and points.ground_m.tolist() == [[3, 4], [7, 8]]
    (tmp_path / "points.yaml").write_text("snapshot: ground.png\npoints:\n  - [1, 2, 3, 4]\n")
    points = load_ground_points(tmp_path / "points.yaml")
    assert points.snapshot == tmp_path / "ground.png" and points.ground_m.tolist() == [[3, 4]]
    (tmp_path / "bad.csv").write_text("u,v,x,y\n1,2,3,4\n")
    with pytest.raises(ScenarioError, match="bad.csv: expected a CSV whose first line is u_px,v_px,x_m,y_m"):
        load_ground_points(tmp_path / "bad.csv")
    (tmp_path / "bad.yaml").write_text("points:\n  - [1, 2, 3]\n")
    with pytest.raises(ScenarioError, match="bad.yaml: points: each point is four numbers"):
        load_ground_points(tmp_path / "bad.yaml")
