"""One ground belief for a network of cameras: each camera's detections update it in turn.

Every step the belief is predicted once; then camera 1's detections update
it through camera 1's pose, Jacobian and pixel noise, camera 2's update the
result through its own, and so on. For measurements ``z_k = C_k x + r_k``
with independent noises ``r_k ~ N(0, V_k)``, updating in turn is the joint
update: in information form each update adds ``C_k^T V_k^-1 C_k``, so after
all of them

    P+^-1 = P-^-1 + sum_k C_k^T V_k^-1 C_k,
    x+ = x- + P+ sum_k C_k^T V_k^-1 (z_k - C_k x-),

whatever the order. With the cameras' homographies the EKF linearises each
camera's update at the state the cameras before it left, not at ``x-``;
where a detection falls where it was predicted the two agree exactly.

A person seen by two cameras is one track: the second camera's detection is
associated with the track the first one updated or started. A track one
camera misses where it would have found the person loses existence by that
camera's detection probability, and a track it does not look at keeps it
(:mod:`ptztrack.track.tracker`), so the existence update is Bayes' rule for
independent sensors too.

Cameras in ``needs_a_second_camera`` do not get a track reported on their own:
a track that only one of them has detected is reported once another camera
has detected it too. A person stands where several cameras see, so a track
that one camera alone keeps confirming is more likely its own duplicate of
somebody (its calibration putting the feet elsewhere than the others') or
its clutter than a person only it sees.
"""

from dataclasses import dataclass, field

import numpy as np

from ptztrack.roles import ImageSource
from ptztrack.track.tracker import EkfTracker
from ptztrack.types import Detections, Tracks, TrackUpdate


@dataclass
class SharedBelief:
    """The network's tracker (:class:`ptztrack.roles.NetworkTracker`): one set of tracks, one
    :class:`EkfTracker` per camera for its camera model, pixel noise, detection model and the detector
    model it teaches.

    The motion model and what is reported are the first camera's tracker's parameters (a scenario gives
    every camera the same tracker section).

    needs_a_second_camera : indices of the cameras whose detections alone do not get a track reported
        (see the module's docstring); detected_by : each live track's id -> the cameras that have detected it.
    """

    cameras: tuple[EkfTracker, ...]
    tracks: Tracks = field(default_factory=Tracks.empty)
    needs_a_second_camera: frozenset[int] = frozenset()
    detected_by: dict[int, frozenset[int]] = field(default_factory=dict, repr=False)

    def __post_init__(self):
        if not self.cameras:
            raise ValueError("a shared belief needs at least one camera's tracker")

    def predict(self, dt_s: float | None = None) -> Tracks:
        first = self.cameras[0]
        first.tracks = self.tracks
        self.tracks = first.predict(dt_s)
        for other in self.cameras[1:]:
            other.elapse(first.step_s if dt_s is None else dt_s)
        return self.tracks

    def updater(self, camera: int) -> "CameraUpdater":
        return CameraUpdater(self, camera)

    def reported(self) -> Tracks:
        first = self.cameras[0]
        first.tracks = self.tracks
        reported = first.reported()
        if not self.needs_a_second_camera or len(self.cameras) < 2:
            return reported
        live = set(self.tracks.ids.tolist())
        self.detected_by = {track: cameras for track, cameras in self.detected_by.items() if track in live}
        found_by = [self.detected_by.get(int(track), frozenset()) for track in reported.ids]
        return reported.select(
            np.array([len(cameras) > 1 or not cameras <= self.needs_a_second_camera for cameras in found_by], bool)
        )


@dataclass(frozen=True)
class CameraUpdater:
    """Camera ``camera``'s update of a :class:`SharedBelief` (:class:`ptztrack.roles.Updater`): its tracker
    takes the belief as the cameras before it left it, and leaves it for the next."""

    belief: SharedBelief
    camera: int

    def wants_detections(self, step: int) -> bool:
        return self.belief.cameras[self.camera].wants_detections(step)

    def update(self, detections: Detections | None, pose, view: ImageSource, pose_sd=None) -> TrackUpdate:
        tracker = self.belief.cameras[self.camera]
        tracker.tracks = self.belief.tracks
        update = tracker.update(detections, pose, view, pose_sd)
        self.belief.tracks = update.tracks
        # Only a belief that reads them keeps them: ``reported`` prunes them to the live tracks.
        if self.belief.needs_a_second_camera:
            detected_by = self.belief.detected_by
            for track in update.track_ids.tolist():
                detected_by[track] = detected_by.get(track, frozenset()) | {self.camera}
        return update
