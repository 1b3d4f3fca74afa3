"""The pipelined live loop on a camera of this process: pictures taken as they come, each tracked at
the time it was taken, decisions on the newest, no new target while the camera moves, and the rates
it reports."""

import threading
import time
from dataclasses import replace
from functools import partial

import numpy as np
import pytest

from ptztrack.builders.episode import episode_world, make_policy, make_tracker
from ptztrack.camera.onvif_spaces import MoveTimes
from ptztrack.camera.pose_timeline import PoseTimeline
from ptztrack.camera.stream import LatestFrame
from ptztrack.config import scenario_from_dict
from ptztrack.loop.live import run_live, run_live_network, warm_up
from ptztrack.types import Detections

PICTURE_S = 0.02


class PictureCamera:
    """A camera whose pictures come every PICTURE_S from a thread, standing at ``pose`` (or moving
    there, ``moving``); its targets are kept in ``sent``."""

    def __init__(self, world, moving: bool = False, move_times=None):
        self.frames, self.timeline, self.sent = self, PoseTimeline(move_times), []
        self.latest = LatestFrame()
        self.pose = world.grid.poses[world.start_action]
        self.moving, self.image = moving, np.zeros((world.camera.image_height_px, world.camera.image_width_px, 3))
        self._stopping = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def send(self, pose) -> bool:
        if self.sent and np.array_equal(pose, self.sent[-1]):
            return False
        self.sent.append(np.asarray(pose))
        self.timeline.sent(time.time(), pose)
        return True

    def _run(self) -> None:
        while not self._stopping.wait(PICTURE_S):
            now = time.time()
            self.timeline.sample(now, self.pose, self.moving)
            self.latest.put(self.image, now - 0.005)

    def __enter__(self):
        self._thread.start()
        return self

    def __exit__(self, *exc_info):
        self._stopping.set()
        self._thread.join()


class Nobody:
    """A detector that finds nobody, at once."""

    def detect(self, camera, step, pose, rng, believed_pose=None) -> Detections:
        return Detections.empty()


class TimedTracker:
    """The scenario's tracker, keeping the time each prediction stepped."""

    def __init__(self, tracker):
        self.tracker, self.dt_s = tracker, []

    def predict(self, dt_s=None):
        self.dt_s.append(dt_s)
        return self.tracker.predict(dt_s)

    def update(self, *arguments, **keywords):
        return self.tracker.update(*arguments, **keywords)

    def reported(self):
        return self.tracker.reported()


@pytest.fixture(scope="module")
def world():
    scenario = scenario_from_dict({"frames": 5})
    built = episode_world(scenario, 0)
    return scenario, replace(built, detector=Nobody())


def test_each_picture_is_tracked_at_its_time_and_a_pause_skips_to_the_newest_picture(world):
    """The tracker steps by the time between the pictures' captures times ``time_scale``; a decision's
    observer that blocks (a paused view) leaves the pictures of its pause unused but the one the detector
    had taken, not queued."""
    scenario, built = world
    tracker = TimedTracker(make_tracker(None, scenario, built))
    paused = []

    def observer(step, context, record):
        if step == 3:
            time.sleep(0.5)
            paused.append(time.time())

    with PictureCamera(built) as camera:
        live = run_live(built, make_policy("fix", scenario, built), tracker, camera, 12, 0.5, 0, observer)
    assert len(live.capture_time_s) == 12 and tracker.dt_s[0] is None
    np.testing.assert_allclose(tracker.dt_s[1:], 0.5 * np.diff(live.capture_time_s))
    # Four before it, and two of its first moments: the one the tracker had queued, the one the detector held.
    assert np.sum(live.capture_time_s < paused[0] - 0.1) <= 6, "pictures of the pause were used"
    rates = live.rates()
    assert rates["frames_used_per_s"] == pytest.approx(11 / (live.capture_time_s[-1] - live.capture_time_s[0]))
    assert np.all(live.decided_s[np.isfinite(live.decided_s)] >= live.capture_time_s[np.isfinite(live.decided_s)])


