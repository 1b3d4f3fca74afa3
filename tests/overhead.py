"""The scene of the tests computed by hand for a camera high above the area.

The default synthetic scene's camera is 2.5 m up (chosen for the paper's
scene statistics); these tests' hand-worked cases, poses and thresholds were
set for a camera 7 m up, 4 m behind the middle of one edge of the 15 x 15 m
area, with f_min = 400 px, people walking alone, 0.5 m wide.
"""

from ptztrack.config import Scenario, scenario_from_dict
from ptztrack.geometry.ptz import PTZCamera

OVERHEAD = {
    "camera": {"position_m": [7.5, -4.0, 7.0], "f_min_px": 400.0},
    "actions": {"tilt_deg": {"start": 15.0, "stop": 60.0, "count": 10}},
    "people": {"width_m": 0.5, "paired_fraction": 0.0},
}
CAMERA = PTZCamera((7.5, -4.0, 7.0), 640, 480, 400.0)


def overhead_scenario(sections: dict | None = None) -> Scenario:
    """The overhead scene with ``sections`` ({section: {field: value}} or {field: value}) on top."""
    merged = {key: dict(value) if isinstance(value, dict) else value for key, value in OVERHEAD.items()}
    for key, value in (sections or {}).items():
        merged[key] = {**merged.get(key, {}), **value} if isinstance(value, dict) else value
    return scenario_from_dict(merged)
