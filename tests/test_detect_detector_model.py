import json

import numpy as np
import pytest

from ptztrack.detect.detector_model import (
    HEIGHT_BIN_EDGES_PX,
    PRIOR_TRIALS_PER_BIN,
    DetectorModelFileError,
    OnlineDetectorModel,
    bin_centres_px,
    read_detector_model_file,
)
from ptztrack.detect.simulated import RecallModel
from ptztrack.geometry.ptz import PTZCamera, look_at, person_in_view, project_people
from ptztrack.types import TrackerEvidence

CAMERA = PTZCamera((0.0, -20.0, 6.0), 640, 480, 400.0)
CALTECH = RecallModel(0.0098, 21.29)
HEIGHT_M, WIDTH_M = 1.75, 0.7


def model(**fields) -> OnlineDetectorModel:
    return OnlineDetectorModel(CAMERA, HEIGHT_M, WIDTH_M, fields.pop("prior", CALTECH), **fields)


def evidence(
    pose, mean_m, detected, existence=None, hits=None, excess_px2=(), false_births=0, exposure=1.0
) -> TrackerEvidence:
    n = len(mean_m)
    return TrackerEvidence(
        pose=np.asarray(pose, dtype=float),
        mean_m=np.asarray(mean_m, dtype=float).reshape(n, 2),
        position_sigma_m=np.full(n, 0.1),
        existence=np.ones(n) if existence is None else np.asarray(existence, dtype=float),
        hits=np.full(n, 5) if hits is None else np.asarray(hits),
        detected=np.asarray(detected, dtype=bool),
        excess_px2=np.asarray(excess_px2, dtype=float),
        false_births=false_births,
        exposure=exposure,
    )


def people_in_a_row(count: int) -> np.ndarray:
    """``count`` people side by side 2 m apart, 10 m in front of the camera: none hides another."""
    return np.c_[np.linspace(-(count - 1), count - 1, count), np.full(count, -10.0)]


def test_without_evidence_the_model_is_its_prior():
    learned = model()
    assert (learned.kd_per_px, learned.r0_px, learned.plateau) == (0.0098, 21.29, 1.0)
    heights = np.linspace(1, 300, 50)
    np.testing.assert_allclose(learned(heights), CALTECH(heights))
    mean, _ = learned.recall_by_bin()
    np.testing.assert_allclose(mean, CALTECH(bin_centres_px()), atol=1e-12)


def test_trials_are_the_established_tracks_fully_in_view_weighted_by_existence():
    ground = people_in_a_row(3)
    pose = look_at(CAMERA, [0.0, -10.0], 1.0)
    projected = project_people(CAMERA, pose, ground, HEIGHT_M, WIDTH_M)
    assert person_in_view(CAMERA, projected).all()
    behind = [0.0, -40.0]
    step = evidence(
        pose, [*ground, behind], [True, False, True, False], existence=[1.0, 0.5, 1.0, 1.0], hits=[5, 5, 1, 5]
    )
    index, height_px, weight = model().trials_of(step)
    # The third was detected once only, the fourth stands behind the camera.
    np.testing.assert_array_equal(index, [0, 1])
    np.testing.assert_allclose(height_px, projected.height_px[:2])
    np.testing.assert_allclose(weight, [1.0, 0.5])


def test_the_learned_recall_finds_the_detectors_own_curve_from_the_trackers_evidence():
    """A detector whose curve is far from the prior (found at half the prior's r0, and only 80 % of the
    time however large): trials at every zoom move the per-bin recall and the curve onto it."""
    truth = RecallModel(0.08, 6.0, plateau=0.8)
    rng = np.random.default_rng(1)
    learned = model()
    ground = people_in_a_row(3)
    for zoom in np.repeat([0.5, 0.75, 1.0, 1.5, 2.0, 3.0], 300):
        pose = look_at(CAMERA, [0.0, -10.0], zoom)
        height_px = project_people(CAMERA, pose, ground, HEIGHT_M, WIDTH_M).height_px
        learned.observe(evidence(pose, ground, rng.random(3) < truth(height_px)))
    mean, sd = learned.recall_by_bin()
    trials = learned.trials
    well_sampled = trials > 200
    assert well_sampled.sum() >= 4
    np.testing.assert_allclose(mean[well_sampled], truth(bin_centres_px()[well_sampled]), atol=0.06)
    assert np.all(sd[well_sampled] < 0.04)
    heights = bin_centres_px()[well_sampled]
    np.testing.assert_allclose(learned(heights), truth(heights), atol=0.06)


