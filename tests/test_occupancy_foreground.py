import functools

import cv2
import numpy as np
import pytest
from scipy.spatial.distance import pdist

from ptztrack.builders.occupancy_synthetic import ROOM_AREA_M, rendered_recording, room_recording
from ptztrack.occupancy.detectors import ClusteringDetector, LpomForegroundDetector, lpom_parameters
from ptztrack.occupancy.foreground import ViewForeground, clean_silhouettes, silhouette_edges, view_foregrounds
from ptztrack.occupancy.parameters import ForegroundParameters, OccupancyParameters
from ptztrack.occupancy.room import RoomLayout, RoomRenderer, room_truth
from ptztrack.scene.render import draw_people

# The 3-person room long enough for the background model to have warmed up (its learning rate is
# 1 / (2 n) at its n-th frame): the last frames are the ones checked.
FRAMES, SEED = 60, 3
CHECKED = range(FRAMES - 5, FRAMES)


@pytest.fixture(scope="module")
def room():
    layout = RoomLayout()
    return RoomRenderer(layout, room_truth(layout, 3, FRAMES, SEED), SEED)


def people_pixels(renderer: RoomRenderer, view: int, frame: int) -> np.ndarray:
    """Where the rendered people are: (height, width) bool, the pixels the people change in the noiseless image."""
    background = renderer.backgrounds[view]
    drawn = draw_people(background, renderer.cameras[view], renderer.people_cones(frame), renderer.outfits)
    return np.any(drawn != background, axis=-1)


def boundary(mask) -> np.ndarray:
    """Pixels of ``mask`` with a 4-neighbour outside it, the image's border continuing the mask."""
    padded = np.pad(mask, 1, mode="edge")
    inside = padded[:-2, 1:-1] & padded[2:, 1:-1] & padded[1:-1, :-2] & padded[1:-1, 2:]
    return mask & ~inside


@pytest.mark.slow
def test_the_silhouettes_cover_the_rendered_people_and_little_else_once_warmed_up(room):
    hits = people = false = 0
    for view in range(4):
        model = ViewForeground(lambda frame, view=view: room.image(view, frame), ForegroundParameters())
        assert not model.silhouettes(0).any()  # no background to compare the first frame with
        for frame in CHECKED:
            silhouettes, truth = model.silhouettes(frame), people_pixels(room, view, frame)
            assert silhouettes.shape == truth.shape and silhouettes.dtype == bool
            hits += np.sum(silhouettes & truth)
            people += np.sum(truth)
            false += np.sum(silhouettes & ~truth)
    assert hits / people > 0.75
    assert false / people < 0.02


def test_the_edges_are_the_silhouettes_boundary():
    mask = np.zeros((8, 10), bool)
    mask[2:5, 3:7] = True  # a block inside: its outline
    mask[5:, 0:2] = True  # a block cut by the image's left and bottom sides: no edge along them
    expected = np.zeros_like(mask)
    expected[2:5, 3:7] = True
    expected[3, 4:6] = False
    expected[5, 0:2] = True
    expected[5:, 1] = True
    np.testing.assert_array_equal(silhouette_edges(mask), expected)
    assert not silhouette_edges(np.ones((4, 4), bool)).any()


@pytest.mark.slow
def test_the_edges_of_the_rooms_silhouettes_are_their_boundary(room):
    model = ViewForeground(lambda frame: room.image(1, frame), ForegroundParameters())
    for frame in range(CHECKED.start):
        model.silhouettes(frame)
    silhouettes, edges = model.silhouettes(CHECKED.start), model.edges(CHECKED.start)
    assert edges.sum() > 500
    assert not np.any(edges & ~silhouettes)
    np.testing.assert_array_equal(edges, boundary(silhouettes))


def test_a_shadow_is_left_out_of_the_silhouettes_and_an_object_is_not():
    rng = np.random.default_rng(0)
    background = cv2.resize(rng.uniform(60, 200, (12, 16, 3)), (128, 96), interpolation=cv2.INTER_CUBIC)
    frames = [np.clip(background + rng.normal(0, 2, background.shape), 0, 255).astype(np.uint8) for _ in range(40)]
    last = frames[-1].astype(float)
    last[20:60, 10:40] *= 0.7  # a shadow: the same colours, darker
    last[20:60, 70:100] = (40, 200, 60)  # an object of another colour
    frames[-1] = np.clip(last, 0, 255).astype(np.uint8)
    for detect_shadows, shadow_is_foreground in ((True, False), (False, True)):
        model = ViewForeground(frames.__getitem__, ForegroundParameters(detect_shadows=detect_shadows))
        silhouettes = model.silhouettes(len(frames) - 1)
        assert silhouettes[20:60, 70:100].mean() > 0.95
        shadow = silhouettes[20:60, 10:40].mean()
        assert shadow > 0.95 if shadow_is_foreground else shadow < 0.05
        assert silhouettes[70:, :].mean() < 0.01  # the untouched background


