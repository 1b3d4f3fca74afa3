"""`ptztrack live --pose registered` against the virtual ONVIF camera on 127.0.0.1, the camera reporting
no positions and refusing AbsoluteMove: the sweep's reference index, a live run placed by its pictures
and moved by RelativeMoves, a picture that does not register, and ContinuousMoves where RelativeMove is
missing."""

import logging
import time
from dataclasses import dataclass

import cv2
import numpy as np
import pytest

from ptztrack.builders.episode import episode_world
from ptztrack.builders.live import live_as_episode, live_world, run_live_episode
from ptztrack.builders.live_registered import registered_camera
from ptztrack.builders.recording import pets_scenario
from ptztrack.builders.virtual_camera import RecordingFeed, virtual_calibration, virtual_onvif_camera
from ptztrack.camera.onvif_client import CameraAddress, ONVIFClient, PTZMoves
from ptztrack.cli import main
from ptztrack.config import CameraCalibrationFile, write_camera_calibration
from ptztrack.evaluate.metrics import episode_metrics

pytest.importorskip("ipycam", reason="the virtual ONVIF camera needs ipycam (pip install --no-deps ipycam==1.3.0)")
# The live runs go one at a time (one xdist worker): two live loops at once would each be a machine busier
# than the one their bounds are for (the other worker's tests are the other load they share the cores with).
pytestmark = [pytest.mark.onvif, pytest.mark.xdist_group("live-loop")]

HALF_PACE = 0.5
# Within this of the truth: a registered pose (degrees, and a fraction of the zoom).
POSE_DEG, ZOOM_FRACTION = 0.5, 0.02


def _narrow_scenario(zooms=(1.0, 2.0)):
    """PETS with HOG and an action grid a few degrees around its start, so that the sweep is short."""
    scenario = pets_scenario("hog")
    actions = scenario.actions.model_copy(
        update={
            "pan_deg": scenario.actions.pan_deg.model_copy(update={"start": -4.0, "stop": 4.0, "count": 3}),
            "tilt_deg": scenario.actions.tilt_deg.model_copy(update={"start": -3.0, "stop": 3.0, "count": 3}),
            "zoom": zooms,
        }
    )
    return scenario.model_copy(update={"actions": actions})


@dataclass
class _Camera:
    """A virtual camera over ``scenario``'s recording without positions and AbsoluteMove, with a ground preset
    where it starts, its calibration (the virtual one, positions relative to that preset) and a count of
    the SOAP operations it answered."""

    camera: object
    feed: RecordingFeed
    calibration: CameraCalibrationFile
    operations: dict

    @property
    def address(self) -> CameraAddress:
        return CameraAddress("127.0.0.1", self.camera.onvif_port)

    def true_pose(self, time_s: float, within_s: float = 0.15):
        """The pose its pictures showed around epoch ``time_s``, None unless it stood still within ``within_s``."""
        rows = self.feed.rows()
        near = rows[np.abs(rows[:, 0] - time_s) <= within_s, 2:5]
        return near[0] if len(near) and np.ptp(near, axis=0).max() == 0 else None


def _started(scenario, feed: RecordingFeed | None = None) -> _Camera:
    camera, feed = virtual_onvif_camera(scenario, HALF_PACE, 0, feed=feed, positions=False, absolute_moves=False)
    camera.start()
    operations: dict[str, int] = {}
    # The camera's SOAP operations, counted as they are answered.
    soap = camera._served.soap
    for key, operation in list(soap.operations.items()):

        def counted(request, operation=operation, name=key[1]):
            operations[name] = operations.get(name, 0) + 1
            return operation(request)

        soap.operations[key] = counted
    client = ONVIFClient(CameraAddress("127.0.0.1", camera.onvif_port))
    client.connect()
    token = client.set_preset("ground")
    client.close()
    start = camera.start_pose
    fields = virtual_calibration().model_dump()
    # Without positions the ground preset stands at normalised 0: the ends are the world degrees a relative
    # move of -1 and +1 from there reaches (the virtual camera's 90 and 45 degrees a unit).
    fields.update(
        positions=False,
        pan_deg=(start[0] - 90.0, start[0] + 90.0),
        tilt_deg=(start[1] + 45.0, start[1] - 45.0),
        ground_view={"preset": token, "pan_deg": start[0], "tilt_deg": start[1]},
    )
    return _Camera(camera, feed, CameraCalibrationFile.model_validate(fields), operations)