def test_no_new_target_goes_out_while_the_camera_moves(world):
    """A camera that never stops moving keeps the target it was first sent: the policy is given that
    one action only."""
    scenario, built = world
    policy = make_policy("random", scenario, built)
    seen = []

    def observer(step, context, record):
        seen.append(context.reachable)

    with PictureCamera(built, moving=True) as camera:
        live = run_live(built, policy, make_tracker(None, scenario, built), camera, 6, 1.0, 0, observer)
    assert all(len(reachable) == 1 and reachable[0] == built.start_action for reachable in seen)
    assert not live.sent.any() and len(camera.sent) == 1


def test_the_policy_plans_on_the_tracks_predicted_from_the_pictures_capture_to_its_decision(world):
    """``plan_ahead`` is given the belief's tracks and the scenario seconds from the capture of the picture
    decided on to the decision (the time scale's multiple of the wall seconds), and the policy what it
    returns."""
    scenario, built = world
    given, seen = [], []

    def plan_ahead(tracks, seconds):
        given.append(seconds)
        return replace(tracks, next_id=1000 + len(given))

    def observer(step, context, record):
        seen.append((context.tracks.next_id, record["decided_s"] - record["capture_time_s"]))

    with PictureCamera(built) as camera:
        tracker = make_tracker(None, scenario, built)
        run_live(
            built, make_policy("fix", scenario, built), tracker, camera, 8, 0.5, 0, observer, plan_ahead=plan_ahead
        )
    assert len(seen) == len(given) > 0
    for k, ((next_id, wall_s), seconds) in enumerate(zip(seen, given, strict=True)):
        assert next_id == 1001 + k and 0.0 <= seconds <= 0.5 * wall_s


class Slow:
    """A detector that finds nobody, in DETECTION_S."""

    def detect(self, camera, step, pose, rng, believed_pose=None) -> Detections:
        time.sleep(DETECTION_S)
        return Detections.empty()


DETECTION_S = 0.06


def test_the_detector_rests_as_long_as_it_detected_but_takes_the_first_picture_at_rest_after_a_move(world):
    """With a detection three pictures long, a camera at rest has its detector take about one picture in
    four (it rests as long as it detected; the pictures of its rest are dropped, and each it takes is the
    newest), each followed by a decision, while the camera stays where it is; the first picture at rest
    after a move is taken at once."""
    scenario, built = world
    slow = replace(built, detector=Slow())
    with PictureCamera(slow) as camera:
        policy, tracker = make_policy("fix", scenario, slow), make_tracker(None, scenario, slow)
        live = run_live(slow, policy, tracker, camera, 12, 1.0, 0)
    assert live.detected.all() and np.all(np.isfinite(live.decided_s))
    taken_apart_s = np.diff(live.picked_s)
    assert np.all(taken_apart_s >= 2 * DETECTION_S - PICTURE_S) and np.median(taken_apart_s) < 2 * DETECTION_S + 0.04
    assert live.frames_received > 2.5 * len(live.capture_time_s)
    with PictureCamera(slow, moving=True) as camera:
        lands = LandsAtThirdDetection(camera)
        policy, tracker = make_policy("random", scenario, slow), make_tracker(None, scenario, slow)
        live = run_live(replace(slow, detector=lands), policy, tracker, camera, 30, 1.0, 0)
    # It would rest for LANDING_DETECTION_S after its third detection: the first picture at rest is taken at once.
    first_at_rest = np.flatnonzero(live.detected & (live.capture_time_s > lands.landed_s))[0]
    assert live.picked_s[first_at_rest] - lands.landed_s < 0.5 * LANDING_DETECTION_S


LANDING_DETECTION_S = 0.1


