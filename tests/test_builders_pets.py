"""The PETS tables' protocols: nothing a table scores is used to fit it, and the area comes from the scene."""

from pathlib import Path

import numpy as np
import pytest

from ptztrack.builders.experiments import recording_cells, shared_views_key
from ptztrack.builders.pets import fit_detector, halves, protocol_folds
from ptztrack.builders.world import build_scene
from ptztrack.geometry.area import inside

EXCERPT = Path(__file__).parent / "data" / "pets_s2l1_excerpt"


def test_a_priori_is_the_scenario_itself_and_two_fold_scores_each_half_with_the_other_halfs_fit(
    tmp_path, excerpt_scenario
):
    scenario = excerpt_scenario(tmp_path, **{"recording.video": str(EXCERPT / "View_001.avi")})
    (assert_single,) = protocol_folds(scenario, "a-priori")
    assert assert_single.scenario is scenario and assert_single.fitted == {} and assert_single.index is None
    first, second = halves(scenario)
    # The excerpt's 30 frames, cut on the experiment's frame step of 2.
    assert first == (0, 16) and second == (16, 30)
    folds = protocol_folds(scenario, "two-fold")
    assert [fold.scenario.recording.frame_range for fold in folds] == [second, first]
    for fold, fitted_on in zip(folds, (first, second), strict=True):
        assert fold.fitted == fit_detector(scenario, fitted_on)
        assert fold.scenario.detector.pixel_noise_px == fold.fitted["pixel_noise_px"]
    with pytest.raises(ValueError, match="unknown protocol 'leave-one-out'"):
        protocol_folds(scenario, "leave-one-out")


def test_the_fitted_pixel_noise_and_width_are_the_annotations_own(tmp_path, excerpt_scenario):
    """The annotated feet lie a median 2.2 px from the calibrated ones in the 768 px frame (the data's
    README): about half a pixel at 160 px; the annotated boxes are about 0.36 times as wide as tall."""
    scenario = excerpt_scenario(tmp_path)
    fitted = fit_detector(scenario, halves(scenario)[0])
    assert set(fitted) == {"pixel_noise_px", "width_m"}
    assert 0.3 < fitted["pixel_noise_px"] < 1.0
    assert 0.30 * 1.75 < fitted["width_m"] < 0.42 * 1.75


def test_the_walkable_area_comes_from_the_calibrated_view_not_the_annotations(tmp_path, excerpt_scenario):
    scenario = excerpt_scenario(tmp_path)
    scene = build_scene(scenario, np.random.default_rng(0))
    assert inside(scene.area_polygon_m, scene.recording.annotations.ground_m).mean() > 0.95
    # Half the annotated people, the same area.
    rows = (EXCERPT / "gt_mot15.txt").read_text().splitlines()
    fewer = tmp_path / "fewer.txt"
    fewer.write_text("\n".join(row for row in rows if int(row.split(",")[1]) % 2) + "\n")
    fewer_scene = build_scene(
        excerpt_scenario(tmp_path, **{"recording.ground_truth": str(fewer)}), np.random.default_rng(0)
    )
    assert len(fewer_scene.recording.annotations.frame) < len(scene.recording.annotations.frame)
    np.testing.assert_array_equal(fewer_scene.area_polygon_m, scene.area_polygon_m)
    given = excerpt_scenario(tmp_path, **{"recording.area_m": [[0, 0], [10, 0], [10, 10]]})
    np.testing.assert_array_equal(
        build_scene(given, np.random.default_rng(0)).area_polygon_m, [[0, 0], [10, 0], [10, 10]]
    )


def test_only_runs_that_depend_on_their_seed_run_several_seeds(tmp_path, excerpt_scenario):
    hog = excerpt_scenario(tmp_path, **{"detector.kind": "hog", "recording.video": str(EXCERPT / "View_001.avi")})
    # With the online detector model, intg plans with draws of it, so it depends on its seed too.
    cells = recording_cells(hog, [1.0], ["fix", "rnd", "intg", "smpl"], seeds=3)
    assert sorted((cell.column, cell.seed) for cell in cells) == [
        ("fix", 0), ("intg b1", 0), ("intg b1", 1), ("intg b1", 2), ("rnd", 0), ("rnd", 1), ("rnd", 2),
        ("smpl b1", 0), ("smpl b1", 1), ("smpl b1", 2),
    ]  # fmt: skip
    kept = recording_cells(hog.model_copy(update={"detector": hog.detector.model_copy(update={"model": "a-priori"})}),
                           [1.0], ["fix", "rnd", "intg", "smpl"], seeds=3)  # fmt: skip
    assert sorted((cell.column, cell.seed) for cell in kept) == [
        ("fix", 0), ("intg b1", 0), ("rnd", 0), ("rnd", 1), ("rnd", 2), ("smpl b1", 0), ("smpl b1", 1), ("smpl b1", 2)
    ]  # fmt: skip
    ideal = recording_cells(excerpt_scenario(tmp_path), [1.0], ["fix"], seeds=3)
    assert [cell.seed for cell in ideal] == [0, 1, 2]


def test_the_information_gain_runs_of_one_fold_and_beta_share_their_views_and_no_other_runs_do(
    tmp_path, excerpt_scenario
):
    hog = excerpt_scenario(tmp_path, **{"detector.kind": "hog", "recording.video": str(EXCERPT / "View_001.avi")})
    cells = [
        cell for fold in (0, 1) for cell in recording_cells(hog, [9.0, 1.0], ["fix", "rnd", "intg", "smpl"], 3, fold)
    ]
    groups: dict = {}
    for cell in cells:
        groups.setdefault(shared_views_key(cell), []).append((cell.fold, cell.column, cell.seed))
    shared = sorted(group for group in groups.values() if len(group) > 1)
    assert shared == [
        [(fold, f"{strategy} b{beta}", seed) for strategy in ("intg", "smpl") for seed in range(3)]
        for fold in (0, 1)
        for beta in (1, 9)
    ]
    assert sum(map(len, groups.values())) == len(cells) == 2 * (1 + 3 + 2 * 6)