def test_clean_silhouettes_drop_shadows_and_specks_and_close_small_gaps():
    mask = np.zeros((40, 40), np.uint8)
    mask[5:30, 5:12] = 255
    mask[5:30, 16:20] = 255  # 4 px of background between two parts of a body: closed by the 9 px closing
    mask[34, 34] = 255  # a speck: opened away
    mask[5:30, 25:35] = 127  # a shadow
    silhouettes = clean_silhouettes(mask, ForegroundParameters())
    assert silhouettes[5:30, 5:20].all()
    assert not silhouettes[:, 22:].any()


@pytest.mark.slow
def test_the_same_frames_give_the_same_masks_whatever_the_order_and_the_thread_count():
    layout = RoomLayout(image_size_px=(256, 192), focal_px=125.0)
    renderer = RoomRenderer(layout, room_truth(layout, 3, 30, 1), 1)

    def frames(frame: int) -> np.ndarray:
        return renderer.image(0, frame)

    in_order = ViewForeground(frames, ForegroundParameters())
    expected = {frame: in_order.silhouettes(frame).copy() for frame in range(30)}
    assert expected[25].sum() > 100
    threads = cv2.getNumThreads()
    try:
        cv2.setNumThreads(1)
        jumping = ViewForeground(frames, ForegroundParameters())
        for frame in (25, 29, 12, 13, 29):  # ahead, ahead, back (learned again from frame 0), the next, ahead
            np.testing.assert_array_equal(jumping.silhouettes(frame), expected[frame])
            np.testing.assert_array_equal(jumping.edges(frame), silhouette_edges(expected[frame]))
    finally:
        cv2.setNumThreads(threads)


@pytest.mark.slow
def test_a_lead_in_is_learned_before_the_first_frame_and_frame_0_has_silhouettes():
    """Frames -L..-1 of a recording with a lead-in are what frames 0..L-1 are to a recording without one."""
    layout = RoomLayout(image_size_px=(256, 192), focal_px=125.0)
    renderer = RoomRenderer(layout, room_truth(layout, 3, 30, 1), 1)
    lead_in = 20

    def from_the_lead_in(frame: int) -> np.ndarray:
        return renderer.image(0, frame + lead_in)

    with_lead_in = ViewForeground(from_the_lead_in, ForegroundParameters(), first_frame=-lead_in)
    without = ViewForeground(functools.partial(renderer.image, 0), ForegroundParameters())
    for frame in (0, 5, 2):  # in order, then back (learned again from the lead-in's first frame)
        np.testing.assert_array_equal(with_lead_in.silhouettes(frame), without.silhouettes(frame + lead_in))
    assert with_lead_in.silhouettes(0).sum() > 100
    assert not ViewForeground(from_the_lead_in, ForegroundParameters()).silhouettes(0).any()


@pytest.mark.slow
def test_the_baselines_blob_boxes_learn_the_lead_in_as_well():
    """The baseline's frame 0 after a lead-in of L frames is what its frame L is without one."""
    layout = RoomLayout(image_size_px=(256, 192), focal_px=125.0)
    renderer = RoomRenderer(layout, room_truth(layout, 3, 30, 1), 1)
    names = [f"camera_{index + 1}" for index in range(len(renderer.cameras))]
    lead_in = 20
    with_lead_in = rendered_recording("room", names, renderer, ROOM_AREA_M, 15.0, lead_in)
    without = rendered_recording("room", names, renderer, ROOM_AREA_M, 15.0)
    learned = ClusteringDetector(with_lead_in, 1.0, 0.5, 100)
    fresh = ClusteringDetector(without, 1.0, 0.5, 100)
    for frame in range(lead_in):
        fresh.detect(frame)
    for frame in range(3):
        expected, found = fresh.detect(frame + lead_in), learned.detect(frame)
        np.testing.assert_array_equal(found.position_m, expected.position_m)
        np.testing.assert_array_equal(found.views, expected.views)
    assert len(expected.position_m) >= 1


@pytest.mark.slow
def test_lpom_from_the_silhouettes_finds_the_rooms_people_within_a_quarter_metre():
    recording = room_recording(people=3, frames=FRAMES, seed=SEED)
    detector = LpomForegroundDetector(
        recording, lpom_parameters(OccupancyParameters()), view_foregrounds(recording, ForegroundParameters())
    )
    assert len(detector.detect(0)[1]) == 0  # no background yet, no evidence
    for frame in range(1, FRAMES):
        pom, modes = detector.detect(frame)
        if frame not in CHECKED:
            continue
        truth_m = recording.truth.positions_m[frame]
        assert pdist(truth_m).min() > 1.0  # apart, so that each can have a mode of its own
        strong = modes.select(modes.strength >= 0.5)
        assert len(strong) == 3
        distance_m = np.linalg.norm(truth_m[:, None] - strong.position_m[None], axis=-1)
        assert np.all(distance_m.min(axis=1) < 0.25)
        assert 0.98 < pom.sum() <= 1.0 + 1e-9
