"""A camera's constant feet-pixel bias, estimated online from the innovations of its paired detections.

A calibrated camera whose calibration is a little off puts every feet pixel a little off: the
registration error of multisensor tracking, modelled, as there, by a constant bias ``b`` (2,) px in the
sensor's measurement, ``z = h(x) + b + r`` (Friedland, IEEE TAC 1969, "Treatment of bias in recursive
filtering"). Each detection paired with a track predicted at ``x-`` has the raw innovation
``z - h(x-) = b + e`` with ``e`` of covariance ``S / w``: ``S = C P- C^T + V`` and ``w`` its Student-t
weight (:func:`ptztrack.track.pixel_noise.student_t_weight`; 1 for Gaussian noise), so that a far detection
says less. With the prior ``b ~ N(0, V0)``, a bias a priori no larger than the pixel noise ``V0`` that
was meant to hold the calibration's error, the posterior mean after the detections ``j`` so far is

    b = (V0^-1 + sum_j w_j S_j^-1)^-1 sum_j w_j S_j^-1 (z_j - h(x_j-)),

in information form. The detections are corrected by the estimate of the steps before, ``z - b``, before
they update the tracks. Tracks the camera's own corrected detections hold add innovations close to the
current ``b`` and so keep it; the other cameras' tracks move it.
"""

from dataclasses import dataclass, field

import numpy as np


@dataclass
class PixelBias:
    """One camera's feet-pixel bias (see the module's docstring).

    information : (2, 2) 1/px^2, ``V0^-1 + sum_j w_j S_j^-1``; weighted_innovations : (2,) 1/px,
    ``sum_j w_j S_j^-1 (z_j - h(x_j-))``.
    """

    information: np.ndarray
    weighted_innovations: np.ndarray = field(default_factory=lambda: np.zeros(2))

    @classmethod
    def centred(cls, prior_px2) -> "PixelBias":
        """No bias yet, with the prior ``N(0, prior_px2)`` ((2, 2) px^2)."""
        return cls(np.linalg.inv(prior_px2))

    def estimate(self) -> np.ndarray:
        """The posterior mean ``b`` (2,) px."""
        return np.linalg.solve(self.information, self.weighted_innovations)

    def observe(self, raw_innovation_px, S_px2, weight) -> None:
        """Take in paired detections' raw innovations ``z - h(x-)`` (k, 2) px, their covariances ``S``
        (k, 2, 2) px^2 and Student-t weights ``w`` (k,)."""
        weighted_precision = np.asarray(weight, dtype=float)[:, None, None] * np.linalg.inv(S_px2)
        self.information = self.information + weighted_precision.sum(axis=0)
        self.weighted_innovations = self.weighted_innovations + np.einsum(
            "kij,kj->i", weighted_precision, np.asarray(raw_innovation_px, dtype=float).reshape(-1, 2)
        )
