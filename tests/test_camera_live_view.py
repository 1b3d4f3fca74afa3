"""Live views as a real PTZ camera takes them: the values drawn per view, and the images rendered with them."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ptztrack.camera import live_view
from ptztrack.camera.parameters import LiveViewParameters
from ptztrack.camera.virtual import virtual_ptz
from ptztrack.geometry.calibration import load_pinhole

EXCERPT = Path(__file__).parent / "data" / "pets_s2l1_excerpt"
VIRTUAL, CENTRE_POSE = virtual_ptz(load_pinhole(EXCERPT / "pinhole.json"), image_size_px=(320, 240))
MODEL = LiveViewParameters(
    roll_max_deg=2.0,
    principal_offset_max_px=10.0,
    offset_image_width_px=640,
    k1_wide=-0.15,
    k1_tele=0.0,
    tele_zoom=4.0,
    gain=(0.7, 1.3),
    brightness_max=20.0,
    jpeg_quality=75,
    seed=0,
)
# Larger departures, neutral light and nearly lossless compression: the geometry alone.
CLEAN = replace(
    MODEL, roll_max_deg=5.0, principal_offset_max_px=20.0, gain=(1.0, 1.0), brightness_max=0.0, jpeg_quality=100
)

poses = st.tuples(st.floats(40, 70), st.floats(5, 30), st.floats(1, 4)).map(np.array)


@settings(max_examples=100, deadline=None)
@given(pose=poses)
def test_a_views_values_lie_in_their_ranges_and_belong_to_its_pose(pose):
    conditions = live_view.view_conditions(MODEL, pose)
    assert abs(conditions.lens.roll_deg) <= 2.0
    assert np.hypot(*conditions.lens.principal_offset_px) <= 10.0
    assert 0.7 <= conditions.gain <= 1.3 and abs(conditions.brightness) <= 20.0
    assert conditions.lens.k1 == live_view.k1_at_zoom(MODEL, pose[2])
    # The same pose, of the same camera unit, always looks the same; another unit differs.
    assert live_view.view_conditions(MODEL, pose.copy()) == conditions
    assert live_view.view_conditions(replace(MODEL, seed=1), pose) != conditions


def test_views_at_different_poses_draw_their_values_over_the_whole_ranges():
    rng = np.random.default_rng(5)
    drawn = [live_view.view_conditions(MODEL, [rng.uniform(40, 70), rng.uniform(5, 30), 2.0]) for _ in range(400)]
    roll_deg = np.array([c.lens.roll_deg for c in drawn])
    offset_px = np.array([np.hypot(*c.lens.principal_offset_px) for c in drawn])
    assert roll_deg.min() < -1.8 and roll_deg.max() > 1.8
    # Uniform over the disc: half the offsets lie beyond radius 10 / sqrt(2).
    assert np.mean(offset_px > 10.0 / np.sqrt(2)) == pytest.approx(0.5, abs=0.08)


def test_distortion_falls_linearly_from_the_wide_to_the_tele_end_and_stays():
    assert live_view.k1_at_zoom(MODEL, 1.0) == pytest.approx(-0.15)
    assert live_view.k1_at_zoom(MODEL, 2.5) == pytest.approx(-0.075)
    assert live_view.k1_at_zoom(MODEL, 4.0) == pytest.approx(0.0)
    assert live_view.k1_at_zoom(MODEL, 6.0) == pytest.approx(0.0)


def blob_frame(centre_px, sigma_px=5.0) -> np.ndarray:
    """A 768 x 576 recorded frame, black but for a Gaussian blob at ``centre_px`` (pixel centres at +0.5)."""
    u, v = np.meshgrid(np.arange(768) + 0.5, np.arange(576) + 0.5)
    blob = 250 * np.exp(-((u - centre_px[0]) ** 2 + (v - centre_px[1]) ** 2) / (2 * sigma_px**2))
    return np.repeat(blob[..., None], 3, axis=2).astype(np.uint8)


def centroid_px(image) -> np.ndarray:
    weight = image[..., 1].astype(float)
    v, u = np.mgrid[: image.shape[0], : image.shape[1]] + 0.5
    return np.array([(weight * u).sum(), (weight * v).sum()]) / weight.sum()


@pytest.mark.parametrize("offset", [[0.0, 0.0, 0.0], [3.0, 2.0, 0.0], [-4.0, -1.0, 1.5]])
def test_a_recorded_point_appears_in_the_live_view_where_its_projection_puts_it(offset):
    pose = CENTRE_POSE + offset
    recorded_px = np.array([300.0, 350.0])
    image = live_view.render_live(VIRTUAL, blob_frame(recorded_px), pose, CLEAN)
    expected = live_view.recorded_to_live(VIRTUAL, recorded_px[None], pose, CLEAN)[0]
    np.testing.assert_allclose(centroid_px(image), expected, atol=0.1)
    # The exact pinhole view puts the point elsewhere: the departures are seen.
    assert np.linalg.norm(centroid_px(VIRTUAL.render(blob_frame(recorded_px), pose)) - expected) > 0.5


def test_the_live_view_is_relit_by_its_gain_and_brightness_and_compressed():
    pose = CENTRE_POSE + [1.0, 1.0, 0.5]
    grey = np.full((576, 768, 3), 100, dtype=np.uint8)
    conditions = live_view.view_conditions(MODEL, pose)
    image = live_view.render_live(VIRTUAL, grey, pose, replace(MODEL, jpeg_quality=100))
    assert np.median(image) == pytest.approx(100 * conditions.gain + conditions.brightness, abs=1.0)
    textured = np.random.default_rng(0).integers(0, 256, (576, 768, 3)).astype(np.uint8)
    lossless = live_view.render_live(VIRTUAL, textured, pose, replace(MODEL, jpeg_quality=100))
    compressed = live_view.render_live(VIRTUAL, textured, pose, MODEL)
    assert np.abs(compressed.astype(int) - lossless.astype(int)).mean() > 2.0


def test_without_a_model_the_camera_renders_the_exact_view():
    frame = blob_frame([400.0, 300.0])
    np.testing.assert_array_equal(
        live_view.render_view(VIRTUAL, frame, CENTRE_POSE, None), VIRTUAL.render(frame, CENTRE_POSE)
    )
