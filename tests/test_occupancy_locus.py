import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from ptztrack.geometry.calibration import load_calibration, pixel_rays, project_pinhole
from ptztrack.occupancy.locus import PERSON, ConeModel, person_locus, profile, touching_positions

PETS = "src/ptztrack/data/pets2009_s2l1"


def sphere_locus(camera_height_m, radius_m, elevation_rad, samples=4001):
    """The paper's example: a sphere rho(z) = sqrt(2 R z - z^2) and the ray from (0, 0, H) along (1, 0, tan a)."""
    z_m = np.linspace(0, 2 * radius_m, samples + 2)[1:-1]
    rho = np.sqrt(2 * radius_m * z_m - z_m**2)
    locus = touching_positions(
        np.array([0.0, 0.0, camera_height_m]),
        np.array([1.0, 0.0, np.tan(elevation_rad)]),
        z_m,
        rho,
        (radius_m - z_m) / rho,
        z_m[1] - z_m[0],
    )
    points = locus.position_m.reshape(-1, 2)
    return points[~np.isnan(points[:, 0])]


@pytest.mark.parametrize("height_m, radius_m, elevation_deg", [(3.0, 0.4, -30.0), (6.0, 0.25, -12.0), (2.5, 0.9, -60)])
def test_the_locus_of_a_sphere_is_the_papers_ellipse(height_m, radius_m, elevation_deg):
    a = np.deg2rad(elevation_deg)
    points = sphere_locus(height_m, radius_m, a)
    x0, y0 = points[:, 0], points[:, 1]
    assert len(points) > 1000
    np.testing.assert_allclose(
        (x0 * np.sin(a) + (height_m - radius_m) * np.cos(a)) ** 2 + y0**2, radius_m**2, atol=1e-9
    )
    # The whole ellipse: from the nearest position B to the farthest A, and +-R across the ray.
    near_m, far_m = (((height_m - radius_m) * np.cos(a) + side * radius_m) / -np.sin(a) for side in (-1, 1))
    assert x0.min() == pytest.approx(near_m, abs=2e-3) and x0.max() == pytest.approx(far_m, abs=2e-3)
    assert y0.min() == pytest.approx(-radius_m, abs=2e-3) and y0.max() == pytest.approx(radius_m, abs=2e-3)


def test_a_ray_that_points_up_touches_nothing_below_the_camera():
    assert len(sphere_locus(3.0, 0.4, np.deg2rad(20.0))) == 0


models = st.builds(
    lambda inner, radii, width: ConeModel((0.0, *sorted(set(inner)), 1.0), tuple(radii[: len(set(inner)) + 2]), width),
    st.lists(st.floats(0.05, 0.95), min_size=1, max_size=4),
    st.lists(st.one_of(st.just(0.0), st.floats(0.01, 0.6)), min_size=6, max_size=6),
    st.floats(0.2, 0.8),
)


@settings(max_examples=200, deadline=None)
@example(
    model=ConeModel((0.0, 0.729765336868212, 1.0), (0.0625, 0.0, 0.0), 0.25),
    height_m=2.0,
    camera=(0.0, 0.0, 11.0),
    direction=(0.0, 1.0, -0.0703125),
)
@given(
    model=models,
    height_m=st.floats(1.2, 2.1),
    camera=st.tuples(st.floats(-5, 5), st.floats(-5, 5), st.floats(2.2, 12.0)),
    direction=st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, -0.05)),
)
def test_every_locus_point_puts_the_model_tangent_to_its_ray(model, height_m, camera, direction):
    """At each locus sample, the model standing there has the ray's point on its surface and its normal
    orthogonal to the ray (equation 5's touch constraints)."""
    centre_m, direction = np.array(camera), np.array(direction)
    if np.hypot(direction[0], direction[1]) < 1e-3:
        direction[0] = 1e-3
    positions_m, weights_m = person_locus(model, centre_m, direction[None, :], [height_m], 24)
    points_m, weights_m = positions_m[0], weights_m[0]
    valid = ~np.isnan(points_m[:, 0])
    assert np.all(weights_m[valid] > 0) and np.all(weights_m[~valid] == 0)
    unit = direction / np.linalg.norm(direction)
    z_m = np.repeat((np.arange(24) + 0.5) / 24 * height_m, 2)[valid]
    t_m = (z_m - centre_m[2]) / unit[2]
    on_ray = centre_m + t_m[:, None] * unit
    offset = on_ray[:, :2] - points_m[valid]
    rho, slope = profile(model, z_m, height_m)
    # Rounding grows with the distance along the ray (about 150 m for a shallow ray from 11 m up).
    atol_m = 1e-9 * max(1.0, t_m.max(initial=0.0))
    np.testing.assert_allclose(np.linalg.norm(offset, axis=-1), rho, atol=atol_m)
    # rho times the surface's normal, (offset, -slope rho): no division by a radius that may be tiny.
    scaled_normal = np.concatenate([offset, -(slope * rho)[:, None]], axis=-1)
    np.testing.assert_allclose(scaled_normal @ unit, 0, atol=atol_m)
    assert np.all(t_m > 0)


def test_the_profile_is_piecewise_linear_through_its_knots():
    heights = np.array(PERSON.height_fraction) * 1.8
    radius_m, _ = profile(PERSON, heights, 1.8)
    np.testing.assert_allclose(radius_m, np.array(PERSON.radius_fraction) * PERSON.width_m)
    middle = 0.5 * (heights[:-1] + heights[1:])
    radius_mid, slope = profile(PERSON, middle, 1.8)
    np.testing.assert_allclose(radius_mid, 0.5 * (radius_m[:-1] + radius_m[1:]))
    np.testing.assert_allclose(slope, np.diff(radius_m) / np.diff(heights))


def test_a_cone_model_refuses_knots_out_of_order():
    with pytest.raises(ValueError, match="increase from 0 to 1"):
        ConeModel((0.0, 0.6, 0.4, 1.0), (0.1, 0.2, 0.2, 0.1), 0.5)


@pytest.mark.parametrize("view", ["View_001", "View_005"])
def test_pixel_rays_pass_through_the_world_points_that_project_to_the_pixels(view):
    calibration = load_calibration(f"{PETS}/{view}.xml")
    world_mm = np.array([[-5000.0, -3000.0, 0.0], [-8000.0, -6000.0, 0.0], [-5000.0, -3000.0, 1700.0]])
    centre_m, direction = pixel_rays(calibration, project_pinhole(calibration, world_mm))
    t_m = (world_mm[:, 2] / 1000 - centre_m[2]) / direction[:, 2]
    np.testing.assert_allclose(centre_m + t_m[:, None] * direction, world_mm / 1000, atol=1e-3)
    np.testing.assert_allclose(np.linalg.norm(direction, axis=-1), 1.0)
