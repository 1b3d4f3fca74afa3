import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.stats import multivariate_normal

import information_gain_reference
from overhead import CAMERA
from ptztrack.camera.actions import ActionGrid
from ptztrack.control.exploration import exploration_map
from ptztrack.control.gaussian_rectangle import bivariate_normal_cdf, gaussian_rectangle_probability
from ptztrack.control.information_gain import (
    action_geometry,
    detection_weight_integral,
    detection_weight_sampled,
    information_if_detected_nats,
)
from ptztrack.control.information_policy import InformationGainPolicy
from ptztrack.control.parameters import ControlParameters
from ptztrack.detect.parameters import DetectorPriorParameters
from ptztrack.detect.simulated import RecallModel
from ptztrack.geometry.area import rectangle_m
from ptztrack.geometry.occlusion import occluded_fraction, occlusion_in_centred_views
from ptztrack.geometry.ptz import (
    apply_homography,
    feet_jacobian,
    ground_to_image,
    head_from_feet_homology,
    homography_jacobian,
    look_at,
    project_people,
)
from ptztrack.track import kalman
from ptztrack.types import DecisionContext, Tracks

GRID = ActionGrid(np.linspace(-45.0, 45.0, 7), np.linspace(15.0, 60.0, 10), np.array([1.0, 2.0, 3.0, 4.0]), (2, 2, 1))
AREA_M = rectangle_m(15.0, 15.0)
V = 4.0 * np.eye(2)
HEIGHT_M = 1.75
WIDTH_M = 0.5
STEP_S = 0.2
# The paper's recall curve of HOG (the realistic detector's), and the ideal detector's recall of 1.
CURVES = {
    "realistic": RecallModel(DetectorPriorParameters.recall_kd, DetectorPriorParameters.recall_r0_px),
    "ideal": RecallModel(DetectorPriorParameters.recall_kd, DetectorPriorParameters.recall_r0_px, perfect=True),
}


def detector_model(kind="realistic"):
    """The recall model the policies plan with for the detector of ``kind``."""
    return CURVES[kind]


def policy_for(method, kind="realistic", beta=0.0):
    """The overhead scene's policy ``method`` planning with the ``kind`` detector's curve, with the
    patrolling term of weight ``beta`` (the default control parameters otherwise)."""
    recall, control = detector_model(kind), ControlParameters()
    exploration = None
    if beta > 0:
        exploration = exploration_map(
            CAMERA,
            GRID.poses,
            AREA_M,
            recall,
            HEIGHT_M,
            control.exploration_cell_m,
            control.prior_untracked_people,
            control.arrival_rate_per_s,
            STEP_S,
        )
    return InformationGainPolicy(CAMERA, GRID, recall, V, HEIGHT_M, WIDTH_M, method, control.samples, beta, exploration)


@settings(deadline=None, max_examples=60)
@given(
    mean=st.tuples(st.floats(-3, 3), st.floats(-3, 3)),
    scales=st.tuples(st.floats(0.1, 3), st.floats(0.1, 3)),
    rho=st.floats(-0.95, 0.95),
    low=st.tuples(st.floats(-4, 2), st.floats(-4, 2)),
    size=st.tuples(st.floats(0, 6), st.floats(0, 6)),
)
def test_rectangle_probability_matches_scipys_numerical_cdf(mean, scales, rho, low, size):
    cov = np.array([[scales[0] ** 2, rho * scales[0] * scales[1]], [rho * scales[0] * scales[1], scales[1] ** 2]])
    high = np.add(low, size)
    expected = multivariate_normal(mean, cov).cdf(high, lower_limit=low) if min(size) > 0 else 0.0
    value = gaussian_rectangle_probability(*mean, cov[0, 0], cov[0, 1], cov[1, 1], low[0], high[0], low[1], high[1])
    assert value == pytest.approx(expected, abs=1e-7)


