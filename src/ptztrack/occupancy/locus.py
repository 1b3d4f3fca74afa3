"""The locus of a pixel: where on the ground a person model would touch the pixel's ray (the LPOM paper).

Hu, Mutlu and Lanz, "Locus-based probabilistic occupancy map", ICIAP 2013,
section 4. A person is a vertically symmetric solid standing at ``(x0, y0)``
on the ground plane z = 0 (equation 4): at height ``z`` its horizontal
section is a circle of radius ``rho(z)`` around the vertical axis through
``(x0, y0)``. A ray ``R(t) = P + t V`` touches the solid at height ``z`` when
the point of the ray at that height lies on the surface and the surface
normal there is orthogonal to ``V`` (the touch constraints, equation 5).
With ``(x, y)`` the horizontal offset of the ray's point from the axis this
is the linear-quadratic system of equation 6::

    <[Vx, Vy], [x, y]> = rho rho' Vz        (normal orthogonal to the ray)
    <[x, y], [x, y]>   = rho^2              (point on the surface)

Writing ``a = [Vx, Vy] / n`` with ``n = |[Vx, Vy]|`` and ``a_perp`` the
horizontal unit vector orthogonal to it, the solutions are::

    [x, y] = rho (c a +- sqrt(1 - c^2) a_perp),    c = rho' Vz / n

and the model's ground position is ``[x0, y0] = [Px + t Vx, Py + t Vy] - [x, y]``
(equation 7), a point for each sign wherever ``|c| <= 1``. The paper writes
the same solution after rescaling ``V`` so that ``n = rho`` ("this can be
imposed through proper rescaling of V"), which makes its ``phi(t) = rho' Vz / rho``
our ``c``; since ``rho`` changes with ``t`` that rescaling is a different one
at every point of the ray, so we keep ``V`` as it is and divide by ``n``
explicitly (the locus, a set of ground points, is the same). We sample the
locus at heights ``z`` of the tangent point, ``t = (z - Pz) / Vz``, and
weight each sample by ``dt`` with ``|V| = 1`` (``t`` in metres along the
ray): equation 8's ``loc(x | m) = integral K(x - x0(t)) dt``. The creases of
a piecewise-linear profile (where two cones meet) touch a ray only at single
values of ``t``, so they carry no weight in that integral and are left out.
"""

from dataclasses import dataclass

import numpy as np

from ptztrack.occupancy.parameters import ConeShapeParameters, OccupancyParameters


@dataclass(frozen=True)
class ConeModel:
    """A person as connected truncated cones: a piecewise-linear profile ``rho(z)`` (equation 4).

    height_fraction : (K,) the knots' heights as fractions of the person's height, increasing from 0 to 1.
    radius_fraction : (K,) the radius at each knot as a fraction of ``width_m`` (the model's widest
        diameter is ``2 max(radius_fraction) width_m``).
    width_m : the width that scales the radii.
    """

    height_fraction: tuple[float, ...]
    radius_fraction: tuple[float, ...]
    width_m: float

    def __post_init__(self):
        fractions = np.asarray(self.height_fraction)
        if len(fractions) < 2 or len(fractions) != len(self.radius_fraction):
            raise ValueError("a cone model needs at least two knots, a radius for each")
        if fractions[0] != 0 or fractions[-1] != 1 or np.any(np.diff(fractions) <= 0):
            raise ValueError(f"height_fraction must increase from 0 to 1 (got {list(self.height_fraction)})")
        if np.any(np.asarray(self.radius_fraction) < 0):
            raise ValueError("radius_fraction must be non-negative")


# The default person (:class:`~ptztrack.occupancy.parameters.ConeShapeParameters`).
PERSON = ConeModel(
    height_fraction=ConeShapeParameters.height_fraction,
    radius_fraction=ConeShapeParameters.radius_fraction,
    width_m=OccupancyParameters.width_m,
)


def profile(model: ConeModel, z_m, height_m) -> tuple[np.ndarray, np.ndarray]:
    """``rho(z)`` in metres and its slope ``rho'(z) = d rho / d z`` of a person ``height_m`` tall.

    z_m, height_m : broadcastable arrays, 0 <= z <= height. At a knot the slope is the one of the
    cone above it (the knots carry no weight in the locus integral).
    """
    z_m, height_m = np.broadcast_arrays(np.asarray(z_m, dtype=float), np.asarray(height_m, dtype=float))
    fraction = z_m / height_m
    knots = np.asarray(model.height_fraction)
    radii = np.asarray(model.radius_fraction) * model.width_m
    segment = np.clip(np.searchsorted(knots, fraction, side="right") - 1, 0, len(knots) - 2)
    slope_per_fraction = (radii[segment + 1] - radii[segment]) / (knots[segment + 1] - knots[segment])
    radius_m = radii[segment] + slope_per_fraction * (fraction - knots[segment])
    return radius_m, slope_per_fraction / height_m


