from pathlib import Path
from types import SimpleNamespace

import cv2
import numpy as np
import pytest

from ptztrack.builders.live import live_world, offline_counterpart
from ptztrack.builders.virtual_camera import virtual_calibration
from ptztrack.builders.world import build_world
from ptztrack.camera.virtual import virtual_ptz
from ptztrack.detect import hog
from ptztrack.detect.hog import (
    SCALE_TOLERANCE,
    GroundSearch,
    HogPeopleDetector,
    clip_boxes,
    feet_and_height_px,
    group_rectangles,
    level_bands,
    person_rows_px,
    pyramid,
    scan,
)
from ptztrack.geometry.area import inside
from ptztrack.geometry.calibration import load_pinhole
from ptztrack.geometry.ptz import PTZCamera, apply_homography, ground_to_image, pixels_to_ground, project_people
from ptztrack.scene.pets import DatasetError, RecordedVideo, load_mot_ground_truth

EXCERPT = Path(__file__).parent / "data" / "pets_s2l1_excerpt"


def test_feet_sit_one_eighth_of_the_box_above_its_bottom_and_the_person_is_three_quarters_of_it():
    feet, height = feet_and_height_px([[10.0, 20.0, 16.0, 32.0]])
    np.testing.assert_allclose(feet, [[18.0, 48.0]])
    np.testing.assert_allclose(height, [24.0])


def test_hog_finds_the_people_of_a_zoomed_virtual_view_at_their_annotated_feet(excerpt_frames):
    virtual, whole_frame = virtual_ptz(load_pinhole(EXCERPT / "pinhole.json"))
    pose = whole_frame * [1, 1, 2]
    frame = 10
    view = virtual.render(excerpt_frames[frame], pose)
    boxes, scores = HogPeopleDetector().boxes(view)
    assert len(boxes) >= 1 and np.all(scores > 0)
    truth = load_mot_ground_truth(EXCERPT / "gt_mot15.txt")
    annotated = apply_homography(ground_to_image(virtual.camera, pose), truth.ground_m[truth.frame == frame])
    feet, _ = feet_and_height_px(boxes)
    nearest_px = np.linalg.norm(feet[:, None] - annotated[None], axis=-1).min(axis=1)
    assert np.sum(nearest_px < 4.0) >= 1


def test_a_luma_detector_finds_in_a_picture_what_it_finds_in_its_grey_copy_and_the_colour_one_does_not(
    excerpt_frames,
):
    virtual, whole_frame = virtual_ptz(load_pinhole(EXCERPT / "pinhole.json"))
    view = virtual.render(excerpt_frames[10], whole_frame * [1, 1, 2])
    grey = cv2.cvtColor(cv2.cvtColor(view, cv2.COLOR_BGR2GRAY), cv2.COLOR_GRAY2BGR)
    found = {luma: [HogPeopleDetector(luma=luma).boxes(image) for image in (view, grey)] for luma in (False, True)}
    (boxes, scores), (grey_boxes, grey_scores) = found[True]
    assert len(boxes) >= 1
    np.testing.assert_array_equal(boxes, grey_boxes)
    np.testing.assert_array_equal(scores, grey_scores)
    (colour_boxes, _), (colour_grey_boxes, _) = found[False]
    assert colour_boxes.shape != colour_grey_boxes.shape or not np.array_equal(colour_boxes, colour_grey_boxes)


def test_hog_finds_nobody_in_an_empty_image():
    boxes, scores = HogPeopleDetector().boxes(np.full((120, 160, 3), 128, np.uint8))
    assert boxes.shape == (0, 4) and scores.shape == (0,)


def test_recorded_video_reads_forwards_and_reopens_to_go_back(excerpt_frames):
    frames = excerpt_frames  # read_video's
    video = RecordedVideo(EXCERPT / "View_001.avi", (768, 576))
    np.testing.assert_array_equal(video.frame(4), frames[4])
    np.testing.assert_array_equal(video.frame(10), frames[10])
    np.testing.assert_array_equal(video.frame(2), frames[2])
    with pytest.raises(DatasetError, match="ends before frame 40"):
        video.frame(40)
    with pytest.raises(DatasetError, match="frames are 768x576 px, expected 640x480"):
        RecordedVideo(EXCERPT / "View_001.avi", (640, 480)).frame(0)