def test_bivariate_cdf_special_values():
    assert bivariate_normal_cdf(0.0, 0.0, 0.0) == pytest.approx(0.25)
    assert bivariate_normal_cdf(0.0, 0.0, 0.5) == pytest.approx(0.25 + np.arcsin(0.5) / (2 * np.pi))
    assert bivariate_normal_cdf(20.0, 0.3, 0.7) == pytest.approx(0.6179114222)
    assert bivariate_normal_cdf(-20.0, 0.3, 0.7) == 0.0
    # a product of the two arguments would underflow to -0.0 here and lose the sign
    assert bivariate_normal_cdf(0.0, -6e-49, 0.0) == pytest.approx(0.25)
    assert bivariate_normal_cdf(-6e-49, 0.0, 0.3) == pytest.approx(0.25 + np.arcsin(0.3) / (2 * np.pi))


def alpha_monte_carlo(pose, mean_m, cov_m2, detector, rng, samples=400_000):
    """Equation 8 by sampling o ~ N(o-, Sigma_o), with the same linearised homology as the closed form."""
    H = ground_to_image(CAMERA, pose)
    o = apply_homography(H, mean_m[None])[0]
    J = feet_jacobian(CAMERA, pose, mean_m[None])[0]
    sigma_o = J @ cov_m2 @ J.T + V
    W = head_from_feet_homology(CAMERA, pose, HEIGHT_M)
    head = apply_homography(W, o[None])[0]
    slope = homography_jacobian(W, o[None])[0, 1, 1]
    draws = rng.multivariate_normal(o, sigma_o, size=samples)
    head_u = draws[:, 0] + (head[0] - o[0])
    head_v = head[1] + slope * (draws[:, 1] - o[1])
    inside = (
        (draws[:, 0] >= 0)
        & (draws[:, 0] <= CAMERA.image_width_px)
        & (head_u >= 0)
        & (head_u <= CAMERA.image_width_px)
        & (draws[:, 1] >= 0)
        & (draws[:, 1] <= CAMERA.image_height_px)
        & (head_v >= 0)
        & (head_v <= CAMERA.image_height_px)
    )
    return np.mean(inside * detector(draws[:, 1] - head_v))


@pytest.mark.parametrize("kind", ["ideal", "realistic"])
def test_closed_form_alpha_agrees_with_monte_carlo_of_equation_8(kind):
    rng = np.random.default_rng(7)
    detector = detector_model(kind)
    checked = 0
    for _ in range(30):
        mean_m = rng.uniform(0, 15, size=2)
        # aim near the person, so that many draws leave it partly in view
        pose = look_at(CAMERA, mean_m + rng.normal(0, 3.0, size=2), rng.choice(GRID.zoom))
        root = rng.normal(size=(2, 2)) * rng.uniform(0.05, 0.6)
        cov_m2 = root @ root.T + 1e-4 * np.eye(2)
        geometry = action_geometry(CAMERA, pose[None], HEIGHT_M)
        alpha = detection_weight_integral(CAMERA, geometry, detector, mean_m[None], cov_m2[None], V)[0, 0]
        expected = alpha_monte_carlo(pose, mean_m, cov_m2, detector, rng)
        assert alpha == pytest.approx(expected, abs=0.01), (pose, mean_m)
        checked += 0.02 < expected < 0.98
    assert checked >= 5, "the draws must include people partly in view"


def test_alpha_is_the_recall_well_inside_a_wide_view_and_zero_far_outside():
    detector = detector_model()
    mean_m = np.array([[7.5, 4.0]])
    cov_m2 = np.eye(2)[None] * 0.01**2
    inside = look_at(CAMERA, mean_m[0], 1.0)
    away = np.array([GRID.pan_deg[0], GRID.tilt_deg[0], GRID.zoom[-1]])
    geometry = action_geometry(CAMERA, np.stack([inside, away]), HEIGHT_M)
    alpha = detection_weight_integral(CAMERA, geometry, detector, mean_m, cov_m2, V)
    height_px = project_people(CAMERA, inside, mean_m, HEIGHT_M, 0.5).height_px[0]
    assert alpha[0, 0] == pytest.approx(detector(height_px), abs=0.01)
    assert alpha[1, 0] < 1e-6


