"""Spatiogram template matching as a measurement source (Lisanti, Del Bimbo and Pernici, section 5).

Each track keeps a colour spatiogram of its person (:mod:`ptztrack.track.appearance`),
taken from the box of a detection. At a step, each track predicted in the
image is searched for near its predicted feet, with boxes of the size a
person must have there (from the head/feet homology of the pose), and a good
enough match gives a feet pixel for that track: the paper's "scale invariant
template matching inside [the] target search region".

The thresholds (``MIN_SIMILARITY``, ``MIN_RADIUS_PX``, ``MAX_RADIUS_PX``) were measured on PETS 2009
S2.L1 View_001 (the measurements are in the documentation's registration page, "Template thresholds").
"""

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from ptztrack.geometry.ptz import (
    PTZCamera,
    apply_homography,
    head_from_feet_homology,
    inside_image,
    pose_noise_px2,
)
from ptztrack.roles import ImageSource
from ptztrack.track import kalman
from ptztrack.track.appearance import Spatiogram, search, spatiogram
from ptztrack.track.observation import observation_matrix, predicted_feet_px
from ptztrack.track.tracker import EkfTracker, update_own_tracks
from ptztrack.types import Detections, Tracks, TrackUpdate

MIN_SIMILARITY = 0.6
MIN_RADIUS_PX = 3.0
MAX_RADIUS_PX = 20.0
# The noise the tracker assumes for template-found feet, 1 sigma per axis, as a fraction of the
# person's height: several times one frame's error, because the errors of consecutive frames are not
# independent (a template that settles a little off its person stays off), and a track trusting each
# match alone grows so confident that the next detection falls outside its gate.
NOISE_HEIGHT_FRACTION = 0.2
SEARCH_SIGMAS = 3.0  # the search region is the 3-sigma extent of the innovation covariance

Templates = dict[int, Spatiogram]
"""Each track's template, by track id."""


class TemplateMeasurements(NamedTuple):
    """Matches found by :func:`template_measurements`, one per row.

    feet_px : (K, 2) found feet; track_ids : (K,) the track whose template
    was found; similarity : (K,) in [min_similarity, 1].
    """

    feet_px: np.ndarray
    track_ids: np.ndarray
    similarity: np.ndarray


def template_box_px(camera: PTZCamera, pose, feet_px, person_height_m: float, person_width_m: float) -> np.ndarray:
    """Boxes (K, 4) (left, top, width, height) px of people standing on ``feet_px`` (K, 2) at ``pose``.

    The height is the rows between the feet and the head the homology puts
    above them; the width is that height times ``person_width_m /
    person_height_m``. Feet must lie below the horizon.
    """
    feet_px = np.asarray(feet_px, dtype=float).reshape(-1, 2)
    head_px = apply_homography(head_from_feet_homology(camera, pose, person_height_m), feet_px)
    height_px = feet_px[:, 1] - head_px[:, 1]
    width_px = height_px * person_width_m / person_height_m
    return np.stack([feet_px[:, 0] - width_px / 2, head_px[:, 1], width_px, height_px], axis=-1)


def refresh_templates(
    templates: Templates,
    live_ids,
    image_bgr,
    camera: PTZCamera,
    pose,
    track_ids,
    feet_px,
    person_height_m: float,
    person_width_m: float,
) -> Templates:
    """The templates of the live tracks, those of ``track_ids`` retaken from the image.

    templates : the current ones; live_ids : (n,) ids of the tracks alive
    now, whose templates are kept (the others are dropped); image_bgr :
    (h, w, 3) uint8, seen at ``pose``; track_ids : (M,) tracks to retake,
    each from the box of a person standing on its ``feet_px`` (M, 2) (see
    :func:`template_box_px`). Feet outside the image give no template.
    Returns a new dict; ``templates`` is not changed.
    """
    live = set(np.asarray(live_ids).tolist())
    refreshed = {track_id: template for track_id, template in templates.items() if track_id in live}
    feet_px = np.asarray(feet_px, dtype=float).reshape(-1, 2)
    boxes_px = template_box_px(camera, pose, feet_px, person_height_m, person_width_m)
    for track_id, box_px, seen in zip(
        np.asarray(track_ids).tolist(), boxes_px, inside_image(camera, feet_px), strict=True
    ):
        if seen and track_id in live:
            refreshed[track_id] = spatiogram(image_bgr, box_px)
    return refreshed


def search_radius_px(S, min_radius_px: float = MIN_RADIUS_PX, max_radius_px: float = MAX_RADIUS_PX) -> np.ndarray:
    """Search radii (n,) px: the circles around the 3-sigma ellipses of innovation covariances ``S`` (n, 2, 2) px^2.

    Clipped to ``[min_radius_px, max_radius_px]``.
    """
    sigma_px = np.sqrt(np.linalg.eigvalsh(S)[:, -1])
    return np.clip(SEARCH_SIGMAS * sigma_px, min_radius_px, max_radius_px)


