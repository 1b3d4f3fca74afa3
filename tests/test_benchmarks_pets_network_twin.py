import sys
from pathlib import Path

import numpy as np

from ptztrack.builders.pets_network import published_views
from ptztrack.builders.recording import pets_scenario
from ptztrack.geometry.calibration import project_pinhole
from ptztrack.types import GroundTruth

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import pets_network_twin  # noqa: E402


def test_a_turned_calibration_keeps_its_optical_centre_and_turns_by_the_drawn_angles():
    view = published_views(pets_scenario("hog"))[0]
    turned = pets_network_twin.turned_calibration(view.calibration, 0.5, np.random.default_rng(4))
    np.testing.assert_allclose(turned.R.T @ turned.t, view.calibration.R.T @ view.calibration.t, rtol=1e-12)
    angle_deg = np.rad2deg(np.arccos((np.trace(turned.R @ view.calibration.R.T) - 1) / 2))
    expected_deg = np.linalg.norm(np.random.default_rng(4).normal(0.0, 0.5, 3))
    np.testing.assert_allclose(angle_deg, expected_deg, rtol=1e-6)


def test_a_walker_alone_in_view_is_boxed_where_its_feet_and_head_project(monkeypatch):
    """With no noise, no misses and no ghosts, the box of the one walker has its bottom centre at the
    walker's feet and its top at its head, through the view's calibration."""
    for name, value in (("BOX_NOISE_PX", 0.0), ("FIXED_RECALL", 1.0), ("GHOSTS_PER_FRAME", 0.0)):
        monkeypatch.setattr(pets_network_twin, name, value)
    view = published_views(pets_scenario("hog"))[2]
    truth = GroundTruth(np.array([[[-8.0, -5.0]], [[np.nan, np.nan]]]), np.array([1.7]), np.array([0.5]), 5.0)
    boxes = pets_network_twin.walker_boxes(truth, view.calibration, view.image_size_px, np.random.default_rng(0))
    feet_px, head_px = project_pinhole(
        view.calibration, np.array([[-8000.0, -5000.0, 0.0], [-8000.0, -5000.0, 1700.0]])
    )
    ((left, top, width, height, score),) = boxes[0]
    np.testing.assert_allclose([left + width / 2, top + height], feet_px, atol=1e-9)
    np.testing.assert_allclose(top, head_px[1], atol=1e-9)
    assert score == 1.0 and len(boxes[1]) == 0