@pytest.fixture(scope="module")
def hog_world(tmp_path_factory, excerpt_scenario):
    """The excerpt seen by the 160 x 120 virtual camera of the PETS protocol, with the ground search."""
    scenario = excerpt_scenario(
        tmp_path_factory.mktemp("hog"), **{"detector.kind": "hog", "recording.video": str(EXCERPT / "View_001.avi")}
    )
    return build_world(scenario, np.random.default_rng(0))


def whole_frame_at_zoom(world, zoom_index: int) -> np.ndarray:
    """The pose of the grid that views the whole recorded frame, at the grid's ``zoom_index``-th zoom."""
    pan, tilt, _ = world.grid.axis_indices[world.start_action]
    return world.grid.poses[int(world.grid.index(pan, tilt, zoom_index))]


def every_window(view_size_px=(160, 120)) -> tuple[np.ndarray, np.ndarray]:
    """Per-row person heights that let every window of the pyramid be scanned."""
    return np.zeros(view_size_px[1]), np.full(view_size_px[1], np.inf)


@pytest.mark.parametrize(("step", "zoom_index"), [(0, 0), (14, 1)])
def test_scanning_every_window_is_opencvs_detect_multiscale_hit_for_hit(hog_world, step, zoom_index):
    pose = whole_frame_at_zoom(hog_world, zoom_index)
    enlarged = cv2.resize(hog_world.backend.image(step, pose), None, fx=6.0, fy=6.0, interpolation=cv2.INTER_LINEAR)
    hog = cv2.HOGDescriptor()
    hog.setSVMDetector(cv2.HOGDescriptor.getDefaultPeopleDetector())
    found, weights = hog.detectMultiScale(enlarged, hitThreshold=0.0, winStride=(8, 8), padding=(8, 8), scale=1.05)
    bands = level_bands(*every_window(), (960, 720), 6.0, SCALE_TOLERANCE)
    hits = scan(hog, enlarged, bands, 0.0, interpolation=cv2.INTER_LINEAR_EXACT)
    boxes, scores = clip_boxes(*group_rectangles(*hits), (960, 720))
    assert len(found) >= 1
    expected = np.asarray(found, dtype=float).reshape(-1, 4)
    order, expected_order = np.lexsort(boxes.T), np.lexsort(expected.T)
    np.testing.assert_array_equal(boxes[order], expected[expected_order])
    np.testing.assert_allclose(scores[order], np.ravel(weights)[expected_order], rtol=1e-12)


def test_the_ground_search_scans_the_full_searchs_windows_in_its_bands_and_no_others(hog_world):
    hog = hog_world.detector._hog
    for step, pose in [(7, whole_frame_at_zoom(hog_world, 0)), (14, whole_frame_at_zoom(hog_world, 3) - [0, 10, 0])]:
        enlarged = cv2.resize(hog_world.backend.image(step, pose), None, fx=6.0, fy=6.0)
        # A hit threshold of -1.5 keeps most windows, whether they hold a person or not.
        everywhere, everywhere_scores = scan(hog, enlarged, level_bands(*every_window(), (960, 720), 6.0, 1.3), -1.5)
        bands = hog_world.detector.search.bands(pose, 6.0, (960, 720))
        searched, scores = scan(hog, enlarged, bands, -1.5)
        in_bands = np.zeros(len(everywhere), dtype=bool)
        for band in bands:
            tops_px = np.rint(np.arange(band.first_top_px, band.last_top_px + 1, 8) * band.scale)
            in_bands |= (everywhere[:, 2] == np.rint(64 * band.scale)) & np.isin(everywhere[:, 1], tops_px)
        assert 0 < in_bands.sum() < len(everywhere)
        expected = dict(zip(map(tuple, everywhere[in_bands].tolist()), everywhere_scores[in_bands], strict=True))
        assert dict(zip(map(tuple, searched.tolist()), scores, strict=True)) == expected