def test_the_a_priori_model_ignores_the_evidence():
    kept = model(learning=False)
    pose = look_at(CAMERA, [0.0, -10.0], 1.0)
    for _ in range(50):
        kept.observe(evidence(pose, people_in_a_row(3), [False] * 3, false_births=2, excess_px2=[100.0]))
    assert (kept.kd_per_px, kept.r0_px, kept.plateau) == (0.0098, 21.29, 1.0)
    assert kept.clutter_per_view == 0.0
    assert kept.learned_pixel_noise_px == 2.0


def test_clutter_and_noise_are_their_closed_form_posteriors():
    learned = model(false_positives_per_view=0.5, pixel_noise_px=2.0)
    pose = look_at(CAMERA, [0.0, -10.0], 1.0)
    births = [3, 0, 1, 0]
    rng = np.random.default_rng(0)
    excess = []
    for count in births:
        # Innovations of a 3 px noise with a prediction as sure as the detector: |nu|^2 - 0.
        step_excess = np.sum(rng.normal(0.0, 3.0, (1000, 2)) ** 2, axis=-1)
        excess.append(step_excess)
        learned.observe(evidence(pose, np.zeros((0, 2)), [], excess_px2=step_excess, false_births=count))
    assert learned.clutter_per_view == pytest.approx((10 * 0.5 + 4) / (10 + 4))
    expected = (2 * 10 * 4.0 + np.sum(np.concatenate(excess))) / (2 * (10 + 4000))
    assert learned.learned_pixel_noise_px == pytest.approx(np.sqrt(expected))
    assert learned.learned_pixel_noise_px == pytest.approx(3.0, abs=0.1)


def test_a_view_counts_in_the_clutter_by_its_exposure():
    """False births seen on a quarter of each view are a quarter of the view's false positives."""
    learned = model(false_positives_per_view=0.5)
    pose = look_at(CAMERA, [0.0, -10.0], 1.0)
    for _ in range(40):
        learned.observe(evidence(pose, np.zeros((0, 2)), [], false_births=1, exposure=0.25))
    assert learned.clutter_per_view == pytest.approx((10 * 0.5 + 40) / (10 + 0.25 * 40))


def test_a_saved_model_is_the_next_runs_prior(tmp_path):
    learned = model()
    pose = look_at(CAMERA, [0.0, -10.0], 1.0)
    for _ in range(40):
        learned.observe(evidence(pose, people_in_a_row(3), [True, True, False], false_births=1, excess_px2=[8.0]))
    path = tmp_path / "detector_model.json"
    learned.save(path)
    saved = json.loads(path.read_text())
    assert {"height_px", "recall", "recall_sd", "clutter_per_view", "pixel_noise_px"} <= set(saved)
    again = OnlineDetectorModel(CAMERA, HEIGHT_M, WIDTH_M, **read_detector_model_file(path))
    np.testing.assert_allclose(again.recall_by_bin()[0], learned.recall_by_bin()[0])
    np.testing.assert_allclose(again.recall_by_bin()[1], learned.recall_by_bin()[1])
    assert (again.kd_per_px, again.r0_px, again.plateau) == (learned.kd_per_px, learned.r0_px, learned.plateau)
    assert again.clutter_per_view == pytest.approx(learned.clutter_per_view)
    assert again.learned_pixel_noise_px == pytest.approx(learned.learned_pixel_noise_px)


