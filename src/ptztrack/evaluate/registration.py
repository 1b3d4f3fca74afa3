"""How well live PTZ views are registered (scale-invariant tracking paper): the errors of each view.

The truth is the view's real pose (pan, tilt, zoom) and focal length, and,
for live views as a real camera takes them (:mod:`ptztrack.camera.live_view`),
its lens: a ground point appears in the view where the real camera puts it.
The errors: the focal length in %, and on the ground (m), over a grid of
points of the walkable area that the view sees (median over the points),
how far the view's pixels of those points land from them when mapped back

* through the registered pose in the tracker's pinhole model (``ground_err``,
  what a tracker gets);
* through the true pose in the same model (``oracle_ground_err``: the
  lens's departures from the model alone);
* through the registered pose with the registered roll and distortion
  (``lens_ground_err``: what the registration knows of the view).
"""

import time
from collections.abc import Callable

import numpy as np

from ptztrack.camera.live_view import render_view, view_lens
from ptztrack.camera.parameters import LiveViewParameters
from ptztrack.camera.virtual import VirtualPTZ
from ptztrack.geometry.lens import Lens, pixel_directions, project_directions
from ptztrack.geometry.ptz import PTZCamera, apply_homography, image_to_ground, inside_image
from ptztrack.geometry.registration import ReferenceIndex, register
from ptztrack.scene.pets import RecordedVideo

# The ground errors of a view, and whether each needs the view registered.
GROUND_ERRORS = {"ground_err_m": True, "oracle_ground_err_m": False, "lens_ground_err_m": True}


def ground_of_pixels(camera: PTZCamera, pose, lens: Lens, pixels) -> np.ndarray:
    """Ground points (N, 2) m seen at pixels (N, 2) of the view at ``pose`` through ``lens``."""
    directions = pixel_directions(camera, pose, lens, pixels)
    return camera.centre_m[:2] - camera.centre_m[2] * directions[:, :2] / directions[:, 2:]


def registration_errors(
    virtual: VirtualPTZ,
    index: ReferenceIndex,
    video: RecordedVideo,
    poses,
    frames,
    ground_points_m,
    live: LiveViewParameters | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> list[dict]:
    """Register the live views of ``virtual`` at ``poses`` (V, 3) of the video's ``frames`` (V,)
    (ascending, so that the video is read forwards once), as ``live`` takes them (None: exact
    pinhole views); ground errors over ``ground_points_m`` (P, 2).

    One row per view: ``pose`` (pan_deg, tilt_deg, zoom), ``frame``, ``registered`` (bool),
    ``focal_err_pct``, the ground errors of ``GROUND_ERRORS`` in m (None when not registered, except
    the oracle's, and all of them when the view sees none of the walkable area), ``roll_err_deg``
    (registered roll minus the true one; None when not registered), ``seconds`` (of registration).
    """
    camera, views = virtual.camera, len(poses)
    ground_points_m = np.asarray(ground_points_m, dtype=float)
    directions = np.c_[ground_points_m, np.zeros(len(ground_points_m))] - camera.centre_m
    rows = []
    for number, (pose, frame) in enumerate(zip(poses, frames, strict=True), start=1):
        image = render_view(virtual, video.frame(int(frame)), pose, live)
        start = time.perf_counter()
        result = register(camera, index, image)
        seconds = time.perf_counter() - start
        lens = Lens() if live is None else view_lens(live, virtual, pose)
        pixels = project_directions(camera, pose, lens, directions)
        seen = inside_image(camera, pixels) & np.all(np.isfinite(pixels), axis=1)
        errors: dict[str, float | None] = dict.fromkeys(GROUND_ERRORS)
        if seen.any():
            mapped = {"oracle_ground_err_m": apply_homography(image_to_ground(camera, pose), pixels[seen])}
            if result is not None:
                mapped["ground_err_m"] = apply_homography(image_to_ground(camera, result.pose), pixels[seen])
                registered_lens = Lens(roll_deg=result.roll_deg, k1=result.k1)
                mapped["lens_ground_err_m"] = ground_of_pixels(camera, result.pose, registered_lens, pixels[seen])
            for key, estimated in mapped.items():
                errors[key] = float(np.median(np.linalg.norm(estimated - ground_points_m[seen], axis=1)))
        rows.append(
            {
                "pose": np.asarray(pose).tolist(),
                "frame": int(frame),
                "registered": result is not None,
                "focal_err_pct": None
                if result is None
                else 100.0 * abs(result.focal_px / (pose[2] * camera.f_min_px) - 1.0),
                **errors,
                "roll_err_deg": None if result is None else result.roll_deg - lens.roll_deg,
                "seconds": seconds,
            }
        )
        if progress is not None:
            progress(number, views)
    return rows