@pytest.mark.slow
def test_the_ground_search_finds_as_many_people_at_their_size_as_the_full_search(hog_world):
    backend, full = hog_world.backend, HogPeopleDetector()
    found_full = found_ground = 0
    for step, zoom_index in [(0, 0), (7, 0), (14, 0), (0, 1), (7, 1), (14, 2)]:
        pose = whole_frame_at_zoom(hog_world, zoom_index)
        view, people = backend.image(step, pose), backend.people(step, pose)
        visible = people.in_view & (people.hidden <= 0.25)
        found = [feet_and_height_px(detector.boxes(view, pose)[0]) for detector in (full, hog_world.detector)]
        near = []
        for feet_px, height_px in found:
            distance = np.linalg.norm(people.feet_px[visible, None] - feet_px[None], axis=-1)
            ratio = height_px[None] / people.height_px[visible, None]
            sized = (distance <= 0.3 * people.height_px[visible, None]) & (ratio < 1.5) & (ratio > 1 / 1.5)
            near.append(sized.any(axis=1))
        found_full += near[0].sum()
        found_ground += near[1].sum()
    # Levels resized from the view move windows near the threshold either way: people are counted, not matched.
    assert found_ground >= found_full >= 8


def test_person_rows_follow_the_homology_of_a_level_camera():
    # Looking level from 5 m up, the ground of row v lies at depth f H / (v - cy) along the axis, where a
    # person h tall is f h / depth = h (v - cy) / H px tall, in every column.
    camera = PTZCamera((0.0, 0.0, 5.0), 160, 120, 100.0)
    everywhere = np.array([[-1e3, -1e3], [1e3, -1e3], [1e3, 1e3], [-1e3, 1e3]])
    shortest, tallest = person_rows_px(camera, [0.0, 0.0, 1.0], everywhere, (1.5, 2.0))
    below = np.arange(120) + 0.5 > 60
    np.testing.assert_allclose(shortest[below], 1.5 * (np.arange(120)[below] + 0.5 - 60) / 5.0, rtol=1e-9)
    np.testing.assert_allclose(tallest[below], 2.0 * (np.arange(120)[below] + 0.5 - 60) / 5.0, rtol=1e-9)
    assert np.all(np.isnan(shortest[~below])) and np.all(np.isnan(tallest[~below]))
    # Only ground 10 to 20 m ahead is walkable: rows 60 + 100 x 5 / 20 = 85 to 60 + 100 x 5 / 10 = 110.
    band = np.array([[-1e3, 10.0], [1e3, 10.0], [1e3, 20.0], [-1e3, 20.0]])
    shortest, _ = person_rows_px(camera, [0.0, 0.0, 1.0], band, (1.5, 2.0))
    np.testing.assert_array_equal(np.flatnonzero(np.isfinite(shortest)), np.arange(85, 110))


def test_person_rows_bound_every_projected_person_at_a_tilted_zoomed_pose(hog_world):
    camera, area = hog_world.camera, hog_world.area_polygon_m
    pose = whole_frame_at_zoom(hog_world, 2) + [4.0, -3.0, 0.0]
    shortest, tallest = person_rows_px(camera, pose, area, (1.5, 2.0))
    u, v = np.meshgrid(np.linspace(0, 160, 9), np.arange(120) + 0.5)
    feet_px = np.c_[u.ravel(), v.ravel()]
    ground_m = pixels_to_ground(camera, pose, feet_px)
    walkable = np.isfinite(ground_m[:, 0])
    walkable[walkable] = inside(area, ground_m[walkable])
    rows = v.ravel()[walkable].astype(int)
    for height_m in (1.5, 1.75, 2.0):
        projected = project_people(camera, pose, ground_m[walkable], height_m, 0.5)
        np.testing.assert_allclose(projected.feet_px, feet_px[walkable], atol=1e-6)
        assert np.all(shortest[rows] <= projected.height_px + 1e-9)
        assert np.all(projected.height_px <= tallest[rows] + 1e-9)
    assert np.isfinite(shortest).sum() > 60