def test_a_constant_prior_learns_a_constant_recall_pooled_over_the_bins():
    """A height-independent prior (0.9) and a detector that finds people half the time at every size: the
    fitted recall stays a constant, the pooled share of successes with the prior's pseudo-counts, and the
    planning draws are constants too."""
    learned = model(prior=RecallModel.constant(0.9))
    assert learned.perfect and learned.plateau == pytest.approx(0.9)
    np.testing.assert_allclose(learned(np.array([5.0, 50.0, 250.0])), 0.9)
    rng = np.random.default_rng(2)
    ground = people_in_a_row(3)
    for zoom in np.repeat([0.5, 1.0, 2.0], 100):
        learned.observe(evidence(look_at(CAMERA, [0.0, -10.0], zoom), ground, rng.random(3) < 0.5))
        assert learned.planning_curve.perfect
    assert learned.perfect
    prior_successes, prior_trials = np.sum(learned.prior_successes), np.sum(learned.prior_trials)
    expected = (prior_successes + np.sum(learned.successes)) / (prior_trials + np.sum(learned.trials))
    assert learned.plateau == pytest.approx(expected)
    assert learned.plateau == pytest.approx(0.5, abs=0.06)
    assert learned.planning_curve.plateau == pytest.approx(learned.plateau, abs=0.1)
    np.testing.assert_allclose(learned(np.array([5.0, 50.0, 250.0])), learned.plateau)


def test_a_constant_prior_learns_clutter_and_a_saved_one_stays_constant(tmp_path):
    learned = model(prior=RecallModel.constant(0.9))
    pose = look_at(CAMERA, [0.0, -10.0], 1.0)
    for _ in range(30):
        learned.observe(evidence(pose, people_in_a_row(3), [True, True, False], false_births=2))
    assert learned.clutter_per_view == pytest.approx(2 * 30 / (10 + 30))
    path = tmp_path / "detector_model.json"
    learned.save(path)
    again = OnlineDetectorModel(CAMERA, HEIGHT_M, WIDTH_M, **read_detector_model_file(path))
    assert again.perfect and again.plateau == pytest.approx(learned.plateau)


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda d: d.pop("successes"), "successes"),
        (lambda d: d.update(trials=[1.0] * 3), "out of range"),
        (lambda d: d.update(height_bin_edges_px=[1.0, 2.0]), "height bins"),
        (lambda d: d.update(clutter_per_view=-1.0), "out of range"),
    ],
)
def test_a_bad_model_file_is_refused_naming_the_file(tmp_path, change, message):
    path = tmp_path / "model.json"
    model().save(path)
    data = json.loads(path.read_text())
    change(data)
    path.write_text(json.dumps(data))
    with pytest.raises(DetectorModelFileError, match=message) as error:
        read_detector_model_file(path)
    assert str(path) in str(error.value)


def test_the_prior_weighs_as_many_trials_per_bin_as_it_says():
    learned = model()
    assert np.all(learned.prior_trials == PRIOR_TRIALS_PER_BIN)
    assert len(learned.prior_trials) == len(HEIGHT_BIN_EDGES_PX) - 1


@pytest.mark.slow
def test_a_run_writes_what_it_learned_and_the_next_run_starts_from_it(tmp_path, capsys):
    from ptztrack.cli import main

    first = tmp_path / "first"
    assert main(["run", "--frames", "15", "--quiet", "--out", str(first)]) == 0
    learned = json.loads((first / "detector_model.json").read_text())
    assert learned["learning"] is True
    prior_trials = PRIOR_TRIALS_PER_BIN * (len(HEIGHT_BIN_EDGES_PX) - 1)
    assert sum(learned["trials"]) > prior_trials + 5  # the run's own trials beside the prior's pseudo-trials
    second = tmp_path / "second"
    arguments = ["run", "--frames", "15", "--quiet", "--detector-model", str(first / "detector_model.json")]
    assert main([*arguments, "--out", str(second)]) == 0
    again = json.loads((second / "detector_model.json").read_text())
    # The second run's counts start from the first's and only grow.
    assert np.all(np.asarray(again["trials"]) >= np.asarray(learned["trials"]) - 1e-9)
    assert again["views"] == learned["views"] + 15
