"""The detectors' parameters and their defaults, plain data that the configuration maps onto
(:mod:`ptztrack.config` takes its defaults from here)."""

from dataclasses import dataclass


@dataclass(frozen=True)
class DetectorPriorParameters:
    """What the policies and the tracker are told of a simulated or learned detector before a run.

    recall_kd, recall_r0_px : the recall curve ``1 - exp(-kd (r - r0))`` of a person ``r`` px tall
        (the paper's equation 13; by default its Caltech fit of OpenCV's HOG).
    pixel_noise_px : the feet's pixel noise, 1 sigma per axis.
    false_positives_per_frame : false detections per view.
    """

    recall_kd: float = 0.0098
    recall_r0_px: float = 21.29
    pixel_noise_px: float = 2.0
    false_positives_per_frame: float = 0.0


@dataclass(frozen=True)
class BoxDetectorParameters:
    """A recording's precomputed boxes as the PTZ camera's detector
    (:class:`ptztrack.detect.published.PublishedDetections`).

    min_score : boxes scored lower are not reported (0.5: the usual operating threshold of a person
        detector's score, fixed a priori).
    """

    min_score: float = 0.5


@dataclass(frozen=True)
class HogParameters:
    """OpenCV's HOG people detector as ptztrack runs it (:class:`ptztrack.detect.hog.HogPeopleDetector`).

    upsample : factor applied to the view before detection (128 / 21.29 px, rounded: a person at the
        recall curve's r0 fills the 128 px window); hit_threshold : the SVM score below which a window
        is not a detection; nms_iou : boxes overlapping more (intersection over union) are merged;
    person_heights_m : (shortest, tallest) standing person the ground search looks for.
    """

    upsample: float = 6.0
    hit_threshold: float = 0.0
    nms_iou: float = 0.4
    person_heights_m: tuple[float, float] = (1.5, 2.0)
