"""A synthetic room seen by fixed calibrated cameras: the LPOM paper's lab, rendered.

The paper's experiments (section 5) ran in "a lab of about 5 x 6 metres with
four cameras mounted in the four corners", 1024 x 768 px at 15 Hz, with one
and with three people. Here the people walk as in :mod:`ptztrack.scene.synthetic`
and are drawn by the shared renderer (:mod:`ptztrack.scene.render`: textured
cone models over a textured floor, textured walls and a plain ceiling). The
cameras (mounting not given by the paper) hang 2.8 m high, 0.1 m inside each
corner, aimed at the room's centre 0.9 m above the floor, with a 1024 x 768
image and a 500 px focal length (91 deg horizontal field of view) and no lens
distortion. Each frame gets sensor noise.
"""

from dataclasses import dataclass

import numpy as np

from ptztrack.geometry.calibration import PinholeCalibration, aimed_pinhole
from ptztrack.scene.parameters import CrowdParameters
from ptztrack.scene.render import SceneRenderer, Stage
from ptztrack.scene.synthetic import walk_people
from ptztrack.types import GroundTruth


@dataclass(frozen=True)
class RoomLayout:
    """The room and its cameras.

    size_m : (x, y) extent of the floor, the origin at one corner; wall_height_m : up to the ceiling.
    camera_height_m, camera_inset_m : where the cameras hang in the corners; aim_height_m : they look
    at the room's centre at this height. image_size_px : (width, height); focal_px : in pixels.
    """

    size_m: tuple[float, float] = (5.0, 6.0)
    wall_height_m: float = 3.0
    camera_height_m: float = 2.8
    camera_inset_m: float = 0.1
    aim_height_m: float = 0.9
    image_size_px: tuple[int, int] = (1024, 768)
    focal_px: float = 500.0
    frame_rate_hz: float = 15.0


def room_cameras(layout: RoomLayout) -> list[PinholeCalibration]:
    """The four corner cameras, counter-clockwise from the origin's corner."""
    (width_m, depth_m), inset = layout.size_m, layout.camera_inset_m
    corners = [(inset, inset), (width_m - inset, inset), (width_m - inset, depth_m - inset), (inset, depth_m - inset)]
    target = (width_m / 2, depth_m / 2, layout.aim_height_m)
    return [
        aimed_pinhole((x, y, layout.camera_height_m), target, layout.focal_px, layout.image_size_px) for x, y in corners
    ]


def room_stage(layout: RoomLayout) -> Stage:
    """The room as a stage: its floor, four walls up to the ceiling (plain grey), 0.5 m floor tiles."""
    return Stage(bounds_m=((0.0, 0.0), layout.size_m), height_m=layout.wall_height_m)


class RoomRenderer(SceneRenderer):
    """The frames of the room's four cameras: ``image(view, frame)`` (height, width, 3) uint8 BGR.

    layout : the room; truth : the people (positions, heights, widths); seed : fixes the textures,
    outfits and sensor noise (:class:`~ptztrack.scene.render.SceneRenderer`).
    """

    def __init__(self, layout: RoomLayout, truth: GroundTruth, seed: int):
        self.layout = layout
        cameras = room_cameras(layout)
        super().__init__(cameras, [layout.image_size_px] * len(cameras), room_stage(layout), truth, seed)


def room_truth(layout: RoomLayout, people: int, frames: int, seed: int) -> GroundTruth:
    """People walking in the room for ``frames`` frames: 0.5-1.2 m/s (indoor walking), 1.6-1.9 m tall,
    0.5 m wide, present throughout."""
    crowd = CrowdParameters(
        count=people,
        paired_fraction=0.0,
        pair_spacing_m=0.0,
        speed_m_s=(0.5, 1.2),
        height_m=(1.6, 1.9),
        width_m=0.5,
        turn_rate_sigma_deg_s=40.0,
        enter_leave=False,
        stay_s=(1.0, 1.0),
    )
    return walk_people(crowd, layout.size_m, frames, layout.frame_rate_hz, np.random.default_rng(seed))
