"""A step of a run as plain JSON-able data: what the live web view draws.

:class:`ViewState` turns what :func:`ptztrack.loop.run_loop` hands its
observer (the step, the decision's context, the step's record) into a dict
of lists and numbers: the camera's image (JPEG, base64; the backend's, or
where it renders none the camera model's picture of the true people), the
detections' feet, the reported tracks with their 2-sigma ellipses on the
ground and in the image, the truth, the field of view on the ground, the
walkable area, the action grid and the reward of every action where the
policy exposes it (``last_reward_nats``), and running figures.
"""

import base64
import time
from collections import deque

import cv2
import numpy as np

from ptztrack.evaluate.video import SIGMAS, ellipse_axes, image_ellipses, view_renderer
from ptztrack.geometry.ptz import ground_footprint
from ptztrack.loop import World
from ptztrack.types import DecisionContext

JPEG_QUALITY = 80  # enough to see people; a 640 x 480 view is then some 30 kB
FOOTPRINT_RANGE_M = 60.0  # a view of the horizon ends here on the map
RATE_WINDOW_STEPS = 20  # the step rate over the last steps: a pause leaves it soon


class ViewState:
    """Builds each step's state for one run in ``world``; ``policy`` may expose ``last_reward_nats`` (L,)."""

    def __init__(self, world: World, policy: object, steps: int, label: str = ""):
        self.world, self.policy, self.steps, self.label = world, policy, steps, label
        self.render = view_renderer(world)
        self.step_times_s: deque[float] = deque(maxlen=RATE_WINDOW_STEPS)
        self.detections = 0
        self.zoom_sum = 0.0
        grid = world.grid
        # The same every step: sent each time all the same, so a page that opens late needs nothing else.
        self.scene = {
            "area_m": _rounded(world.area_polygon_m, 3),
            "camera_m": _rounded(world.camera.centre_m[:2], 3),
            "image_size_px": [world.camera.image_width_px, world.camera.image_height_px],
            "grid": {"pan_deg": _rounded(grid.pan_deg, 2), "tilt_deg": _rounded(grid.tilt_deg, 2),
                     "zoom": _rounded(grid.zoom, 2)},
            "sigmas": SIGMAS,
            "label": label,
        }  # fmt: skip

    def count(self, record: dict) -> None:
        """Running figures over every step, drawn or not (cheap: called at every step)."""
        self.step_times_s.append(time.perf_counter())
        self.detections += len(record["detections"])
        self.zoom_sum += float(record["poses"][2])

    def state(self, step: int, context: DecisionContext, record: dict) -> dict:
        """The state after ``step`` (call :meth:`count` with the step's record first)."""
        camera, pose, tracks = self.world.camera, record["poses"], record["tracks"]
        truth = self.world.truth
        image = self.render(step, pose)
        ok, jpeg = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY])
        if not ok:
            raise RuntimeError("OpenCV could not encode the camera's view as JPEG")
        position_m, covariance_m2 = tracks.mean[:, :2], tracks.covariance[:, :2, :2]
        ground_axes_m, ground_angle_deg = ellipse_axes(covariance_m2)
        centre_px, in_front, axes_px, angle_px_deg = image_ellipses(camera, pose, position_m, covariance_m2)
        image_size_px = np.array([camera.image_width_px, camera.image_height_px])
        # In the image only tracks near it: towards the horizon the linearised ellipse grows without bound.
        near = in_front & np.all(np.abs(centre_px - image_size_px / 2) <= image_size_px, axis=1)
        track_rows = [
            {
                "id": int(tracks.ids[k]),
                "mean_m": _rounded(position_m[k], 3),
                "covariance_m2": _rounded(covariance_m2[k], 4),
                "ellipse_m": _ellipse(ground_axes_m[k], ground_angle_deg[k], "half_axes_m", 3),
                "image": _ellipse(axes_px[k], angle_px_deg[k], "half_axes_px", 1, centre_px[k]) if near[k] else None,
            }
            for k in range(len(tracks))
        ]
        rewards = getattr(self.policy, "last_reward_nats", None)
        times_s = self.step_times_s
        elapsed_s = times_s[-1] - times_s[0] if len(times_s) > 1 else 0.0
        return {
            "step": step,
            "steps": self.steps,
            "pose": _rounded(pose, 2),
            "image_jpeg": base64.b64encode(jpeg.tobytes()).decode("ascii"),
            "detections_px": _rounded(record["detections"].feet_px, 1),
            "tracks": track_rows,
            "truth_m": _rounded(truth.positions_m[step, truth.present[step]], 3),
            "footprint_m": _rounded(ground_footprint(camera, pose, max_range_m=FOOTPRINT_RANGE_M), 2),
            "decision": {
                "action": int(record["actions"]),
                "reachable": context.reachable.tolist(),
                "reward_nats": None
                if rewards is None
                else [None if np.isnan(r) else round(r, 4) for r in rewards.tolist()],
                "decision_ms": round(1e3 * float(record["decision_s"]), 2),
            },
            "metrics": {
                "steps_per_s": round((len(times_s) - 1) / elapsed_s, 2) if elapsed_s > 0 else None,
                "detections": self.detections,
                "tracks": len(tracks),
                "mean_zoom": round(self.zoom_sum / (step + 1), 2),
            },
            "scene": self.scene,
        }


def _ellipse(half_axes, angle_deg: float, unit: str, decimals: int, centre_px=None) -> dict:
    """A 2-sigma ellipse: half axes (major, minor), the major's angle from the first axis towards the
    second (clockwise in an image), and in the image its centre."""
    ellipse = {unit: _rounded(half_axes, decimals), "angle_deg": round(float(angle_deg), 1)}
    if centre_px is not None:
        ellipse["centre_px"] = _rounded(centre_px, 1)
    return ellipse


def _rounded(values, decimals: int) -> list:
    """Nested lists of floats rounded to ``decimals``: a JSON message a few times smaller."""
    return np.round(np.asarray(values, dtype=float), decimals).tolist()