def test_information_if_detected_is_the_entropy_drop_of_the_kalman_update():
    rng = np.random.default_rng(3)
    mean = np.array([[6.0, 8.0, 1.0, 0.0], [10.0, 3.0, 0.0, -1.0]])
    P = np.stack([np.diag([0.2, 0.1, 0.5, 0.5]), np.diag([0.05, 0.3, 0.4, 0.4])])
    P[:, 0, 1] = P[:, 1, 0] = 0.03
    actions = rng.choice(GRID.size, size=12, replace=False)
    geometry = action_geometry(CAMERA, GRID.poses[actions], HEIGHT_M)
    information = information_if_detected_nats(geometry, mean[:, :2], P[:, :2, :2], V)
    for row, action in enumerate(actions):
        J = feet_jacobian(CAMERA, GRID.poses[action], mean[:, :2])
        C = np.concatenate([J, np.zeros_like(J)], axis=-1)
        _, P_plus = kalman.update(mean, P, np.zeros((2, 2)), C, V)
        drop = 0.5 * (np.linalg.slogdet(P)[1] - np.linalg.slogdet(P_plus)[1])
        np.testing.assert_allclose(information[row], drop, rtol=1e-9)


def single_track(mean_xy, sigma_m):
    return Tracks(
        ids=np.array([0]),
        mean=np.array([[*mean_xy, 0.0, 0.0]]),
        covariance=np.diag([sigma_m**2, sigma_m**2, 0.1, 0.1])[None],
        existence=np.array([0.99]),
        hits=np.array([1]),
        next_id=1,
    )


@pytest.mark.parametrize("kind", ["ideal", "realistic"])
def test_with_one_person_and_no_occluders_smpl_and_intg_choose_the_same_action(kind):
    """Same action, up to ties: where both choices are worth the same to intg (within 0.1 %),
    the sampled estimate may pick either."""
    rng = np.random.default_rng(11)
    agreements = 0
    for trial in range(12):
        position = rng.uniform(1, 14, size=2)
        tracks = single_track(position, rng.uniform(0.05, 0.3))
        # start where the person can be seen from some reachable pose: a real choice to make
        distance = np.abs(GRID.poses[:, :2] - look_at(CAMERA, position)[:2]).sum(axis=1)
        current = int(np.argmin(distance + 100 * (GRID.axis_indices[:, 2] != rng.integers(4))))
        context = DecisionContext(0, current, GRID.reachable(current), tracks, np.random.default_rng(trial))
        intg_policy = policy_for("intg", kind)
        intg = intg_policy.choose(context)
        smpl = policy_for("smpl", kind).choose(context)
        agreements += intg == smpl
        worth = intg_policy.rewards(np.array([intg, smpl]), tracks, context.rng)
        assert worth[1] >= 0.999 * worth[0]
    assert agreements >= 10


def test_smpl_does_not_count_on_a_person_hidden_behind_another_but_intg_does():
    """Section 4.2: occlusion is what sampling adds."""
    front = np.array([7.5, 3.0])
    direction = front - CAMERA.centre_m[:2]
    behind = front + 0.3 * direction / np.linalg.norm(direction)
    mean_m = np.stack([front, behind])
    cov_m2 = np.eye(2)[None].repeat(2, 0) * 0.02**2
    pose = look_at(CAMERA, behind, 2.0)
    geometry = action_geometry(CAMERA, pose[None], HEIGHT_M)
    detector = detector_model("ideal")
    intg = detection_weight_integral(CAMERA, geometry, detector, mean_m, cov_m2, V)[0]
    smpl = detection_weight_sampled(
        CAMERA, geometry, detector, mean_m, cov_m2, HEIGHT_M, 0.5, pose, np.random.default_rng(0), 100
    )[0]
    hidden = project_people(CAMERA, pose, mean_m, HEIGHT_M, 0.5)
    c = occluded_fraction(hidden.box_px, hidden.range_m, hidden.in_front)
    assert c[1] > 0.8
    assert intg[1] > 0.99
    assert smpl[0] > 0.99
    assert smpl[1] == pytest.approx(1 - c[1], abs=0.1)


