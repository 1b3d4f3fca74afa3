import os
from pathlib import Path

import cv2
import numpy as np
import pytest

from ptztrack.builders.episode import episode_world, run_episode
from ptztrack.cli import main
from ptztrack.cli.run import DETECTOR_MODEL_FILE
from ptztrack.config import scenario_from_dict
from ptztrack.geometry.area import bounds_m
from ptztrack.geometry.ptz import PTZCamera
from ptztrack.names import RUN_FILES, VIEW_STATES_FILE
from ptztrack.view.video import (
    FRAME_SIZE_PX,
    PANEL_SIZE_PX,
    ellipse_axes,
    episode_frames,
    image_ellipses,
    map_transform,
    view_renderer,
    write_episode_video,
)

EXCERPT = Path(__file__).parent / "data" / "pets_s2l1_excerpt"


def read_video(path):
    """All frames of a video file and its frame rate, as OpenCV reads them back."""
    capture = cv2.VideoCapture(str(path))
    assert capture.isOpened()
    frame_rate_hz = capture.get(cv2.CAP_PROP_FPS)
    frames = []
    while (frame := capture.read())[0]:
        frames.append(frame[1])
    capture.release()
    return np.stack(frames), frame_rate_hz


def test_run_out_writes_an_mp4_with_one_frame_per_step(tmp_path, capsys):
    assert main(["run", "--policy", "fix", "--detector", "ideal", "--frames", "10", "--out", str(tmp_path)]) == 0
    printed = capsys.readouterr().out
    assert "episode.mp4" in printed and str(tmp_path) in printed
    frames, frame_rate_hz = read_video(tmp_path / "episode.mp4")
    assert frames.shape == (10, FRAME_SIZE_PX[1], FRAME_SIZE_PX[0], 3)
    assert frame_rate_hz == pytest.approx(5.0)
    assert sorted(os.listdir(tmp_path)) == sorted([*RUN_FILES, VIEW_STATES_FILE, DETECTOR_MODEL_FILE])
    assert len((tmp_path / VIEW_STATES_FILE).read_text().splitlines()) == 10  # a state per step, for `ptztrack view`


def test_the_video_holds_the_drawn_frames_and_the_same_seed_gives_the_same_bytes(tmp_path):
    scenario = scenario_from_dict({"frames": 6, "detector": {"kind": "ideal"}})
    episode = run_episode(scenario, "random", 3)
    render_view = view_renderer(episode_world(scenario, 3))
    drawn = np.stack(list(episode_frames(episode, render_view, "random")))
    for name in ("a.mp4", "b.mp4"):
        write_episode_video(tmp_path / name, episode, render_view, "random")
    decoded, _ = read_video(tmp_path / "a.mp4")
    # lossy, but close to what was drawn, frame by frame
    assert np.mean(np.abs(decoded.astype(float) - drawn)) < 4.0
    assert (tmp_path / "a.mp4").read_bytes() == (tmp_path / "b.mp4").read_bytes()


def test_a_long_runs_video_shows_its_last_steps():
    scenario = scenario_from_dict({"frames": 5, "detector": {"kind": "ideal"}})
    episode = run_episode(scenario, "random", 3)
    render_view = view_renderer(episode_world(scenario, 3))
    every_step = list(episode_frames(episode, render_view, "random"))
    last_three = list(episode_frames(episode, render_view, "random", max_steps=3))
    assert len(every_step) == 5 and len(last_three) == 3
    np.testing.assert_array_equal(np.stack(last_three), np.stack(every_step[2:]))


def test_the_synthetic_view_shows_the_people_the_detector_saw():
    scenario = scenario_from_dict({"frames": 1, "detector": {"kind": "ideal", "pixel_noise_px": 0.0}})
    episode = run_episode(scenario, "fix", 0)
    view = view_renderer(episode_world(scenario, 0))(0, episode.poses[0])
    assert view.shape == (480, 640, 3)
    background = view[0, 0]
    feet_px = np.floor(episode.detections[0].feet_px).astype(int)
    assert len(feet_px) >= 5
    # just above each detected feet point stands a person, drawn darker than the background
    for u, v in feet_px:
        assert np.all(view[v - 5, u] < background)


