"""A camera's feet-pixel noise learned online from its own innovations (variational Bayes).

A detection ``z`` (2,) px of a track predicted at ``x-`` with covariance ``P-`` (4, 4) px has the
innovation ``nu = z - h(x-)`` of covariance ``S = C P- C^T + V``, ``C`` (2, 4) the observation's
Jacobian. The variational-Bayes adaptive Kalman filter (Sarkka & Nummenmaa, IEEE TAC 2009; with an
inverse-Wishart noise covariance, Sarkka & Hartikainen, MLSP 2013) learns ``V`` from each detection's
expected squared residual under the updated state, ``eps eps^T + C P+ C^T`` with ``eps = z - h(x+) =
V S^-1 nu`` and ``C P+ C^T = V - V S^-1 V``:

    B = V S^-1 nu nu^T S^-1 V + V - V S^-1 V,    E[B] = V where V is right.

A track the camera barely constrains (``C P- C^T`` much larger than ``V``) gives ``B`` close to ``V``:
it neither raises nor lowers the estimate. Two additions:

* The gate. Only detections within the chi-square gate ``nu^T S^-1 nu <= g`` are associated, and a
  Gaussian innovation's second moment inside it is ``c S``, ``c = F_4(g) / F_2(g)`` (``F_k`` the
  chi-square distribution function with ``k`` degrees of freedom); ``nu nu^T`` is divided by ``c``.
  So the estimate can grow: innovations much wider than the gate fill it, ``nu nu^T`` about
  ``g / 4 S`` per axis, more than ``c S``, and ``V`` grows until the gate holds them.
* The prior. The a-priori noise ``V0`` is the mean of an inverse-Wishart prior worth ``n0``
  detections, and ``V`` never falls below it:

      V = V0 + [ (n0 V0 + sum_j B_j) / (n0 + n) - V0 ]_+,

  ``[A]_+`` the symmetric matrix ``A`` with its negative eigenvalues set to 0, ``n`` the detections
  seen, each ``B_j`` taken with the ``V`` of its step (one variational iteration per step). Every
  detection counts alike (no forgetting): the noise learned is that of a camera's calibration and
  detector, which do not change during a run.
"""

from dataclasses import dataclass, field

import numpy as np
from scipy.stats import chi2


def gate_second_moment(gate_probability: float) -> float:
    """``c = F_4(g) / F_2(g)``, ``g = F_2^-1(gate_probability)``: a 2-d Gaussian innovation's covariance
    inside the chi-square gate is ``c S`` (``E[w w^T | |w|^2 <= g] = F_4(g) / F_2(g) I`` for ``w ~ N(0, I)``)."""
    g = chi2.ppf(gate_probability, df=2)
    return float(chi2.cdf(g, df=4) / gate_probability)


def positive_part(matrix) -> np.ndarray:
    """The symmetric (2, 2) ``matrix`` with its negative eigenvalues set to 0."""
    eigenvalues, eigenvectors = np.linalg.eigh(matrix)
    return (eigenvectors * np.maximum(eigenvalues, 0.0)) @ eigenvectors.T


@dataclass
class AdaptiveNoise:
    """One camera's pixel noise ``V`` (2, 2) px^2, learned from its associated detections (see the module's
    docstring).

    prior : (2, 2) px^2 the a-priori noise ``V0``, also the floor; prior_detections : ``n0``, the prior's
    weight in detections; gate_probability : the association's chi-square gate (2 degrees of freedom).
    """

    prior: np.ndarray
    prior_detections: float
    gate_probability: float
    residual_px2: np.ndarray = field(default_factory=lambda: np.zeros((2, 2)))
    detections: int = 0

    def covariance(self) -> np.ndarray:
        """``V`` (2, 2) px^2 from the detections observed so far."""
        n0 = self.prior_detections
        mean = (n0 * self.prior + self.residual_px2) / (n0 + self.detections)
        return self.prior + positive_part(mean - self.prior)

    def observe(self, innovation_px, predicted_spread_px2) -> None:
        """Take in associated detections' innovations ``nu`` (k, 2) px and their tracks' predicted spreads
        ``C P- C^T`` (k, 2, 2) px^2, measured with this noise's :meth:`covariance`."""
        innovation_px = np.asarray(innovation_px, dtype=float).reshape(-1, 2)
        V = self.covariance()
        gain = V @ np.linalg.inv(predicted_spread_px2 + V)
        outer = innovation_px[:, :, None] * innovation_px[:, None, :] / gate_second_moment(self.gate_probability)
        expected = gain @ outer @ np.swapaxes(gain, -1, -2) + V - gain @ V
        self.residual_px2 = self.residual_px2 + np.sum(expected, axis=0)
        self.detections += len(innovation_px)