def _connect(address: CameraAddress):
    def connect() -> ONVIFClient:
        client = ONVIFClient(address)
        client.connect()
        return client

    return connect


def _rest_poses(feed: RecordingFeed) -> np.ndarray:
    """(R, 3) the poses the camera stood still at for at least 5 pictures."""
    poses = feed.rows()[:, 2:5]
    runs = [k for k in range(len(poses) - 4) if np.ptp(poses[k : k + 5], axis=0).max() == 0]
    return np.unique(poses[runs], axis=0)


def _off(poses, truth) -> np.ndarray:
    """(N,) how far each pose (N, 3) is from the nearest of ``truth`` (R, 3), in units of the tolerances."""
    poses, truth = np.asarray(poses)[:, None, :], np.asarray(truth)[None, :, :]
    deg = np.abs(poses[..., :2] - truth[..., :2]).max(axis=-1) / POSE_DEG
    zoom = np.abs(poses[..., 2] - truth[..., 2]) / (ZOOM_FRACTION * truth[..., 2])
    return np.maximum(deg, zoom).min(axis=1)


@pytest.mark.slow
def test_the_sweep_builds_an_index_whose_poses_are_the_cameras_true_poses():
    """The camera swept over a narrow action grid by RelativeMoves: every view of the index lies within
    half a degree and 2 % of zoom of a pose the camera stood still at, without AbsoluteMove or GetStatus."""
    scenario = _narrow_scenario()
    served = _started(scenario)
    camera = registered_camera(
        _connect(served.address), served.calibration, live_world(scenario, served.calibration, 0), "tcp"
    )
    try:
        camera.start()
    finally:
        camera.close()
        served.camera.stop()
    index = camera.registration.index
    assert len(index.poses) >= 10
    assert np.all(_off(index.poses, _rest_poses(served.feed)) <= 1.0), index.poses
    assert served.operations.get("RelativeMove", 0) >= len(index.poses) - 1
    assert "AbsoluteMove" not in served.operations and "GetStatus" not in served.operations


class _BlankingFeed(RecordingFeed):
    """The recording's pictures, or a uniform grey one until epoch ``blank_until_s``."""

    blank_until_s: float = 0.0

    def render(self, pose, elapsed_s: float) -> np.ndarray:
        image = super().render(pose, elapsed_s)
        return np.full_like(image, 128) if time.time() < self.blank_until_s else image


# Enough pictures that 20 of them, the accuracy's sample, are taken with the camera at rest however busy the
# machine (which pictures are depends on the policy's moves and the machine's pace, not on the registration).
PICTURES = 60


