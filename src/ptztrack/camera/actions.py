"""The discrete PTZ action set and the mechanics that limit each step (paper section 4.3)."""

from dataclasses import dataclass
from functools import cached_property

import numpy as np


@dataclass(frozen=True)
class ActionGrid:
    """A grid of pan x tilt x zoom values.

    An action is a flat index into the grid, ordered pan-major then tilt then
    zoom (``np.ravel_multi_index`` over ``shape``).

    Attributes
    ----------
    pan_deg, tilt_deg, zoom : 1-D increasing arrays of the values of each axis.
    max_steps : (3,) how many grid steps each of pan, tilt and zoom may move
        in one time step (the paper: 2, 2, 1).
    """

    pan_deg: np.ndarray
    tilt_deg: np.ndarray
    zoom: np.ndarray
    max_steps: tuple[int, int, int] = (2, 2, 1)

    @property
    def shape(self) -> tuple[int, int, int]:
        return (len(self.pan_deg), len(self.tilt_deg), len(self.zoom))

    @property
    def size(self) -> int:
        return int(np.prod(self.shape))

    @cached_property
    def axis_indices(self) -> np.ndarray:
        """(L, 3) grid indices (pan, tilt, zoom) of every action."""
        return np.stack(np.unravel_index(np.arange(self.size), self.shape), axis=-1)

    @cached_property
    def poses(self) -> np.ndarray:
        """(L, 3) poses (pan_deg, tilt_deg, zoom) of every action."""
        i = self.axis_indices
        return np.stack([self.pan_deg[i[:, 0]], self.tilt_deg[i[:, 1]], self.zoom[i[:, 2]]], axis=-1)

    def index(self, pan_index, tilt_index, zoom_index) -> np.ndarray:
        """Flat action index of grid indices (broadcasts)."""
        return np.ravel_multi_index((pan_index, tilt_index, zoom_index), self.shape)

    def reachable_mask(self, current) -> np.ndarray:
        """Which actions are reachable in one step from action(s) ``current``.

        current : int or (B,) flat indices. Returns (L,) or (B, L) bool.
        """
        here = self.axis_indices[np.asarray(current)]
        step = np.abs(self.axis_indices - here[..., None, :])
        return np.all(step <= np.asarray(self.max_steps), axis=-1)

    def reachable(self, current: int) -> np.ndarray:
        """Flat indices of the actions reachable in one step from ``current``."""
        return np.flatnonzero(self.reachable_mask(current))

    def nearest(self, pose) -> int:
        """The flat index of the grid action nearest to ``pose`` (3,), axis by axis."""
        indices = [int(np.argmin(np.abs(values - value))) for values, value in zip(self.axes, pose, strict=True)]
        return int(self.index(*indices))

    @property
    def axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return self.pan_deg, self.tilt_deg, self.zoom

    def step_towards(self, current: int, target: int) -> int:
        """The reachable action closest (in grid steps) to ``target``."""
        here = self.axis_indices[current]
        goal = self.axis_indices[target]
        step = np.clip(goal - here, -np.asarray(self.max_steps), self.max_steps)
        return int(self.index(*(here + step)))
