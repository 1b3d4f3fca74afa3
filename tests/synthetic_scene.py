"""The default synthetic scene's camera, action grid and area, built from the maths' own types (the
scenario's defaults as these tests' inputs): tests of the camera and control layers use them without
the configuration or the builders."""

import numpy as np

from ptztrack.camera.actions import ActionGrid
from ptztrack.geometry.area import rectangle_m
from ptztrack.geometry.ptz import PTZCamera

CAMERA = PTZCamera((7.5, -6.0, 2.5), 640, 480, 325.0)
GRID = ActionGrid(np.linspace(-45.0, 45.0, 7), np.linspace(0.0, 24.0, 10), np.array([1.0, 2.0, 3.0, 4.0]), (2, 2, 1))
AREA_M = rectangle_m(15.0, 15.0)