@dataclass(frozen=True)
class Locus:
    """Ground positions of a model that touches rays, sampled at the heights of the tangent point.

    position_m : (..., 2, 2) the model's ground position (x0, y0) for each sign of equation 7
        (second-to-last axis), NaN where there is none.
    weight_m : (..., 2) ``dt``: the length of ray each sample stands for (0 where there is no solution).
    """

    position_m: np.ndarray
    weight_m: np.ndarray


def touching_positions(centre_m, direction, z_m, radius_m, slope, dz_m) -> Locus:
    """Equation 7: where a vertically symmetric model stands when it touches each ray at height ``z``.

    centre_m : (..., 3) a point of each ray (the camera centre), metres; direction : (..., 3) the
    ray's direction (any length; rays go forwards, t > 0). z_m, radius_m, slope : heights of the
    tangent point, ``rho(z)`` and ``rho'(z)`` there, broadcastable against the rays' leading axes
    (e.g. rays (R, 1, 1, 3) against heights (H, Z)). dz_m : the spacing of the ``z`` samples, so that
    each sample's weight is ``dt = dz / |Vz|`` with ``|V| = 1``.

    Returns a :class:`Locus` over the broadcast shape of the rays and the samples.
    """
    direction = np.asarray(direction, dtype=float)
    direction = direction / np.linalg.norm(direction, axis=-1, keepdims=True)
    centre_m = np.asarray(centre_m, dtype=float)
    vx, vy, vz = direction[..., 0], direction[..., 1], direction[..., 2]
    horizontal = np.hypot(vx, vy)
    with np.errstate(divide="ignore", invalid="ignore"):
        t_m = (z_m - centre_m[..., 2]) / vz
        cosine = slope * vz / horizontal
        along = np.stack([vx / horizontal, vy / horizontal], axis=-1)
    across = np.stack([-along[..., 1], along[..., 0]], axis=-1)
    valid = (t_m > 0) & (np.abs(cosine) <= 1) & (horizontal > 0) & (radius_m >= 0)
    sine = np.sqrt(np.clip(1 - cosine**2, 0.0, None))
    on_ray = centre_m[..., :2] + t_m[..., None] * direction[..., :2]
    signs = np.array([1.0, -1.0])
    offset = radius_m[..., None, None] * (
        cosine[..., None, None] * along[..., None, :] + signs[:, None] * sine[..., None, None] * across[..., None, :]
    )
    position_m = np.where(valid[..., None, None], on_ray[..., None, :] - offset, np.nan)
    with np.errstate(divide="ignore"):
        weight_m = np.where(valid, dz_m / np.abs(vz), 0.0)
    return Locus(position_m, np.repeat(weight_m[..., None], 2, axis=-1))


def person_locus(
    model: ConeModel, centre_m, direction, heights_m, samples_per_height: int
) -> tuple[np.ndarray, np.ndarray]:
    """The loci of rays for a person of each height (Algorithm 1's inner loops), flattened per ray.

    centre_m : (R, 3) or (3,); direction : (R, 3) in metres. heights_m : (H,). The tangent point's
    height is sampled at the midpoints of ``samples_per_height`` equal slices of [0, h].
    Returns positions (R, H * samples_per_height * 2, 2) metres (NaN where none) and their weights
    ``dt`` (R, H * samples_per_height * 2) metres.
    """
    heights_m = np.asarray(heights_m, dtype=float)
    fractions = (np.arange(samples_per_height) + 0.5) / samples_per_height
    z_m = heights_m[:, None] * fractions[None, :]
    radius_m, slope = profile(model, z_m, heights_m[:, None])
    dz_m = np.broadcast_to(heights_m[:, None] / samples_per_height, z_m.shape)
    direction = np.asarray(direction, dtype=float)
    centre_m = np.broadcast_to(np.asarray(centre_m, dtype=float), direction.shape)
    locus = touching_positions(centre_m[:, None, None, :], direction[:, None, None, :], z_m, radius_m, slope, dz_m)
    rays = len(direction)
    return locus.position_m.reshape(rays, -1, 2), locus.weight_m.reshape(rays, -1)
