"""The detector model a camera learns as it runs: recall by apparent height, false positives, pixel noise.

A deployed camera is not told its detector's recall curve, clutter rate and
pixel noise; it learns them from its own tracker, which knows every step
which established tracks it predicted fully in view and at which height, and
which of them a detection confirmed (:class:`ptztrack.types.TrackerEvidence`).
No annotation is read.

Recall. Apparent heights are cut into bins (``HEIGHT_BIN_EDGES_PX``). Each
bin holds Beta pseudo-counts from the prior curve, ``w p0(r_b)`` successes
and ``w (1 - p0(r_b))`` failures (``PRIOR_TRIALS_PER_BIN`` = w), plus the
evidence: a track of existence ``e``, predicted fully in view at height
``r`` and hidden by a fraction ``c`` of its box behind other tracks, is a
trial of weight ``e (1 - c)`` in r's bin, a success when a detection was
assigned to it. The policies need a curve they can integrate in closed form,
``recall(r) = P (1 - exp(-Kd (r - r0)))`` (the paper's equation 13 with a
plateau ``P``): its parameters are the posterior mode of the binned
likelihood,

    argmax_{Kd, r0, P}  sum_b  s_b log recall(r_b) + f_b log(1 - recall(r_b)),

over a fixed grid that holds the prior curve's own parameters, so that with
no evidence the model is the prior. Each bin's Beta posterior gives the
reported recall and its standard deviation. The tracker reads this mode.

A prior that does not depend on the height (``RecallModel.perfect``: a
constant recall ``P``, say a fixed camera given a published detector's
boxes) keeps to constants: the fitted recall is the mode of the same binned
likelihood over every constant, ``P = sum_b s_b / sum_b (s_b + f_b)``, the
pooled share of successes, and it stays height-independent. The curve is not
learned there: a constant is not in its family (it is the limit Kd -> inf,
r0 = 0), and a fixed camera sees each place at one height only, so the bins'
recall would confound the height with the place (scene objects, the view's
edges, the calibration's error with range), which a PTZ camera, zooming,
tells apart.

The policies plan with a draw instead (Thompson sampling): after every
step, one recall per bin from its Beta posterior, with Jeffreys' half a
success and half a failure added so that no bin is ever certain, and the
curve fitted to the draws as to counts. A prior that says people smaller
than its r0 are never found would otherwise confirm itself: the camera
would never look where they are that small, and never see that they are
found. Once a bin holds evidence, its draws stay near its recall.

False positives per view: a Gamma-Poisson posterior, with the prior mean
weighted as ``PRIOR_VIEWS`` views, on the tracks that one detection started
and that died unconfirmed where the detector would have found them again.
A view counts by its exposure ``x_t``, the share of it where a false
detection would have started a track (a tracker that starts none in a
track's gate sees false births only outside the gates):
``lambda = (PRIOR_VIEWS lambda0 + sum_t births_t) / (PRIOR_VIEWS + sum_t x_t)``.

Pixel noise: with ``excess = |nu|^2 - tr(C P C^T)``, ``E[excess] = 2 sigma^2``;
``sigma^2`` is the mean of the excesses with the prior's ``sigma0^2`` weighted
as ``PRIOR_INNOVATIONS`` innovations.
"""

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ptztrack.detect.parameters import DetectorPriorParameters
from ptztrack.detect.simulated import RecallModel
from ptztrack.files import InputError, read_json, write_json
from ptztrack.geometry.occlusion import occluded_fraction
from ptztrack.geometry.ptz import PTZCamera, look_at, person_in_view, project_people
from ptztrack.types import TrackerEvidence

# 19 bins 1.25x apart from 4 px to 278 px: a person is a few pixels to a whole view tall.
HEIGHT_BIN_EDGES_PX = 4.0 * 1.25 ** np.arange(0, 20)
# The prior's weight: as if the camera had seen two people of every size (a priori, before any run).
PRIOR_TRIALS_PER_BIN = 2.0
PRIOR_VIEWS = 10.0
PRIOR_INNOVATIONS = 10.0
# A track is an established person once detected twice; only a track localised this well is a fair trial.
ESTABLISHED_HITS = 2
TRIAL_POSITION_SIGMA_M = 0.5
# The curve's search grid: Kd from 0.002 to 1 per px, r0 from 0 to 40 px, the plateau from 0.3 to 1.
GRID_KD_PER_PX = np.geomspace(0.002, 1.0, 28)
GRID_R0_PX = np.arange(0.0, 40.0, 1.0)
GRID_PLATEAU = np.linspace(0.3, 1.0, 15)
PROBABILITY_FLOOR = 1e-4


