"""Live views as a real PTZ camera takes them: rolled, off-centre, distorted, relit and JPEG-compressed.

The virtual camera (:mod:`ptztrack.camera.virtual`) renders exact pinhole
views. A real head's views depart from that model in ways a registration
must survive (the scale-invariant tracking paper registers such views):
each view is rolled about its optical axis, its principal point is off the
image centre, its lens distorts radially by an amount that changes with
zoom, the light and the exposure differ from those of the reference views,
and the camera compresses its images. :class:`LiveViewParameters` holds the
ranges; :func:`view_conditions` draws one view's values and
:func:`render_live` renders the view with them.

A view's values are a fixed pseudo-random function of its pose (and of the
model's seed, which stands for one camera unit): a camera that holds its
pose keeps them, as a real head's are repeatable at a pose, and every
landing at a new pose draws new ones. So the detector's image and the
registered image of a step, rendered at different sizes, agree.
"""

from dataclasses import dataclass

import cv2
import numpy as np

from ptztrack.camera.parameters import LiveViewParameters
from ptztrack.camera.virtual import VirtualPTZ, resample
from ptztrack.geometry.lens import Lens, pixel_directions, project_directions


@dataclass(frozen=True)
class ViewConditions:
    """One live view's values: its lens (offset in pixels of an image ``offset_image_width_px``
    wide), contrast ``gain`` and ``brightness`` offset (grey levels)."""

    lens: Lens
    gain: float
    brightness: float


def k1_at_zoom(model: LiveViewParameters, zoom: float) -> float:
    """The radial distortion of a view at ``zoom``: k1_wide at zoom 1, linear to k1_tele at tele_zoom."""
    fraction = np.clip((zoom - 1.0) / (model.tele_zoom - 1.0), 0.0, 1.0)
    return float(model.k1_wide + fraction * (model.k1_tele - model.k1_wide))


def view_conditions(model: LiveViewParameters, pose) -> ViewConditions:
    """The values of the view at ``pose`` (pan_deg, tilt_deg, zoom): drawn from a generator seeded
    by the model's seed and the pose's bits, so that the same pose always gets the same values."""
    pose = np.asarray(pose, dtype=float)
    rng = np.random.default_rng([model.seed, *pose.view(np.uint32).tolist()])
    roll_deg = rng.uniform(-model.roll_max_deg, model.roll_max_deg)
    # Uniform over the disc: the radius of a uniform point grows as the square root of a uniform draw.
    radius_px = model.principal_offset_max_px * np.sqrt(rng.uniform())
    angle = rng.uniform(0.0, 2.0 * np.pi)
    gain = rng.uniform(*model.gain)
    brightness = rng.uniform(-model.brightness_max, model.brightness_max)
    offset_px = (float(radius_px * np.cos(angle)), float(radius_px * np.sin(angle)))
    return ViewConditions(Lens(float(roll_deg), offset_px, k1_at_zoom(model, pose[2])), float(gain), float(brightness))


def view_lens(model: LiveViewParameters, virtual: VirtualPTZ, pose) -> Lens:
    """The lens of the view at ``pose`` in ``virtual``'s pixels (its principal point offset scaled
    to the virtual camera's image width)."""
    return _in_pixels_of(virtual, model, view_conditions(model, pose).lens)


def _in_pixels_of(virtual: VirtualPTZ, model: LiveViewParameters, lens: Lens) -> Lens:
    scale = virtual.camera.image_width_px / model.offset_image_width_px
    offset_px = (lens.principal_offset_px[0] * scale, lens.principal_offset_px[1] * scale)
    return Lens(lens.roll_deg, offset_px, lens.k1)


def render_live(virtual: VirtualPTZ, frame, pose, model: LiveViewParameters) -> np.ndarray:
    """The live view (h, w, 3) uint8 BGR of a recorded frame at ``pose``: each pixel reads the
    recording along its ray through the view's lens; then the view's gain and brightness, then JPEG
    compression (``cv2.imencode`` and ``cv2.imdecode``)."""
    pose = np.asarray(pose, dtype=float)
    conditions = view_conditions(model, pose)
    lens = _in_pixels_of(virtual, model, conditions.lens)
    directions = pixel_directions(virtual.camera, pose, lens, virtual.pixel_centres())
    view = resample(frame, virtual.maps_of_directions(directions), pose[2])
    relit = np.clip(np.rint(view * conditions.gain + conditions.brightness), 0, 255).astype(np.uint8)
    encoded = cv2.imencode(".jpg", relit, [cv2.IMWRITE_JPEG_QUALITY, model.jpeg_quality])[1]
    return np.asarray(cv2.imdecode(encoded, cv2.IMREAD_COLOR))


def render_view(virtual: VirtualPTZ, frame, pose, model: LiveViewParameters | None) -> np.ndarray:
    """The camera's view of a recorded frame at ``pose``: live (:func:`render_live`) with a model,
    the exact pinhole view (``virtual.render``) without."""
    return virtual.render(frame, pose) if model is None else render_live(virtual, frame, pose, model)


def recorded_to_live(virtual: VirtualPTZ, recorded_px, pose, model: LiveViewParameters) -> np.ndarray:
    """Recorded (distorted) pixels (N, 2) to pixels (N, 2) of the live view at ``pose``; NaN behind it."""
    pose = np.asarray(pose, dtype=float)
    directions = virtual.recorded_directions(recorded_px)
    return project_directions(virtual.camera, pose, view_lens(model, virtual, pose), directions)
