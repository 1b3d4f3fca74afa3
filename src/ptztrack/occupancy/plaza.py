"""A synthetic plaza seen by far, shallow calibrated cameras: a recorded dataset's geometry with exact truth.

The synthetic room (:mod:`ptztrack.occupancy.room`) has four near, steep cameras. PETS 2009 S2.L1's
are far and shallow: three stand 8-70 m outside the area people walk in, 6-7 m high, four at its
edge about 2 m high, all looking down at 3-21 degrees. The plaza renders any calibrated cameras
(the builders pass S2.L1's seven, with its ground area and frame rate:
:func:`ptztrack.builders.occupancy_synthetic.plaza_recording`) with the shared renderer
(:mod:`ptztrack.scene.render`): paving of 1 m slabs over the whole ground, facades 15 m high
standing 5 m beyond the area and every camera, a plain sky above. People walk over the area as in
:mod:`ptztrack.scene.synthetic`, most of them in pairs side by side 0.6 m apart, as S2.L1's groups
walk 0.5-0.7 m apart.
"""

from dataclasses import dataclass, replace

import numpy as np

from ptztrack.geometry.calibration import PinholeCalibration
from ptztrack.scene.parameters import CrowdParameters
from ptztrack.scene.render import Stage, stage_around
from ptztrack.scene.synthetic import walk_people
from ptztrack.types import GroundTruth


@dataclass(frozen=True)
class PlazaLayout:
    """The plaza and who walks in it.

    area_m : ((x0, y0), (x1, y1)) the ground people walk on, m; frame_rate_hz : frames per second.
    margin_m : how far beyond the area and every camera the facades stand; facade_height_m : their
    height (at least margin_m above the highest camera); tile_m : the paving slabs' side.
    speed_m_s, height_m : [low, high] of each walker's uniform draws; width_m : everybody's width;
    paired_fraction : the share of walkers in pairs, the second pair_spacing_m to the left of the first.
    """

    area_m: tuple[tuple[float, float], tuple[float, float]]
    frame_rate_hz: float
    margin_m: float = 5.0
    facade_height_m: float = 15.0
    tile_m: float = 1.0
    speed_m_s: tuple[float, float] = (1.0, 1.5)
    height_m: tuple[float, float] = (1.6, 1.9)
    width_m: float = 0.5
    paired_fraction: float = 0.8
    pair_spacing_m: float = 0.6


def plaza_stage(layout: PlazaLayout, cameras: list[PinholeCalibration]) -> Stage:
    """The stage around the area and the cameras (:func:`~ptztrack.scene.render.stage_around`): facades
    margin_m beyond both, facade_height_m high (at least margin_m above the highest camera), paving of
    tile_m slabs, the sky above."""
    return stage_around(layout.area_m, cameras, layout.margin_m, layout.facade_height_m, layout.tile_m)


def plaza_crowd(layout: PlazaLayout, people: int) -> CrowdParameters:
    """The walkers of :func:`plaza_truth`: ``people`` of them, present throughout, turning as the
    synthetic scene's walkers do (:class:`~ptztrack.scene.parameters.CrowdParameters`'s defaults)."""
    return CrowdParameters(
        count=people,
        speed_m_s=layout.speed_m_s,
        height_m=layout.height_m,
        width_m=layout.width_m,
        enter_leave=False,
        paired_fraction=layout.paired_fraction,
        pair_spacing_m=layout.pair_spacing_m,
    )


def plaza_truth(layout: PlazaLayout, people: int, frames: int, seed: int) -> GroundTruth:
    """``people`` walking over the area for ``frames`` frames: positions (frames, people, 2) m in the
    area's coordinates (:func:`~ptztrack.scene.synthetic.walk_people` walks in [0, x1 - x0] x
    [0, y1 - y0]; the area's corner (x0, y0) is added)."""
    (x0, y0), (x1, y1) = layout.area_m
    rng = np.random.default_rng(seed)
    truth = walk_people(plaza_crowd(layout, people), (x1 - x0, y1 - y0), frames, layout.frame_rate_hz, rng)
    return replace(truth, positions_m=truth.positions_m + np.array([x0, y0]))