def bin_centres_px(edges_px=HEIGHT_BIN_EDGES_PX) -> np.ndarray:
    """The geometric centre of each height bin; (B,)."""
    return np.sqrt(edges_px[:-1] * edges_px[1:])


def _curve_grid(prior: RecallModel, centres_px) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The candidate curves' parameters (G, 3) as (Kd, r0, plateau), with the prior's among them, and their
    log recall and log miss probability at the bin centres (G, B) each."""
    kd = np.union1d(GRID_KD_PER_PX, [prior.kd_per_px])
    r0 = np.union1d(GRID_R0_PX, [prior.r0_px])
    plateau = np.union1d(GRID_PLATEAU, [prior.plateau])
    parameters = np.stack(np.meshgrid(kd, r0, plateau, indexing="ij"), axis=-1).reshape(-1, 3)
    rise = -np.expm1(-parameters[:, :1] * np.maximum(centres_px[None] - parameters[:, 1:2], 0.0))
    recall = np.clip(parameters[:, 2:] * rise, PROBABILITY_FLOOR, 1 - PROBABILITY_FLOOR)
    return parameters, np.log(recall), np.log1p(-recall)


@dataclass
class OnlineDetectorModel:
    """A detector model learned from the tracker's evidence, read by the policies as a :class:`RecallModel`.

    camera, person_height_m, person_width_m : what a track's apparent size is computed with.
    prior : the curve the camera starts from; learning : False keeps the prior (the a-priori model).
    prior_successes, prior_trials : (B,) the bins' pseudo-counts (by default from ``prior``; a file
        written by :meth:`save` sets them to what an earlier run learned).
    false_positives_per_view, pixel_noise_px : the prior's clutter and noise, with their weights.
    """

    camera: PTZCamera
    person_height_m: float
    person_width_m: float
    prior: RecallModel
    learning: bool = True
    false_positives_per_view: float = DetectorPriorParameters.false_positives_per_frame
    pixel_noise_px: float = DetectorPriorParameters.pixel_noise_px
    prior_successes: np.ndarray | None = None
    prior_trials: np.ndarray | None = None
    prior_views: float = PRIOR_VIEWS
    prior_innovations: float = PRIOR_INNOVATIONS
    rng: np.random.Generator = field(default_factory=lambda: np.random.default_rng(0), repr=False)
    successes: np.ndarray = field(init=False, repr=False)
    trials: np.ndarray = field(init=False, repr=False)
    curve: RecallModel = field(init=False)
    planning_curve: RecallModel = field(init=False)
    false_births: float = field(default=0.0, init=False)
    views: float = field(default=0.0, init=False)
    excess_sum_px2: float = field(default=0.0, init=False)
    innovations: int = field(default=0, init=False)

    def __post_init__(self):
        self.centres_px = bin_centres_px()
        if self.prior_trials is None:
            p0 = self.prior(self.centres_px)
            self.prior_trials = np.full(len(self.centres_px), PRIOR_TRIALS_PER_BIN)
            self.prior_successes = PRIOR_TRIALS_PER_BIN * p0
        self.successes = np.zeros(len(self.centres_px))
        self.trials = np.zeros(len(self.centres_px))
        if not self.prior.perfect:
            self._parameters, self._log_recall, self._log_miss = _curve_grid(self.prior, self.centres_px)
        self.curve = self.prior
        self._refit()
        self._draw()

    # The RecallModel the policies and the tracker read.
    @property
    def perfect(self) -> bool:
        return self.curve.perfect

    @property
    def kd_per_px(self) -> float:
        return self.curve.kd_per_px

    @property
    def r0_px(self) -> float:
        return self.curve.r0_px

    @property
    def plateau(self) -> float:
        return self.curve.plateau

    def __call__(self, height_px) -> np.ndarray:
        return self.curve(height_px)

    def observe(self, evidence: TrackerEvidence) -> None:
        """Add one tracker step's evidence (see the module's docstring) and refit the curve."""
        if not self.learning:
            return
        self.views += evidence.exposure
        self.false_births += evidence.false_births
        self.excess_sum_px2 += float(np.sum(evidence.excess_px2))
        self.innovations += len(evidence.excess_px2)
        index, height_px, weight = self.trials_of(evidence)
        if len(index):
            which = np.digitize(height_px, HEIGHT_BIN_EDGES_PX) - 1
            inside = (which >= 0) & (which < len(self.centres_px))
            self.trials += np.bincount(which[inside], weight[inside], len(self.centres_px))
            found = weight * evidence.detected[index]
            self.successes += np.bincount(which[inside], found[inside], len(self.centres_px))
            self._refit()
        self._draw()

    def trials_of(self, evidence: TrackerEvidence) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The established tracks predicted fully in view: their indices (k,), heights (k,) px and
        trial weights (k,)."""
        none = np.zeros(0, dtype=int), np.zeros(0), np.zeros(0)
        mean_m = np.asarray(evidence.mean_m, dtype=float)
        if len(mean_m) == 0:
            return none
        candidate = (evidence.hits >= ESTABLISHED_HITS) & (evidence.position_sigma_m <= TRIAL_POSITION_SIGMA_M)
        if not candidate.any():
            return none
        people = project_people(self.camera, evidence.pose, mean_m, self.person_height_m, self.person_width_m)
        index = np.flatnonzero(person_in_view(self.camera, people) & candidate)
        if len(index) == 0:
            return none
        centred = project_people(
            self.camera,
            look_at(self.camera, mean_m.mean(axis=0), 1.0),
            mean_m,
            self.person_height_m,
            self.person_width_m,
        )
        hidden = occluded_fraction(centred.box_px, centred.range_m, centred.in_front)
        return index, people.height_px[index], evidence.existence[index] * (1.0 - hidden[index])

    def _refit(self) -> None:
        successes = self.prior_successes + self.successes
        self.curve = self._fitted(successes, self.prior_trials + self.trials - successes)

    def _fitted(self, successes, failures) -> RecallModel:
        """The grid's curve of highest binned likelihood for these counts (B,) each; for a height-independent
        prior, the constant of highest likelihood, ``sum(successes) / sum(successes + failures)``."""
        if self.prior.perfect:
            return RecallModel.constant(float(np.sum(successes) / (np.sum(successes) + np.sum(failures))))
        score = self._log_recall @ successes + self._log_miss @ failures
        kd, r0, plateau = self._parameters[int(np.argmax(score))]
        return RecallModel(float(kd), float(r0), plateau=float(plateau))

    def _draw(self) -> None:
        """A new planning curve from the posterior (see the module's docstring); the mode's when not learning."""
        if not self.learning:
            self.planning_curve = self.curve
            return
        successes = self.prior_successes + self.successes + 0.5
        failures = self.prior_trials + self.trials - self.prior_successes - self.successes + 0.5
        drawn = self.rng.beta(successes, failures)
        total = successes + failures
        self.planning_curve = self._fitted(total * drawn, total * (1.0 - drawn))

    def planner(self) -> "PlanningCurve":
        """The curve the policies plan with, as a :class:`RecallCurve` that follows the model's draws."""
        return PlanningCurve(self)

    def recall_by_bin(self) -> tuple[np.ndarray, np.ndarray]:
        """Each bin's Beta posterior mean and standard deviation of recall; (B,) each."""
        a = self.prior_successes + self.successes
        b = self.prior_trials + self.trials - a
        mean = a / (a + b)
        return mean, np.sqrt(a * b / ((a + b) ** 2 * (a + b + 1)))

    @property
    def clutter_per_view(self) -> float:
        """The posterior mean of the false positives per view (the module's docstring)."""
        return (self.prior_views * self.false_positives_per_view + self.false_births) / (self.prior_views + self.views)

    @property
    def learned_pixel_noise_px(self) -> float:
        """The posterior estimate of the feet's pixel noise (1 sigma per axis)."""
        variance = (2 * self.prior_innovations * self.pixel_noise_px**2 + self.excess_sum_px2) / (
            2 * (self.prior_innovations + self.innovations)
        )
        return math.sqrt(max(variance, 0.25))

    def as_dict(self) -> dict:
        """The model as ``detector_model.json`` holds it."""
        mean, sd = self.recall_by_bin()
        return {
            "height_px": self.centres_px.tolist(),
            "height_bin_edges_px": HEIGHT_BIN_EDGES_PX.tolist(),
            "recall": mean.tolist(),
            "recall_sd": sd.tolist(),
            "successes": (self.prior_successes + self.successes).tolist(),
            "trials": (self.prior_trials + self.trials).tolist(),
            "curve": {
                "kd_per_px": self.kd_per_px,
                "r0_px": self.r0_px,
                "plateau": self.plateau,
                "perfect": self.perfect,
            },
            "clutter_per_view": self.clutter_per_view,
            "views": self.prior_views + self.views,
            "pixel_noise_px": self.learned_pixel_noise_px,
            "innovations": self.prior_innovations + self.innovations,
            "learning": self.learning,
        }

    def save(self, path: str | Path) -> None:
        """Write :meth:`as_dict` to ``path`` (a temporary file beside it, then renamed)."""
        write_json(path, self.as_dict())