class LandsAtThirdDetection:
    """A detector that finds nobody, in LANDING_DETECTION_S, and stops ``camera`` as its third detection ends."""

    def __init__(self, camera: PictureCamera):
        self.camera, self.detections, self.landed_s = camera, 0, np.inf

    def detect(self, camera, step, pose, rng, believed_pose=None) -> Detections:
        time.sleep(LANDING_DETECTION_S)
        self.detections += 1
        if self.detections == 3:
            self.camera.moving, self.landed_s = False, time.time()
        return Detections.empty()


def _keep_reachable(seen: list, step, context, record) -> None:
    seen.append(context.reachable)


def test_a_camera_that_stands_still_before_its_move_could_have_landed_is_given_its_target_only(world):
    """The policy chooses anew only on a picture taken at rest where the camera was sent: with a move
    that takes an hour, after the first move the policy is given that move's target alone; with one that
    lands at once, it chooses among every reachable action at each picture."""
    scenario, built = world
    for slope, choices in ((1e3, 1), (0.0, 12)):
        policy = make_policy("random", scenario, built)
        seen: list[np.ndarray] = []
        with PictureCamera(built, move_times=MoveTimes((0.0, slope), (0.0, slope), (0.0, slope))) as camera:
            observer = partial(_keep_reachable, seen)
            run_live(built, policy, make_tracker(None, scenario, built), camera, 12, 1.0, 0, observer)
        given_a_choice = [len(reachable) > 1 for reachable in seen]
        assert sum(given_a_choice) == choices and given_a_choice[0]
        if choices == 1:
            assert len(camera.sent) == 2 and all(
                reachable[0] == built.grid.nearest(camera.sent[1]) for reachable in seen[1:]
            )


def test_warming_up_leaves_the_policy_and_the_tracker_as_they_were(world):
    scenario, built = world
    policy, tracker = make_policy("smpl", scenario, built), make_tracker(None, scenario, built)
    warm_up(built, policy, tracker)
    assert len(tracker.tracks) == 0 and policy.last_terms is None


class RecordingBelief:
    """A network's belief over the scenario's tracker: the time of each prediction and which camera's
    updater took each picture."""

    def __init__(self, tracker):
        self.tracker, self.dt_s, self.updaters = tracker, [], []

    def predict(self, dt_s=None):
        self.dt_s.append(dt_s)
        return self.tracker.predict(dt_s)

    def updater(self, camera):
        self.updaters.append(camera)
        return self.tracker

    def reported(self):
        return self.tracker.reported()


class EveryCameraLast:
    """A network policy that sends every camera to the last action it may reach, keeping each decision's
    contexts."""

    def __init__(self):
        self.contexts = []

    def choose(self, contexts):
        self.contexts.append(contexts)
        return [int(context.reachable[-1]) for context in contexts]


def test_a_network_updates_one_belief_with_every_cameras_pictures_and_decides_for_all(world):
    """Two cameras, one moving all the time: each picture, whichever camera took it, updates the one
    belief through its camera's updater, predicted forward only; every decision has both cameras'
    contexts, the moving camera's with its target alone (the still one's too until a picture of it is in the
    belief), and only the still camera is sent anywhere new."""
    scenario, built = world
    belief, policy = RecordingBelief(make_tracker(None, scenario, built)), EveryCameraLast()
    with PictureCamera(built, moving=True) as moving, PictureCamera(built) as still:
        lives = run_live_network([built, built], policy, belief, [moving, still], 16, 1.0, 0)
    pictures = [len(live.capture_time_s) for live in lives]
    assert sum(pictures) == 16 and min(pictures) > 0
    assert sorted(belief.updaters) == [0] * pictures[0] + [1] * pictures[1]
    assert belief.dt_s[0] is None and min(belief.dt_s[1:]) >= 0.0
    assert policy.contexts and all(len(contexts) == 2 for contexts in policy.contexts)
    assert all(len(contexts[0].reachable) == 1 for contexts in policy.contexts)
    assert any(len(contexts[1].reachable) > 1 for contexts in policy.contexts)
    assert len(moving.sent) == 1 and len(still.sent) > 1