def test_level_bands_scan_only_windows_of_plausible_people():
    rows = np.arange(120) + 0.5
    shortest = np.where(rows > 40, 0.25 * (rows - 30), np.nan)
    tallest = 4 / 3 * shortest
    everything = level_bands(*every_window(), (960, 720), 6.0, 1.3)
    # 1.05^35 = 5.52 is the last scale at which 720 px rows hold the 128 px window.
    assert len(everything) == len(pyramid((960, 720))) == 36
    assert all(band.first_top_px == -8 for band in everything)
    assert level_bands(np.full(120, np.nan), np.full(120, np.nan), (960, 720), 6.0, 1.3) == []
    bands = level_bands(shortest, tallest, (960, 720), 6.0, 1.3)
    assert 0 < len(bands) < len(everything)
    for band in bands:
        tops = np.arange(band.first_top_px, band.last_top_px + 1, 8)
        box_height = np.rint(128 * band.scale)
        feet_row = np.floor((np.rint(tops * band.scale) + 7 / 8 * box_height) / 6.0).astype(int)
        person_px = 0.75 * box_height / 6.0
        assert np.all(shortest[feet_row] <= 1.3 * person_px) and np.all(person_px <= 1.3 * tallest[feet_row])


def test_grouping_agrees_with_opencvs_cascade_grouping():
    rng = np.random.default_rng(4)
    centres = rng.uniform(100, 800, (12, 2))
    sizes = rng.uniform(60, 200, 12)
    boxes = []
    for (x, y), size, copies in zip(centres, sizes, rng.integers(1, 7, 12), strict=True):
        jitter = rng.normal(0, 0.04 * size, (copies, 3))
        height = size * (1 + jitter[:, 2] / size)
        boxes += [np.c_[x + jitter[:, 0] - height / 4, y + jitter[:, 1] - height / 2, height / 2, height]]
    boxes = np.rint(np.concatenate(boxes))
    scores = rng.uniform(0, 3, len(boxes))
    grouped, best = group_rectangles(boxes, scores)
    expected, counts = cv2.groupRectangles(boxes.astype(int).tolist(), 2, 0.2)
    assert len(grouped) == len(expected) > 0
    # OpenCV's cascade version averages in single precision: a box may round 1 px apart.
    np.testing.assert_allclose(grouped[np.lexsort(grouped.T)], expected[np.lexsort(expected.T)], atol=1)
    assert np.all(np.isin(best, scores))


def test_a_ground_search_refuses_what_it_cannot_use(hog_world):
    with pytest.raises(ValueError, match="person_heights_m must be"):
        GroundSearch(hog_world.camera, hog_world.area_polygon_m, (2.0, 1.5))
    with pytest.raises(ValueError, match="tolerance must be at least 1"):
        GroundSearch(hog_world.camera, hog_world.area_polygon_m, tolerance=0.9)
    detector = hog_world.detector
    with pytest.raises(ValueError, match="pose must be"):
        detector.search.bands([np.nan, 0.0, 1.0], 6.0, (960, 720))
    view = np.zeros((120, 160, 3), np.uint8)
    with pytest.raises(ValueError, match="needs the pose the image was taken at"):
        detector.boxes(view)
    with pytest.raises(ValueError, match="the image is 320x240 px, the search's camera 160x120 px"):
        detector.boxes(np.zeros((240, 320, 3), np.uint8), whole_frame_at_zoom(hog_world, 0))


class CountingDetector(HogPeopleDetector):
    """The HOG detector, counting the views it searches."""

    searched = 0

    def boxes(self, image, pose=None):
        self.searched += 1
        return super().boxes(image, pose)


def test_a_view_seen_before_gives_the_boxes_found_then_without_searching_again(hog_world, monkeypatch):
    monkeypatch.setattr("ptztrack.detect.hog._BOXES_SEEN", {})
    backend, search = hog_world.backend, hog_world.detector.search
    pose = whole_frame_at_zoom(hog_world, 0)
    first, second = CountingDetector(search=search), CountingDetector(search=search)
    found = first.detect(backend, 3, pose, np.random.default_rng(0))
    again = second.detect(backend, 3, pose, np.random.default_rng(1))
    assert (first.searched, second.searched) == (1, 0) and len(found) >= 1
    np.testing.assert_array_equal(again.feet_px, found.feet_px)
    np.testing.assert_array_equal(again.score, found.score)
    # Another image, another pose or other settings are searched.
    second.detect(backend, 4, pose, np.random.default_rng(0))
    second.detect(backend, 3, pose + [2.0, 0.0, 0.0], np.random.default_rng(0))
    other = CountingDetector(nms_iou=0.3, search=search)
    other.detect(backend, 3, pose, np.random.default_rng(0))
    assert (second.searched, other.searched) == (2, 1)