def test_a_pets_excerpt_video_shows_the_recording_through_the_virtual_camera(tmp_path, excerpt_scenario):
    scenario = excerpt_scenario(tmp_path, **{"recording.video": str(EXCERPT / "View_001.avi")})
    episode = run_episode(scenario, "fix", 0)
    world = episode_world(scenario, 0)
    write_episode_video(tmp_path / "episode.mp4", episode, view_renderer(world), "fix")
    frames, frame_rate_hz = read_video(tmp_path / "episode.mp4")
    assert frames.shape == (15, FRAME_SIZE_PX[1], FRAME_SIZE_PX[0], 3)
    assert frame_rate_hz == pytest.approx(5.0)
    # the left panel is the 160 x 120 view upscaled 4x
    recorded = cv2.VideoCapture(str(EXCERPT / "View_001.avi")).read()[1]
    view = world.backend.virtual.render(recorded, episode.poses[0])
    expected = cv2.resize(view, PANEL_SIZE_PX, interpolation=cv2.INTER_NEAREST).astype(float)
    panel = frames[0, : PANEL_SIZE_PX[1], : PANEL_SIZE_PX[0]]
    assert np.median(np.abs(panel - expected)) < 6.0 < np.median(np.abs(panel - expected.mean()))


def test_a_failed_video_leaves_the_old_file_and_no_temporary(tmp_path):
    scenario = scenario_from_dict({"frames": 4})
    episode = run_episode(scenario, "fix", 0)
    (tmp_path / "episode.mp4").write_bytes(b"old")

    def fails_at_step_2(step, pose):
        if step == 2:
            raise OSError("camera gone")
        return np.zeros((480, 640, 3), np.uint8)

    with pytest.raises(OSError, match="camera gone"):
        write_episode_video(tmp_path / "episode.mp4", episode, fails_at_step_2)
    assert os.listdir(tmp_path) == ["episode.mp4"]
    assert (tmp_path / "episode.mp4").read_bytes() == b"old"


def test_ellipse_axes_are_twice_the_square_roots_of_the_eigenvalues():
    J = np.array([[2.0, 1.0], [0.0, 3.0]])
    covariance = J @ np.eye(2) @ J.T  # [[5, 3], [3, 9]]: eigenvalues 7 +- sqrt(13)
    half_axes, angle_deg = ellipse_axes(covariance)
    np.testing.assert_allclose(half_axes, np.sqrt(4 * (7 + np.array([1, -1]) * np.sqrt(13))))
    major = np.array([np.cos(np.deg2rad(angle_deg)), np.sin(np.deg2rad(angle_deg))])
    np.testing.assert_allclose(covariance @ major, (7 + np.sqrt(13)) * major)


def test_a_camera_looking_straight_down_scales_the_ellipse_by_focal_length_over_height():
    camera = PTZCamera((0.0, 0.0, 10.0), 640, 480, 500.0)
    pose = np.array([0.0, 90.0, 2.0])  # f = 1000 px at 10 m: 100 px per metre, image v along world -y
    rotation = np.array([[np.cos(np.pi / 6), -np.sin(np.pi / 6)], [np.sin(np.pi / 6), np.cos(np.pi / 6)]])
    covariance_m2 = rotation @ np.diag([0.2**2, 0.1**2]) @ rotation.T  # major axis 30 deg from +x towards +y
    centre_px, in_front, half_axes_px, angle_deg = image_ellipses(camera, pose, [[1.0, 2.0]], covariance_m2[None])
    np.testing.assert_allclose(centre_px, [[320 + 100, 240 - 200]])
    assert in_front.tolist() == [True]
    np.testing.assert_allclose(half_axes_px, [[2 * 0.2 * 100, 2 * 0.1 * 100]])
    # +y on the ground is -v in the image: the major axis turns to -30 deg
    assert np.mod(angle_deg[0], 180.0) == pytest.approx(150.0)


def test_the_map_shows_area_and_camera_with_y_up():
    episode = run_episode(scenario_from_dict({"frames": 2}), "fix", 0)
    transform = map_transform(episode)
    points_m = np.vstack([episode.area_polygon_m, episode.camera.centre_m[:2]])
    points_px = transform.to_px(points_m)
    assert np.all((points_px > 0) & (points_px < PANEL_SIZE_PX))
    (x0, y0), (x1, y1) = bounds_m(episode.area_polygon_m)
    low_px, high_px = transform.to_px([[x0, y0], [x1, y1]])
    assert high_px[0] > low_px[0] and high_px[1] < low_px[1]
    np.testing.assert_allclose(transform.to_m(points_px), points_m, atol=1e-9)