@dataclass(frozen=True)
class PlanningCurve:
    """The latest draw of an :class:`OnlineDetectorModel`, read as a :class:`RecallCurve`."""

    model: OnlineDetectorModel

    @property
    def kd_per_px(self) -> float:
        return self.model.planning_curve.kd_per_px

    @property
    def r0_px(self) -> float:
        return self.model.planning_curve.r0_px

    @property
    def plateau(self) -> float:
        return self.model.planning_curve.plateau

    @property
    def perfect(self) -> bool:
        return self.model.planning_curve.perfect

    def __call__(self, height_px) -> np.ndarray:
        return self.model.planning_curve(height_px)


class DetectorModelFileError(InputError):
    """A detector model file that cannot be read as one."""


MAX_FILE_BYTES = 1_000_000


def read_detector_model_file(path: str | Path) -> dict:
    """The prior a file written by :meth:`OnlineDetectorModel.save` holds: ``prior_successes``,
    ``prior_trials`` (B,), ``false_positives_per_view``, ``prior_views``, ``pixel_noise_px``,
    ``prior_innovations`` and the curve as ``prior``; checked against this model's bins."""
    path = Path(path)
    data = read_json(path, "detector model", MAX_FILE_BYTES, DetectorModelFileError)
    if not isinstance(data, dict):
        raise DetectorModelFileError(f"{path}: expected a detector model (a JSON object)")
    bins = len(HEIGHT_BIN_EDGES_PX) - 1
    try:
        successes = np.asarray(data["successes"], dtype=float)
        trials = np.asarray(data["trials"], dtype=float)
        curve = data["curve"]
        prior = RecallModel(
            float(curve["kd_per_px"]),
            float(curve["r0_px"]),
            perfect=bool(curve.get("perfect", False)),
            plateau=float(curve["plateau"]),
        )
        fields = {
            "false_positives_per_view": float(data["clutter_per_view"]),
            "prior_views": float(data["views"]),
            "pixel_noise_px": float(data["pixel_noise_px"]),
            "prior_innovations": float(data["innovations"]),
        }
    except (KeyError, TypeError, ValueError) as error:
        raise DetectorModelFileError(f"{path}: missing or malformed field {error} of a detector model") from None
    edges = np.asarray(data.get("height_bin_edges_px", []), dtype=float)
    if edges.shape != HEIGHT_BIN_EDGES_PX.shape or not np.allclose(edges, HEIGHT_BIN_EDGES_PX):
        raise DetectorModelFileError(f"{path}: its height bins are not this version's ({bins} bins from 4 px)")
    values = [*fields.values(), prior.kd_per_px, prior.r0_px, prior.plateau]
    if (
        successes.shape != (bins,)
        or trials.shape != (bins,)
        or not np.all(np.isfinite(values))
        or np.any(successes < 0)
        or np.any(successes > trials)
        or min(values) < 0
    ):
        raise DetectorModelFileError(f"{path}: counts or values out of range for a detector model")
    return {"prior": prior, "prior_successes": successes, "prior_trials": trials, **fields}
