"""The synthetic plaza: PETS 2009 S2.L1's cameras, people drawn where the truth puts them, pairs that
keep their spacing, and the experiment's rows."""

import json
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np
import pytest

from ptztrack.builders.occupancy_synthetic import plaza_layout, plaza_recording, plaza_renderer
from ptztrack.cli import main
from ptztrack.config import pets_dataset
from ptztrack.geometry.calibration import camera_centre_m, in_image, load_tsai, pinhole_from_tsai, project_pinhole
from ptztrack.occupancy.plaza import plaza_truth
from ptztrack.scene.pets import load_mot_ground_truth
from ptztrack.scene.render import body_cones, draw_people, random_outfit

FRAMES = 12
CALIBRATIONS = {view.name: Path(view.calibration).with_name(f"{view.name}.xml") for view in pets_dataset().views}
WHITE = replace(random_outfit(np.random.default_rng(0)), legs=(255, 255, 255), torso=(255, 255, 255))


@pytest.fixture(scope="module")
def renderer():
    return plaza_renderer(people=8, frames=FRAMES, seed=4)


def tsai_ground_points(view: str, step_px: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Pixels (N, 2) of the view on a grid and the ground points (N, 3) mm that Tsai's model images
    there (its distortion inverted in closed form: r_u = r_d (1 + kappa1 r_d^2)); only pixels whose
    ray goes down to the ground and that lie where the distortion grows outwards."""
    tsai = load_tsai(CALIBRATIONS[view])
    width, height = tsai.image_size_px
    u, v = np.meshgrid(np.arange(0, width, step_px) + 0.5, np.arange(0, height, step_px) + 0.5)
    pixels = np.stack([u.ravel(), v.ravel()], axis=-1)
    x_mm = (pixels[:, 0] - tsai.centre_px[0]) * tsai.dpx_mm / tsai.sx
    y_mm = (pixels[:, 1] - tsai.centre_px[1]) * tsai.dy_mm
    squared = x_mm**2 + y_mm**2
    scale = 1 + tsai.kappa1 * squared
    in_camera = np.stack([x_mm * scale, y_mm * scale, np.full_like(x_mm, tsai.focal_mm)], axis=-1)
    direction = in_camera @ tsai.rotation  # R^T d for each row d
    centre_mm = -tsai.rotation.T @ np.asarray(tsai.translation_mm)
    along = -centre_mm[2] / direction[:, 2]
    usable = (along > 0) & (3 * tsai.kappa1 * squared + 1 > 0)
    return pixels[usable], centre_mm + along[usable, None] * direction[usable]


# pinhole_from_tsai fits OpenCV's three radial coefficients to Tsai's distortion: exact for views
# 1, 3 and 4, within a third of a pixel for 5 and 6; View_008's stronger distortion leaves 2 px at the
# corners, and View_007's (kappa1 = -0.062 /mm^2, turning back at 2.3 mm, inside the image's
# corners) up to 21 px: the polynomial cannot follow it, on PETS as in the plaza.
CONVERSION_PX = {
    "View_001": 0.05,
    "View_003": 0.05,
    "View_004": 0.05,
    "View_005": 0.2,
    "View_006": 0.4,
    "View_007": 25.0,
    "View_008": 2.5,
}


@pytest.mark.slow
def test_the_plaza_sees_through_petss_calibrations():
    recording = plaza_recording(people=2, frames=2, seed=0)
    assert [view.name for view in recording.views] == list(CONVERSION_PX)
    assert recording.frame_rate_hz == pets_dataset().frame_rate_hz == 10.0
    # The band S2.L1's people walk in: 90 % of its annotated positions along each axis, inside its area.
    (x0, y0), (x1, y1) = recording.area_m
    walked_m = load_mot_ground_truth(pets_dataset().ground_truth).ground_m
    for axis, (low, high) in enumerate([(x0, x1), (y0, y1)]):
        inside = np.mean((walked_m[:, axis] >= low) & (walked_m[:, axis] <= high))
        assert inside == pytest.approx(0.90, abs=0.005)
    pets_area_m = np.asarray(pets_dataset().area_m)
    assert np.all(recording.area_m[0] >= pets_area_m[0]) and np.all(recording.area_m[1] <= pets_area_m[1])
    for view in recording.views:
        pixels, ground_mm = tsai_ground_points(view.name)
        assert len(pixels) > 2000
        error_px = np.abs(project_pinhole(view.calibration, ground_mm) - pixels).max()
        assert error_px < CONVERSION_PX[view.name], (view.name, error_px)
        tsai = load_tsai(CALIBRATIONS[view.name])
        assert view.image_size_px == tsai.image_size_px
        assert view.frames is not None and view.frames(1).shape == (tsai.image_size_px[1], tsai.image_size_px[0], 3)
        assert view.boxes is None


def test_every_camera_stands_inside_the_stage(renderer):
    (x0, y0), (x1, y1) = renderer.stage.bounds_m
    for camera in renderer.cameras:
        x, y, z = camera_centre_m(camera)
        assert x0 < x < x1 and y0 < y < y1 and 0 < z < renderer.stage.height_m


@pytest.mark.slow
def test_people_are_drawn_where_the_truth_puts_them(renderer):
    """Each person drawn alone on black: the pixel of their feet lies in their silhouette's convex hull
    (the point between the feet, which stride apart, within a pixel), at its bottom (within 5 % of its
    height), and the pixel of
    their waist lies in the silhouette, in every view that sees both."""
    truth = renderer.truth
    checked = 0
    for view, (camera, (width, height)) in enumerate(zip(renderer.cameras, renderer.image_sizes_px, strict=True)):
        for frame in (0, FRAMES - 1):
            for person, person_cones in enumerate(renderer.people_cones(frame)):
                x, y = truth.positions_m[frame, person]
                body_mm = np.array([[x, y, 0.0], [x, y, 0.5 * truth.heights_m[person]]]) * 1000.0
                if not in_image(camera, (width, height), body_mm).all():
                    continue
                drawn = draw_people(np.zeros((height, width, 3), np.uint8), camera, [person_cones], [WHITE])
                silhouette = drawn.max(axis=-1) > 0
                rows, columns = np.nonzero(silhouette)
                hull = cv2.convexHull(np.stack([columns, rows], axis=-1).astype(np.int32))
                (feet_u, feet_v), (waist_u, waist_v) = np.floor(project_pinhole(camera, body_mm)).astype(int)
                where = (view, frame, person)
                assert cv2.pointPolygonTest(hull, (float(feet_u), float(feet_v)), True) >= -1.0, where
                # The nearer foot, up to 0.22 m ahead in the stride, reaches a little lower.
                assert abs(rows.max() - feet_v) <= 2 + 0.05 * (rows.max() - rows.min()), where
                assert silhouette[waist_v, waist_u], where
                checked += 1
    assert checked > 30


def test_the_rendered_frames_show_people_at_their_feet(renderer):
    """In the rendered frame, the image differs from the empty plaza at a person's waist."""
    truth, frame = renderer.truth, FRAMES - 1
    for view, (camera, size_px) in enumerate(zip(renderer.cameras, renderer.image_sizes_px, strict=True)):
        changed = np.abs(renderer.image(view, frame).astype(int) - renderer.backgrounds[view]).max(axis=-1) > 20
        for person in range(truth.positions_m.shape[1]):
            x, y = truth.positions_m[frame, person]
            waist_mm = np.array([[x, y, 0.55 * truth.heights_m[person]]]) * 1000.0
            if in_image(camera, size_px, waist_mm)[0]:
                u, v = np.floor(project_pinhole(camera, waist_mm)[0]).astype(int)
                assert changed[v - 1 : v + 2, u - 1 : u + 2].any(), (view, person)


def test_a_person_past_the_fold_of_the_distortion_is_not_drawn():
    """View_001's distortion polynomial folds a person 65 degrees off its axis (the image is 25 degrees
    wide) back into the image; the renderer does not draw them."""
    camera = pinhole_from_tsai(load_tsai(CALIBRATIONS["View_001"]))
    centre_m = camera_centre_m(camera)
    heading = np.arctan2(camera.R[2, 1], camera.R[2, 0]) - np.radians(65.0)  # the optical axis on the ground
    feet_m = centre_m[:2] + 10.0 * np.array([np.cos(heading), np.sin(heading)])
    body_mm = np.array([[*feet_m, z] for z in (0.0, 0.9, 1.8)]) * 1000.0
    folded_px = project_pinhole(camera, body_mm)
    assert np.all((folded_px >= 0) & (folded_px < [768, 576])) and not in_image(camera, (768, 576), body_mm).any()
    image = draw_people(np.zeros((576, 768, 3), np.uint8), camera, [body_cones(feet_m, 0.0, 0.0, 1.8, 0.5)], [WHITE])
    assert image.max() == 0


@pytest.mark.parametrize("people, pairs", [(4, 2), (8, 3)])
def test_pairs_walk_side_by_side_at_their_spacing(people, pairs):
    layout = plaza_layout()
    truth = plaza_truth(layout, people, 150, seed=2)
    (x0, y0), (x1, y1) = layout.area_m
    positions = truth.positions_m
    assert np.all((positions[..., 0] >= x0) & (positions[..., 0] <= x1))
    assert np.all((positions[..., 1] >= y0) & (positions[..., 1] <= y1))
    assert np.all((truth.heights_m >= 1.6) & (truth.heights_m <= 1.9)) and truth.frame_rate_hz == 10.0
    distance = np.linalg.norm(positions[:, :, None] - positions[:, None, :], axis=-1)
    for leader in range(0, 2 * pairs, 2):
        follower = positions[:, leader + 1]
        # Away from the border, where the follower is not held inside the area, the spacing is exact.
        away = np.all((follower > [x0 + 0.01, y0 + 0.01]) & (follower < [x1 - 0.01, y1 - 0.01]), axis=-1)
        assert away.mean() > 0.5
        np.testing.assert_allclose(distance[away, leader, leader + 1], layout.pair_spacing_m, atol=1e-9)
        assert 0.5 <= layout.pair_spacing_m <= 0.7
    # Those walking alone do not keep to anybody.
    for single in range(2 * pairs, people):
        others = np.delete(distance[:, single], single, axis=-1)
        assert np.ptp(others.min(axis=-1)) > 1.0


@pytest.mark.slow
def test_the_plaza_experiment_rows_have_lpom_and_the_baseline_for_each_crowd(tmp_path):
    """(Every method's rows are checked on PETS, test_occupancy_evaluation.py.)"""
    rows_path = tmp_path / "plaza.json"
    command = ["experiment", "occupancy", "synthetic-plaza", "--frames", "4", "--lead-in", "2", "--methods"]
    assert main([*command, "--json", str(rows_path)]) == 0
    rows = json.loads(rows_path.read_text())
    methods = ("lpom", "clustering")
    assert [(row["method"], row["people"]) for row in rows] == [
        (method, people) for people in (4, 8) for method in methods
    ]
    for row in rows:
        assert row["views"] == 7 and row["frames"] == 4 and row["dataset"] == f"plaza-{row['people']}"
        assert {"moda", "modp", "precision", "recall", "error_m"} <= set(row)
    assert all({"mota", "motp_m", "idf1"} <= set(row) for row in rows if row["method"] != "clustering")