def test_a_live_worlds_hog_searches_every_picture_and_keeps_no_memo_of_them(
    hog_world, tmp_path, excerpt_scenario, monkeypatch
):
    """A camera's pictures never repeat: a live run's detector finds in a picture seen again what it found
    the first time, by searching it again, and leaves the memo of views empty however long it runs."""
    monkeypatch.setattr("ptztrack.detect.hog._BOXES_SEEN", {})
    scenario = excerpt_scenario(tmp_path, **{"detector.kind": "hog", "recording.video": str(EXCERPT / "View_001.avi")})
    live = live_world(scenario, virtual_calibration(), seed=0).detector
    assert not live.remember_views
    detector = CountingDetector(search=live.search, luma=live.luma, remember_views=live.remember_views)
    pose = whole_frame_at_zoom(hog_world, 0)
    found = detector.detect(hog_world.backend, 3, pose, np.random.default_rng(0))
    again = detector.detect(hog_world.backend, 3, pose, np.random.default_rng(0))
    assert detector.searched == 2 and len(found) >= 1
    np.testing.assert_array_equal(again.feet_px, found.feet_px)
    assert hog._BOXES_SEEN == {}


def test_scanning_the_levels_on_threads_finds_the_same_windows(hog_world):
    pose = whole_frame_at_zoom(hog_world, 1)
    enlarged = cv2.resize(hog_world.backend.image(5, pose), None, fx=6.0, fy=6.0)
    bands = hog_world.detector.search.bands(pose, 6.0, (960, 720))
    alone = scan(hog_world.detector._hog, enlarged, bands, -1.0)
    threaded = scan(hog_world.detector._hog, enlarged, bands, -1.0, threads=3)
    assert len(alone[0]) > 0
    np.testing.assert_array_equal(threaded[0], alone[0])
    np.testing.assert_array_equal(threaded[1], alone[1])


def test_the_search_is_planned_at_the_believed_pose_not_at_the_pose_the_camera_took(hog_world, monkeypatch):
    """The camera is where it was told to be (the view holds people), but the system believes it is
    looking 40 degrees off in tilt, where no walkable ground is in view: a search planned there scans
    nothing and finds nobody."""
    monkeypatch.setattr("ptztrack.detect.hog._BOXES_SEEN", {})
    backend, detector = hog_world.backend, hog_world.detector
    pose = whole_frame_at_zoom(hog_world, 0)
    skyward = pose - [0.0, 40.0, 0.0]
    assert detector.search.bands(skyward, 6.0, (960, 720)) == []
    found = detector.detect(backend, 3, pose, np.random.default_rng(0))
    believed_sky = detector.detect(backend, 3, pose, np.random.default_rng(0), believed_pose=skyward)
    believed_true = detector.detect(backend, 3, pose, np.random.default_rng(0), believed_pose=pose)
    assert len(found) >= 1 and len(believed_sky) == 0
    np.testing.assert_array_equal(believed_true.feet_px, found.feet_px)


@pytest.mark.parametrize(("hog_luma", "reads_luma"), [(None, True), (False, False), (True, True)])
def test_a_live_camera_and_its_offline_counterpart_read_the_luma_unless_the_scenario_says_colour(
    tmp_path, excerpt_scenario, hog_luma, reads_luma
):
    scenario = excerpt_scenario(
        tmp_path,
        **{"detector.kind": "hog", "detector.hog_luma": hog_luma, "recording.video": str(EXCERPT / "View_001.avi")},
    )
    assert build_world(scenario, np.random.default_rng(0)).detector.luma is bool(hog_luma)
    world = live_world(scenario, virtual_calibration(), 0)
    assert world.detector.luma is reads_luma
    # Pictures captured 1 s and 2 s after the recording's first shown step, shown at steps 3 and 7.
    truth_log = np.array([[100.0, 3, 0, 0, 1], [101.5, 7, 0, 0, 1]])
    live = SimpleNamespace(capture_time_s=np.array([101.0, 102.0]))
    offline = offline_counterpart(scenario, world, live, truth_log)
    assert offline.frames == 5 and offline.detector.hog_luma is reads_luma
