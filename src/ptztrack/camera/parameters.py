"""The PTZ camera's parameters and their defaults, plain data that the configuration maps onto
(:mod:`ptztrack.config` takes its defaults from here)."""

from dataclasses import dataclass


@dataclass(frozen=True)
class LandingErrorParameters:
    """How far a camera lands from the pose it is sent to: pan and tilt off by ``pan_tilt_bias_deg``
    plus Gaussian errors of ``pan_tilt_sigma_deg``, zoom times ``zoom_bias`` times (1 + a Gaussian
    error of ``zoom_sigma``). The defaults are a perfect camera."""

    pan_tilt_sigma_deg: float = 0.0
    pan_tilt_bias_deg: tuple[float, float] = (0.0, 0.0)
    zoom_sigma: float = 0.0
    zoom_bias: float = 1.0


@dataclass(frozen=True)
class LiveViewParameters:
    """The departures of a real PTZ camera's views from the pinhole model, and their ranges.

    roll_max_deg : roll about the optical axis, uniform in [-roll_max_deg, roll_max_deg].
    principal_offset_max_px : principal point offset, uniform over the disc of this radius, in
        pixels of an image ``offset_image_width_px`` wide (other image sizes scale it).
    k1_wide, k1_tele, tele_zoom : radial distortion (normalised coordinates), k1_wide at zoom 1
        falling linearly to k1_tele at ``tele_zoom`` and held beyond.
    gain : (low, high) contrast factor, uniform; brightness_max : brightness offset in grey
        levels, uniform in [-brightness_max, brightness_max].
    jpeg_quality : JPEG quality (1-100) each image is compressed at.
    seed : the camera unit: its views' values at a pose are fixed by the seed and the pose.
    """

    roll_max_deg: float = 2.0
    principal_offset_max_px: float = 10.0
    offset_image_width_px: int = 640
    # The PETS camera's own lens over the field of the zoom-1 view (its calibration's k1).
    k1_wide: float = -0.15
    k1_tele: float = 0.0
    tele_zoom: float = 4.0
    gain: tuple[float, float] = (0.7, 1.3)
    brightness_max: float = 20.0
    jpeg_quality: int = 75
    seed: int = 0