def crowd(rng, count):
    """``count`` tracks within a couple of metres of one another, in front of the camera: the
    nearer hide the farther in many draws. Position standard deviations 0.05-0.6 m."""
    centre = rng.uniform(4, 11, size=2)
    mean = np.concatenate([centre + rng.normal(0, 1.0, size=(count, 2)), rng.normal(0, 1, (count, 2))], axis=1)
    root = rng.normal(size=(count, 2, 2)) * rng.uniform(0.05, 0.6, size=(count, 1, 1))
    covariance = np.tile(np.eye(4) * 0.1, (count, 1, 1))
    covariance[:, :2, :2] = root @ np.swapaxes(root, 1, 2) + 1e-4 * np.eye(2)
    return Tracks(
        ids=np.arange(count),
        mean=mean,
        covariance=covariance,
        existence=np.full(count, 0.99),
        hits=np.ones(count, dtype=int),
        next_id=count,
    )


@pytest.mark.parametrize("kind", ["ideal", "realistic"])
@pytest.mark.parametrize("method", ["intg", "smpl"])
def test_rewards_of_the_kernels_are_those_of_the_numpy_reference(method, kind):
    """Every action's reward, from the compiled kernels, equals the plain NumPy evaluation of the
    same estimator (equations 7-9 and 19; the same draws for smpl) to rounding, on crowds that
    hide one another, and the best action is the same."""
    policy = policy_for(method, kind, beta=1.0)
    actions = np.arange(GRID.size)
    rng = np.random.default_rng(21)
    hidden = []
    for trial in range(6):
        tracks = crowd(rng, int(rng.integers(2, 9)))
        reward = policy.rewards(actions, tracks, np.random.default_rng(trial))
        expected = information_gain_reference.rewards(policy, actions, tracks, np.random.default_rng(trial))
        np.testing.assert_allclose(reward, expected, rtol=1e-9, atol=1e-9 * np.max(np.abs(expected)))
        assert np.argmax(reward) == np.argmax(expected)
        centred = project_people(
            CAMERA, look_at(CAMERA, tracks.mean[:, :2].mean(axis=0)), tracks.mean[:, :2], 1.75, 0.5
        )
        hidden.append(occluded_fraction(centred.box_px, centred.range_m, centred.in_front).max())
    assert np.mean(np.array(hidden) > 0.2) >= 0.5, "the crowds must hide people"


def test_one_reference_view_gives_the_detectors_occlusion_on_average():
    """smpl measures who hides whom once per sample in the view centred on the tracks;
    the simulated detector in the view centred on each person. Same rays, slightly different boxes."""
    rng = np.random.default_rng(5)
    ground_m = rng.uniform(0, 15, size=(100, 7, 2))
    reference = project_people(CAMERA, look_at(CAMERA, [7.5, 7.5], 1.0), ground_m, HEIGHT_M, 0.5)
    at_reference = occluded_fraction(reference.box_px, reference.range_m, reference.in_front)
    centred = np.stack(
        [
            occlusion_in_centred_views(CAMERA, g, np.full(7, HEIGHT_M), np.full(7, 0.5), np.ones(7, bool))
            for g in ground_m
        ]
    )
    assert np.mean(np.abs(at_reference - centred)) < 0.01
    assert np.mean(at_reference) == pytest.approx(np.mean(centred), rel=0.15)


