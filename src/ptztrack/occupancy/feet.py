"""A candidate person's position from the feet of the boxes that the views' detectors drew near it.

An occupancy map's candidate lies at a cell, and where the views' calibrations disagree on where a
person stands, the cell that best explains every view's mask lies between them. A view whose
detector drew a box around the person also says where the feet are: the box's bottom centre,
back-projected to the ground (:func:`~ptztrack.occupancy.clustering.feet_on_ground`). Taking each
view's feet nearest to the candidate, within a gate, as a measurement of the position with an
isotropic Gaussian error of the view's own variance ``s_c^2`` per axis, the position's maximum
likelihood and its covariance are the inverse-variance weighted mean::

    x = sum_c f_c / s_c^2 / sum_c 1 / s_c^2,        P = I / sum_c 1 / s_c^2,

over the views ``c`` with feet within the gate (:func:`localized_by_feet`); a candidate without any
keeps its cell's position. Each view's variance is fitted on annotated frames: the mean squared
distance from each annotated person to the view's nearest feet within the gate, halved
(:func:`fitted_feet_variances`).
"""

from collections.abc import Sequence

import numpy as np

from ptztrack.occupancy.clustering import view_feet_on_ground
from ptztrack.occupancy.lpom import Modes
from ptztrack.occupancy.multiview import MultiViewRecording

# A view's variance needs more matches than one person's few frames give.
MIN_FEET_MATCHES = 20


def recording_feet_m(recording: MultiViewRecording, frame: int, min_box_score: float) -> list[np.ndarray]:
    """Per view, its boxes' feet (K_c, 2) m on the ground at ``frame`` (boxes of at least
    ``min_box_score``; none for a view without a detector's boxes)."""
    return [
        np.zeros((0, 2)) if view.boxes is None else view_feet_on_ground(view, frame, min_box_score)
        for view in recording.views
    ]


def nearest_feet_m(points_m, feet_m: Sequence[np.ndarray], gate_m: float) -> np.ndarray:
    """Per point (P, 2) m and view, the view's feet (``feet_m[c]``: (K_c, 2) m) nearest to it when
    closer than ``gate_m``: (P, views, 2) m, NaN where the view has none that close."""
    points_m = np.asarray(points_m, dtype=float).reshape(-1, 2)
    nearest = np.full((len(points_m), len(feet_m), 2), np.nan)
    for view, feet in enumerate(feet_m):
        if len(feet) == 0 or len(points_m) == 0:
            continue
        distance_m = np.linalg.norm(points_m[:, None, :] - feet[None, :, :], axis=-1)
        closest = distance_m.argmin(axis=1)
        near = distance_m[np.arange(len(points_m)), closest] < gate_m
        nearest[near, view] = feet[closest[near]]
    return nearest


def fitted_feet_variances(
    recording: MultiViewRecording, truth_m, frames, gate_m: float, min_box_score: float
) -> np.ndarray:
    """Each view's feet variance per axis (views,) m^2 from annotated ``frames`` (truth_m (T, N, 2) m,
    NaN where absent): half the mean squared distance from each annotated person to the view's nearest
    feet within ``gate_m``; infinite (the view is not used) for a view with fewer than
    ``MIN_FEET_MATCHES`` such people."""
    truth_m = np.asarray(truth_m, dtype=float)
    squared_m2: list[list[np.ndarray]] = [[] for _ in recording.views]
    for frame in frames:
        people_m = truth_m[frame][~np.isnan(truth_m[frame][:, 0])]
        nearest = nearest_feet_m(people_m, recording_feet_m(recording, frame, min_box_score), gate_m)
        for view in range(len(recording.views)):
            offset_m = nearest[:, view] - people_m
            squared_m2[view].append(np.sum(offset_m[~np.isnan(offset_m[:, 0])] ** 2, axis=-1))
    variances = np.full(len(recording.views), np.inf)
    for view, squares in enumerate(squared_m2):
        matched = np.concatenate(squares) if squares else np.zeros(0)
        if len(matched) >= MIN_FEET_MATCHES:
            variances[view] = 0.5 * float(np.mean(matched))
    return variances


def localized_by_feet(modes: Modes, feet_m: Sequence[np.ndarray], variances_m2, gate_m: float) -> Modes:
    """The modes with each position and covariance replaced by the inverse-variance weighted mean of
    the views' feet nearest to it within ``gate_m`` (module docstring); per view ``feet_m`` (K_c, 2) m
    and ``variances_m2`` (views,) m^2 per axis (infinite: not used). A mode without any keeps its own."""
    nearest = nearest_feet_m(modes.position_m, feet_m, gate_m)
    weight = np.where(np.isnan(nearest[..., 0]), 0.0, 1.0 / np.asarray(variances_m2, dtype=float)[None, :])
    total = weight.sum(axis=1)
    measured = total > 0
    if not np.any(measured):
        return modes
    position_m, covariance_m2 = modes.position_m.copy(), modes.covariance_m2.copy()
    weighted = np.sum(np.nan_to_num(nearest) * weight[..., None], axis=1)
    position_m[measured] = weighted[measured] / total[measured, None]
    covariance_m2[measured] = np.eye(2) / total[measured, None, None]
    return Modes(position_m, covariance_m2, modes.strength, modes.views, modes.variant)