@pytest.mark.slow
def test_a_live_run_is_placed_by_its_pictures_moved_by_relative_moves_and_skips_a_blank_picture(caplog):
    """A live smpl run with --pose registered: most pictures used are placed within half a degree and 2 %
    of zoom of where the camera stood, the camera is moved by RelativeMoves only (no AbsoluteMove, no
    GetStatus), and half a second of uniform pictures costs steps (decided on the prediction, no picture
    placed or detected in), with a log line for it."""
    scenario = _narrow_scenario()
    feed = _BlankingFeed(episode_world(scenario, 0), 1.0 / scenario.frame_rate_hz, HALF_PACE)
    served = _started(scenario, feed)
    blanked: list[float] = []

    def observe(worlds, policy):
        def blank_once(step, context, row) -> None:
            if step >= 15 and not blanked:
                blanked.append(time.time())
                feed.blank_until_s = blanked[0] + 0.5

        return blank_once

    try:
        with caplog.at_level(logging.WARNING, logger="ptztrack.loop.live"):
            (world,), (live,) = run_live_episode(
                scenario, [served.calibration], [served.address], "smpl", PICTURES, HALF_PACE, 0,
                keep_images=True, observe=observe, pose_source="registered",
            )  # fmt: skip
    finally:
        served.camera.stop()
    assert len(live.capture_time_s) == PICTURES and blanked
    placed = np.all(np.isfinite(live.poses), axis=1)
    times_s = live.capture_time_s
    truths = [served.true_pose(time_s) if here else None for time_s, here in zip(times_s, placed, strict=True)]
    at_rest = np.array([truth is not None for truth in truths])
    errors = np.array(
        [_off(pose[None], truth[None])[0] for pose, truth in zip(live.poses, truths, strict=True) if truth is not None]
    )
    assert at_rest.sum() >= 20 and np.mean(errors <= 1.0) >= 0.9, errors
    assert served.operations.get("RelativeMove", 0) > 0
    assert "AbsoluteMove" not in served.operations and "GetStatus" not in served.operations
    pictures = [cv2.imdecode(np.frombuffer(jpeg, np.uint8), cv2.IMREAD_GRAYSCALE) for jpeg in live.images]
    uniform = np.array([picture.std() < 2.0 for picture in pictures])
    # A uniform picture costs its step (a decision on the prediction), and is never placed or detected in.
    assert uniform.any() and not np.any(uniform & placed), "a uniform picture was used"
    assert all(len(live.detections[step]) == 0 for step in np.flatnonzero(uniform))
    # Such steps are scored as the others: the camera's commanded pose stands in for the unknown one.
    looked = episode_metrics(live_as_episode(world, live))
    assert looked["detections"] == sum(len(found) for found in live.detections)
    lines = [record for record in caplog.records if "did not register" in record.getMessage()]
    # The blank pictures' line, or the line less than a second before them that held it back (a line a
    # second at most).
    assert any(blanked[0] - 1.0 <= record.created <= blanked[0] + 1.5 for record in lines)
    assert np.all(np.diff([record.created for record in lines]) >= 1.0), "more than a line a second"


@pytest.mark.slow
def test_a_camera_without_relative_moves_is_swept_and_moved_by_timed_continuous_moves(monkeypatch):
    """A node that offers ContinuousMove only: the sweep and a target sent after it go by ContinuousMoves
    timed by the move-time model, each followed by Stop, and land within half a degree of their poses."""
    monkeypatch.setattr(ONVIFClient, "moves", lambda self: PTZMoves(absolute=False, relative=False, continuous=True))
    scenario = _narrow_scenario(zooms=(1.0, 1.4))
    served = _started(scenario)
    world = live_world(scenario, served.calibration, 0)
    camera = registered_camera(_connect(served.address), served.calibration, world, "tcp")
    target = world.grid.poses[world.start_action] + [3.0, -2.0, 0.0]
    try:
        camera.start()
        camera.send(target)
        deadline_s = time.time() + 10.0
        while time.time() < deadline_s and not (camera.timeline.settled(time.time() - 0.2)):
            time.sleep(0.1)
        registered = camera.timeline.current()
        truth = served.true_pose(time.time() - 0.2)
    finally:
        camera.close()
        served.camera.stop()
    assert np.all(_off(camera.registration.index.poses, _rest_poses(served.feed)) <= 1.0)
    assert served.operations.get("ContinuousMove", 0) >= 5 and served.operations.get("Stop", 0) >= 5
    assert "RelativeMove" not in served.operations
    assert _off(registered[None], truth[None])[0] <= 1.0 and _off(truth[None], target[None])[0] <= 1.0


def test_a_calibration_without_positions_is_refused_for_status_poses_before_connecting(tmp_path, capsys):
    fields = virtual_calibration().model_dump()
    fields.update(positions=False, ground_view={"preset": "1", "pan_deg": 57.0, "tilt_deg": 17.0})
    path = tmp_path / "camera.yaml"
    write_camera_calibration(path, CameraCalibrationFile.model_validate(fields))
    # Nobody listens at port 9: a connection would fail with another line.
    status = main(["live", "--camera", "onvif://127.0.0.1:9", "--calibration", str(path), "--steps", "3"])
    error = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and error == ["ptztrack: error: this camera reports no positions: use --pose registered"]