def test_zoom_leaves_occluded_fractions_exactly_unchanged():
    rng = np.random.default_rng(6)
    ground_m = rng.uniform(0, 15, size=(10, 7, 2))
    fractions = []
    for zoom in (1.0, 2.5, 4.0):
        people = project_people(CAMERA, look_at(CAMERA, [6.0, 9.0], zoom), ground_m, HEIGHT_M, 0.5)
        fractions.append(occluded_fraction(people.box_px, people.range_m, people.in_front))
    np.testing.assert_allclose(fractions[0], fractions[1], atol=1e-9)
    np.testing.assert_allclose(fractions[0], fractions[2], atol=1e-9)


def test_patrolling_term_grows_while_unobserved_and_clears_where_the_camera_looks():
    exploration = policy_for("intg", "ideal", beta=1.0).exploration
    q = exploration.detection_probability(np.arange(len(exploration.height_px)))
    wide = int(np.argmax(q.sum(axis=1)))
    elsewhere = int(np.argmin(q[:, q[wide] > 0.5].sum(axis=1)))
    before = exploration.information_nats(np.array([wide]))[0]
    for _ in range(10):
        exploration.advance(elsewhere)
    grown = exploration.information_nats(np.array([wide]))[0]
    exploration.advance(wide)
    cleared = exploration.information_nats(np.array([wide]))[0]
    assert grown > before > 0
    assert cleared < 0.5 * grown
    never_seen = q.max(axis=0) == 0
    assert not never_seen.all()


def test_the_patrolling_term_grows_by_the_time_unobserved_in_steps_of_any_length():
    """Arrivals are a Poisson process: two half steps unobserved leave the map as one whole step does."""
    halves, whole = policy_for("intg", "ideal", beta=1.0).exploration, policy_for("intg", "ideal", beta=1.0).exploration
    q = halves.detection_probability(np.arange(len(halves.height_px)))
    unseen = int(np.argmin(q.sum(axis=1)))
    halves.advance(unseen, halves.step_s / 2)
    halves.advance(unseen, halves.step_s / 2)
    whole.advance(unseen)
    looked = q[unseen] > 0
    np.testing.assert_allclose(halves.occupancy[~looked], whole.occupancy[~looked], rtol=1e-12)


def test_looks_closer_than_a_step_clear_a_cell_together_as_one_look_of_a_step():
    """A live camera decides about three times a step: three looks of a third of a step at one view leave
    every cell, seen or not, where one look of a whole step does (no arrivals), and each clears less than
    that look (a miss's evidence raised to its share of the step)."""
    thirds, whole = policy_for("intg", beta=1.0).exploration, policy_for("intg", beta=1.0).exploration
    for exploration in (thirds, whole):
        exploration.arrival_rate_per_s = np.zeros_like(exploration.arrival_rate_per_s)
    q = thirds.detection_probability(np.arange(len(thirds.height_px)))
    view = int(np.argmax(q.sum(axis=1)))
    thirds.advance(view, thirds.step_s / 3)
    seen = (q[view] > 0) & (q[view] < 1)
    one_look = whole.occupancy * (1 - q[view]) / (1 - whole.occupancy * q[view])
    assert seen.any() and np.all(thirds.occupancy[seen] > one_look[seen])
    thirds.advance(view, thirds.step_s / 3)
    thirds.advance(view, thirds.step_s / 3)
    whole.advance(view)
    np.testing.assert_allclose(thirds.occupancy, whole.occupancy, rtol=1e-12)


def test_without_tracks_the_patrolling_term_moves_the_camera_and_without_it_the_camera_stays():
    empty = Tracks.empty()
    start = int(GRID.index(3, 4, 1))
    context = DecisionContext(0, start, GRID.reachable(start), empty, np.random.default_rng(0))
    assert policy_for("intg", beta=0.0).choose(context) == start
    explorer = policy_for("intg", beta=1.0)
    moves = [explorer.choose(context) for _ in range(3)]
    assert any(move != start for move in moves)


def test_control_defaults_are_the_papers_synthetic_protocol():
    """M = 100 samples, and no patrolling term: in section 5.1 "the targets are always in the scene"."""
    assert ControlParameters().samples == 100
    assert ControlParameters().beta == 0.0