def template_measurements(
    image_bgr,
    camera: PTZCamera,
    pose,
    tracks: Tracks,
    templates: Templates,
    V,
    person_height_m: float,
    person_width_m: float,
    min_similarity: float = MIN_SIMILARITY,
    max_radius_px: float = MAX_RADIUS_PX,
) -> TemplateMeasurements:
    """Feet of the tracked people found by their templates in ``image_bgr`` (h, w, 3) uint8 seen at ``pose``.

    tracks : predicted to this step; V : (2, 2) px^2, the measurement noise
    in the innovation covariance ``S = C P C^T + V`` that sets the search
    radius (:func:`search_radius_px`). Each track with a template whose
    predicted feet lie in front of the camera and in the image is searched
    for around its predicted feet, with boxes of the person's size there
    (:func:`template_box_px`); the best match is a measurement when its
    similarity is at least ``min_similarity``.

    Each measurement belongs to its track and must not start a new one,
    which :func:`~ptztrack.track.tracker.update_tracks` would do with a match
    its association leaves unassigned.
    """
    predicted_px, in_front = predicted_feet_px(camera, pose, tracks.mean)
    S = kalman.innovation_covariance(tracks.covariance, observation_matrix(camera, pose, tracks.mean), V)
    radius_px = search_radius_px(S, max_radius_px=max_radius_px)
    searched = np.flatnonzero(in_front & inside_image(camera, predicted_px) & np.isin(tracks.ids, list(templates)))
    boxes_px = template_box_px(camera, pose, predicted_px[searched], person_height_m, person_width_m)
    found_px, track_ids, scores = [], [], []
    for index, (_, _, width_px, height_px) in zip(searched, boxes_px, strict=True):
        template = templates[int(tracks.ids[index])]
        feet_px, score = search(image_bgr, template, predicted_px[index], height_px, width_px, radius_px[index])
        if score >= min_similarity:
            found_px.append(feet_px)
            track_ids.append(tracks.ids[index])
            scores.append(score)
    return TemplateMeasurements(
        np.reshape(found_px, (-1, 2)), np.asarray(track_ids, dtype=int), np.asarray(scores, dtype=float)
    )


def template_noise_covariance(camera: PTZCamera, pose, feet_px, person_height_m: float, V) -> np.ndarray:
    """(K, 2, 2) px^2: the noise of template-found feet (K, 2) px, ``NOISE_HEIGHT_FRACTION`` of the
    person's height there per axis, and never below the detector's ``V`` (2, 2)."""
    height_px = template_box_px(camera, pose, feet_px, person_height_m, 1.0)[:, 3]
    return np.maximum((NOISE_HEIGHT_FRACTION * height_px)[:, None, None] ** 2 * np.eye(2), V)


@dataclass
class TemplateTracker:
    """The ground tracker measuring people by their templates between detector steps (a
    :class:`ptztrack.roles.Tracker`).

    The detector runs every ``detector_every_steps`` steps; there ``tracker`` (the EKF tracker)
    updates, starts and deletes tracks, and each track the update pairs with a detection takes its
    template from that detection's box in the view. In between, each track with a template is
    searched for in the view (:func:`template_measurements`) and a match updates that track alone
    (:func:`~ptztrack.track.tracker.update_own_tracks`). People are ``person_height_m`` tall and
    ``person_width_m`` wide.
    """

    tracker: EkfTracker
    detector_every_steps: int
    person_height_m: float
    person_width_m: float
    templates: Templates = field(default_factory=dict)

    def predict(self, dt_s: float | None = None) -> Tracks:
        return self.tracker.predict(dt_s)

    def wants_detections(self, step: int) -> bool:
        return step % self.detector_every_steps == 0

    def update(self, detections: Detections | None, pose, view: ImageSource, pose_sd=None) -> TrackUpdate:
        """The detector's update where it ran, else the templates'; pose_sd as :meth:`EkfTracker.update` takes it."""
        camera, height_m, width_m = self.tracker.camera, self.person_height_m, self.person_width_m
        image = view()
        if image is None:
            raise RuntimeError("template matching needs a camera backend that renders images")
        if detections is not None:
            update = self.tracker.update(detections, pose, view, pose_sd)
            feet_px = detections.feet_px[update.measurement_index]
            self.templates = refresh_templates(
                self.templates, update.tracks.ids, image, camera, pose, update.track_ids, feet_px, height_m, width_m
            )
            return update
        tracks, V = self.tracker.tracks, self.tracker.V
        if pose_sd is not None:
            V = V + pose_noise_px2(camera, pose, pose_sd)
        found = template_measurements(image, camera, pose, tracks, self.templates, V, height_m, width_m)
        noise = template_noise_covariance(camera, pose, found.feet_px, height_m, V)
        max_sigma_m = self.tracker.parameters.max_position_sigma_m
        self.tracker.tracks = update_own_tracks(
            tracks, found.track_ids, found.feet_px, camera, pose, noise, max_sigma_m
        )
        height_px = template_box_px(camera, pose, found.feet_px, height_m, width_m)[:, 3]
        measurements = Detections(found.feet_px, height_px, np.full(len(found.feet_px), -1), found.similarity)
        alive = np.isin(found.track_ids, self.tracker.tracks.ids)
        return TrackUpdate(self.tracker.tracks, found.track_ids[alive], np.flatnonzero(alive), measurements)

    def reported(self) -> Tracks:
        return self.tracker.reported()
