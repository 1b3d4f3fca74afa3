"""How well live PTZ views are registered (scale-invariant tracking paper): errors per view, and their summary.

The errors are those of the registered pose against the true one: the focal
length in %, and on the ground (m) the median over a grid of points of the
walkable area that the view sees.
"""

import time
from collections.abc import Callable, Sequence

import numpy as np

from ptztrack.camera.virtual import VirtualPTZ
from ptztrack.geometry.ptz import apply_homography, ground_to_image, image_to_ground, inside_image
from ptztrack.geometry.registration import ReferenceIndex, register
from ptztrack.scene.pets import RecordedVideo


def registration_errors(
    virtual: VirtualPTZ,
    index: ReferenceIndex,
    video: RecordedVideo,
    poses,
    frames,
    ground_points_m,
    progress: Callable[[int, int], None] | None = None,
) -> list[dict]:
    """Register the live views of ``virtual`` at ``poses`` (V, 3) of the video's ``frames`` (V,)
    (ascending, so that the video is read forwards once); ground errors over ``ground_points_m`` (P, 2).

    One row per view: ``pose`` (pan_deg, tilt_deg, zoom), ``frame``, ``registered`` (bool),
    ``focal_err_pct`` and ``ground_err_m`` (None when not registered, and the ground error also when
    the view sees none of the walkable area), ``seconds`` (of registration).
    """
    camera, views = virtual.camera, len(poses)
    rows = []
    for number, (pose, frame) in enumerate(zip(poses, frames, strict=True), start=1):
        image = virtual.render(video.frame(int(frame)), pose)
        start = time.perf_counter()
        result = register(camera, index, image)
        seconds = time.perf_counter() - start
        focal_err_pct = ground_err_m = None
        if result is not None:
            focal_err_pct = 100.0 * abs(result.focal_px / (pose[2] * camera.f_min_px) - 1.0)
            pixels = apply_homography(ground_to_image(camera, pose), ground_points_m)
            seen = inside_image(camera, pixels) & np.all(np.isfinite(pixels), axis=1)
            if seen.any():
                estimated = apply_homography(image_to_ground(camera, result.pose), pixels[seen])
                ground_err_m = float(np.median(np.linalg.norm(estimated - ground_points_m[seen], axis=1)))
        rows.append(
            {
                "pose": pose.tolist(),
                "frame": int(frame),
                "registered": result is not None,
                "focal_err_pct": focal_err_pct,
                "ground_err_m": ground_err_m,
                "seconds": seconds,
            }
        )
        if progress is not None:
            progress(number, views)
    return rows


def summarise_registration(rows: Sequence[dict]) -> dict:
    """Medians and 90th percentiles of the errors over the views.

    A view that was not registered counts as an error larger than any, so it raises the percentiles
    rather than vanishing from them; percentiles are order statistics (no interpolation with such
    views), None when they fall on such a view. A registered view that sees none of the walkable
    area has no ground error and is left out of the ground error's statistics only.
    """
    registered = np.array([row["registered"] for row in rows])
    focal = np.array([row["focal_err_pct"] if row["registered"] else np.inf for row in rows], dtype=float)
    ground = np.array([row["ground_err_m"] if row["registered"] else np.inf for row in rows], dtype=float)
    ground = ground[~np.isnan(ground)]

    def percentile(values, q):
        value = float(np.percentile(values, q, method="inverted_cdf")) if len(values) else np.inf
        return value if np.isfinite(value) else None

    return {
        "views": len(rows),
        "registered": int(registered.sum()),
        "focal_err_median_pct": percentile(focal, 50),
        "focal_err_p90_pct": percentile(focal, 90),
        "ground_err_median_m": percentile(ground, 50),
        "ground_err_p90_m": percentile(ground, 90),
        "register_ms_median": float(1e3 * np.median([row["seconds"] for row in rows])),
    }
