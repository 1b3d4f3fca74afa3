"""Where people can be: the walkable area as a polygon on the ground, and points inside it."""

import numpy as np
from matplotlib.path import Path


def rectangle_m(width_m: float, depth_m: float) -> np.ndarray:
    """The polygon (4, 2) of the area [0, width] x [0, depth], corner at the origin, counter-clockwise."""
    return np.array([[0.0, 0.0], [width_m, 0.0], [width_m, depth_m], [0.0, depth_m]])


def bounds_m(polygon_m) -> np.ndarray:
    """[[x0, y0], [x1, y1]], the bounding box of a polygon (K, 2)."""
    polygon_m = np.asarray(polygon_m, dtype=float)
    return np.array([polygon_m.min(axis=0), polygon_m.max(axis=0)])


def inside(polygon_m, points_m) -> np.ndarray:
    """Which points (N, 2) lie inside the polygon (K, 2); (N,) bool."""
    return Path(np.asarray(polygon_m, dtype=float)).contains_points(np.asarray(points_m, dtype=float).reshape(-1, 2))


def grid_inside(polygon_m, xs, ys) -> np.ndarray:
    """The points of the grid ``xs`` x ``ys`` (row by row along x) inside the polygon; (M, 2)."""
    points = np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2)
    return points[inside(polygon_m, points)]
