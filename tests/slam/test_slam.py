"""Radio SLAM pieces against cases computed by hand: similarity (Eq. 2), the distance model
(Eq. 3), the pose graph (Eq. 1) and its robust kernel, the trajectory error."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sfw_gym.core.errors import ConfigError
from sfw_gym.slam import (
    PoseGraph,
    SimilarityRangeModel,
    absolute_trajectory_error,
    closure_candidates,
    compose_pose,
    cosine_similarity,
    kernel_similarity,
    relative_pose,
)

nan = np.nan


def test_cosine_similarity_is_the_papers_eq_2():
    f_i, f_j = np.array([-40.0, -50.0, nan]), np.array([-40.0, nan, -60.0])
    # common AP 0 only in the numerator, each fingerprint's own APs in its norm
    expected = 1600.0 / (math.sqrt(1600 + 2500) * math.sqrt(1600 + 3600))
    assert cosine_similarity(f_i, f_j) == pytest.approx(expected)
    assert cosine_similarity(f_i, f_i) == pytest.approx(1.0)
    assert cosine_similarity(np.array([-40.0, nan]), np.array([nan, -40.0])) == 0.0
    many = cosine_similarity(f_i, np.stack([f_i, f_j]))  # one against many
    np.testing.assert_allclose(many, [1.0, expected])


def test_kernel_similarity_falls_with_the_rssi_difference_and_the_shared_aps():
    f = np.array([-40.0, -50.0])
    assert kernel_similarity(f, f) == pytest.approx(1.0)
    assert kernel_similarity(f, f - 6.0, sigma_db=6.0) == pytest.approx(math.exp(-0.5))
    half = kernel_similarity(np.array([-40.0, -50.0]), np.array([-40.0, nan]))
    assert half == pytest.approx(0.5)  # the one common AP agrees; half the heard APs are shared


def test_the_distance_model_bins_pairs_as_eq_3():
    model = SimilarityRangeModel(bin_width=0.05, min_samples=5)
    model.update(np.full(10, 0.92), np.r_[np.full(5, 1.0), np.full(5, 3.0)])
    model.update(np.full(3, 0.41), np.full(3, 9.0))  # too few in its bin
    mean, var = model.predict(np.array([0.91, 0.42, 0.1]))
    assert mean[0] == pytest.approx(2.0) and var[0] == pytest.approx(1.0)
    assert np.isnan(mean[1:]).all() and np.isnan(var[1:]).all()
    with pytest.raises(ConfigError, match="bin_width"):
        SimilarityRangeModel(bin_width=0.0)


def square_loop(n_side: int = 10, side_m: float = 10.0, laps: int = 2) -> np.ndarray:
    """Poses around a square, counter-clockwise, heading along the path, ``laps`` times."""
    poses = []
    for k in list(range(4)) * laps:
        heading = k * math.pi / 2
        start = np.array([[0, 0], [side_m, 0], [side_m, side_m], [0, side_m]][k], float)
        for t in range(n_side):
            xy = start + (t * side_m / n_side) * np.array([math.cos(heading), math.sin(heading)])
            poses.append([*xy, heading])
    return np.array(poses)


def drifting_graph(truth: np.ndarray, robust: str, false_closure: bool = False):
    """Odometry with a heading bias, radio closures between the laps' poses 1.5 m or less apart."""
    graph = PoseGraph(len(truth), robust=robust)
    odometry = [truth[0]]
    for k in range(len(truth) - 1):
        dx, dy, dth = relative_pose(truth[k], truth[k + 1])
        measured = (dx, dy, dth + 0.02)  # 0.02 rad of heading drift per step
        graph.add_odometry(k, k + 1, measured, sigma_xy=0.05, sigma_theta=0.02)
        odometry.append(compose_pose(odometry[-1], measured))
    for i in range(len(truth)):
        for j in range(i + 20, len(truth)):  # the second lap passes the first
            d = float(np.linalg.norm(truth[i, :2] - truth[j, :2]))
            if d <= 1.5:
                graph.add_range(i, j, d, sigma_m=0.3)
    if false_closure:  # far-apart poses claimed to be the same place
        for i, j in ((5, 65), (15, 55), (25, 75)):
            graph.add_range(i, j, 0.0, sigma_m=0.3)
    return graph, np.array(odometry)


def test_odometry_alone_is_kept_and_closures_undo_the_drift():
    truth = square_loop()
    graph, odometry = drifting_graph(truth, robust="none")
    assert absolute_trajectory_error(odometry, truth) > 1.0  # the drift opens the loop
    solved = graph.optimize(odometry)
    assert absolute_trajectory_error(solved, truth) < 0.3
    np.testing.assert_allclose(solved[0], odometry[0], atol=1e-6)  # the first pose stays
    chain = PoseGraph(len(truth))
    for k in range(len(truth) - 1):
        chain.add_odometry(k, k + 1, relative_pose(odometry[k], odometry[k + 1]), 0.05, 0.02)
    np.testing.assert_allclose(chain.optimize(odometry), odometry, atol=1e-9)  # nothing to fix


def test_a_robust_kernel_keeps_a_false_closure_from_bending_the_trajectory():
    truth = square_loop()
    plain_graph, odometry = drifting_graph(truth, robust="none", false_closure=True)
    robust_graph, _ = drifting_graph(truth, robust="cauchy", false_closure=True)
    plain = absolute_trajectory_error(plain_graph.optimize(odometry), truth)
    robust = absolute_trajectory_error(robust_graph.optimize(odometry), truth)
    assert robust < 0.3 < plain


def test_ate_ignores_a_rigid_motion_and_rejects_mismatched_trajectories():
    truth = square_loop()
    c, s = math.cos(0.7), math.sin(0.7)
    moved = truth[:, :2] @ np.array([[c, s], [-s, c]]) + [3.0, -2.0]
    assert absolute_trajectory_error(moved, truth) == pytest.approx(0.0, abs=1e-9)
    with pytest.raises(ConfigError, match="same"):
        absolute_trajectory_error(truth[:3], truth)
    with pytest.raises(ConfigError, match="robust"):
        PoseGraph(3, robust="tukey")


def test_closure_candidates_are_close_fingerprints_far_apart_along_the_path():
    rng = np.random.default_rng(0)
    places = rng.uniform(-90, -40, (5, 8))  # five places, eight APs
    visits = [0, 1, 2, 3, 4, 0, 2]  # the walk returns to places 0 and 2
    fingerprints = places[visits] + rng.normal(0, 1, (len(visits), 8))
    fingerprints[3, 5] = nan  # an AP not heard once
    travelled = np.arange(len(visits)) * 10.0
    pairs = closure_candidates(fingerprints, travelled, min_travel_m=15.0, radius_db=8.0)
    assert pairs.tolist() == [[0, 5], [2, 6]]
    brute = [
        (i, j)
        for i in range(len(visits))
        for j in range(i + 1, len(visits))
        if np.linalg.norm(
            np.nan_to_num(fingerprints[i], nan=-100) - np.nan_to_num(fingerprints[j], nan=-100)
        )
        <= 8.0
        and travelled[j] - travelled[i] >= 15.0
    ]
    assert [tuple(p) for p in pairs] == brute  # the KD-tree finds what all pairs would
    assert closure_candidates(fingerprints, travelled, min_travel_m=100.0, radius_db=8.0).shape == (
        0,
        2,
    )


@pytest.mark.slow
def test_radio_slam_on_a_drifting_run_with_background_aps_beats_odometry():
    import gymnasium as gym

    import sfw_gym  # noqa: F401  (registration)
    from sfw_gym.agents import FrontierAgent
    from sfw_gym.slam import radio_slam

    noisy = {"odometry_translation_std": 0.05, "odometry_heading_std_rad": 0.02}
    env = gym.make("SfW-Explore-v0", n_background_aps=16, robot=noisy, max_steps=1500)
    obs, _ = env.reset(seed=2_000_001)
    agent = FrontierAgent()
    agent.reset(env, seed=0)
    truth, odometry, prints = [], [], []
    done = False
    while not done:
        obs, _, terminated, truncated, info = env.step(agent.act(obs))
        truth.append(info["true_pose"])
        odometry.append(info["odometry_pose"])
        prints.append(info["fingerprint"])
        done = terminated or truncated
    truth, odometry = np.array(truth), np.array(odometry)
    result = radio_slam(odometry, np.array(prints))
    apart = np.linalg.norm(
        truth[result.closures[:, 0], :2] - truth[result.closures[:, 1], :2], axis=1
    )
    # closures (between every 5th pose, the default keyframes) are real revisits
    assert len(apart) >= 10 and np.mean(apart < 2.0) > 0.9
    before = absolute_trajectory_error(odometry, truth)
    after = absolute_trajectory_error(result.poses, truth)
    assert after < 0.7 * before, (before, after)


def test_the_pose_graph_reaches_gtsams_optimum():
    """The same graph (odometry between-factors, range factors, the first pose fixed) solved by
    GTSAM's Levenberg–Marquardt: the optima agree within 1 cm (no robust kernel in either)."""
    gtsam = pytest.importorskip("gtsam")
    rng = np.random.default_rng(3)
    truth = square_loop()
    n = len(truth)
    sxy, sth, srange = 0.005, 0.02, 0.3  # SfW-ExploreDrift-v0: 5 % of a 0.1 m step
    graph, factors = PoseGraph(n, robust="none"), gtsam.NonlinearFactorGraph()
    odometry = [truth[0]]
    for k in range(n - 1):
        dx, dy, dth = relative_pose(truth[k], truth[k + 1])
        z = (dx + rng.normal(0, sxy), dy + rng.normal(0, sxy), dth + rng.normal(0, sth))
        graph.add_odometry(k, k + 1, z, sxy, sth)
        factors.add(
            gtsam.BetweenFactorPose2(
                k,
                k + 1,
                gtsam.Pose2(*z),
                gtsam.noiseModel.Diagonal.Sigmas(np.array([sxy, sxy, sth])),
            )
        )
        odometry.append(compose_pose(odometry[-1], z))
    for i, j in [(0, n - 1), (5, n - 6), (10, 50), (20, 60), (2, 42)]:
        d = float(np.hypot(*(truth[i, :2] - truth[j, :2]))) + rng.normal(0, srange)
        graph.add_range(i, j, d, srange)
        factors.add(gtsam.RangeFactorPose2(i, j, d, gtsam.noiseModel.Isotropic.Sigma(1, srange)))
    odometry = np.array(odometry)
    factors.add(
        gtsam.PriorFactorPose2(
            0, gtsam.Pose2(*odometry[0]), gtsam.noiseModel.Isotropic.Sigma(3, 1e-6)
        )
    )
    values = gtsam.Values()
    for k, pose in enumerate(odometry):
        values.insert(k, gtsam.Pose2(*pose))
    params = gtsam.LevenbergMarquardtParams()
    params.setRelativeErrorTol(1e-12)
    params.setAbsoluteErrorTol(1e-12)
    params.setMaxIterations(200)
    solved = gtsam.LevenbergMarquardtOptimizer(factors, values, params).optimize()
    theirs = np.array([[solved.atPose2(k).x(), solved.atPose2(k).y()] for k in range(n)])
    ours = graph.optimize(odometry, iterations=200, relative_decrease=1e-12)[:, :2]
    assert np.abs(ours - odometry[:, :2]).max() > 0.1  # the closures did move the poses
    assert np.abs(ours - theirs).max() < 0.01


def test_the_online_solver_fits_the_distance_model_as_the_offline_one_does():
    from sfw_gym.slam import OnlineRadioSlam, RadioSlamConfig
    from sfw_gym.slam.radio_slam import fit_range_model

    rng = np.random.default_rng(0)
    truth = square_loop(n_side=25, laps=3)
    aps = rng.uniform(-5, 15, (8, 2))
    d = np.linalg.norm(truth[:, None, :2] - aps[None], axis=2)
    prints = -40 - 20 * np.log10(1 + d) + rng.normal(0, 2, d.shape)
    config = RadioSlamConfig(solve_every=50)
    online = OnlineRadioSlam(config)
    moved = [online.add(pose, f) for pose, f in zip(truth, prints, strict=True)]
    assert online.n_solves == len(truth) // 50
    assert all(m is None for k, m in enumerate(moved) if (k + 1) % 50)  # solves only on schedule
    offline = SimilarityRangeModel()
    fit_range_model(offline, truth[: 50 * online.n_solves], prints[: 50 * online.n_solves], config)
    np.testing.assert_array_equal(online.model._n, offline._n)
    np.testing.assert_allclose(online.model._sum, offline._sum)
    # between solves the estimate follows odometry from the last solved pose
    estimate = online.estimate()
    assert estimate.shape == truth.shape
    np.testing.assert_allclose(online.latest(), estimate[-1])


def test_rpe_measures_drift_per_step_and_the_metrics_module_has_every_score():
    from sfw_gym import metrics
    from sfw_gym.slam import relative_pose_error

    truth = square_loop()
    assert relative_pose_error(truth, truth) == (0.0, 0.0)
    # every step 0.1 m too long along the robot's heading: 0.1 m of translation error per step
    steps = np.diff(truth[:, :2], axis=0)
    longer = steps * (1 + 0.1 / np.linalg.norm(steps, axis=1))[:, None]
    stretched = truth.copy()
    stretched[1:, :2] = truth[0, :2] + np.cumsum(longer, axis=0)
    translation, rotation = relative_pose_error(stretched, truth)
    assert translation == pytest.approx(0.1) and rotation == pytest.approx(0.0, abs=1e-12)
    assert relative_pose_error(stretched, truth, delta=2)[0] == pytest.approx(0.2, rel=0.05)
    with pytest.raises(ConfigError, match="delta"):
        relative_pose_error(truth, truth, delta=0)
    assert metrics.absolute_trajectory_error is absolute_trajectory_error
    assert {"free_iou", "wall_precision", "relative_pose_error"} <= set(metrics.__all__)


def test_false_closures_the_first_solve_disagrees_with_are_dropped():
    from sfw_gym.slam import RadioSlamConfig, radio_slam

    rng = np.random.default_rng(1)
    truth = square_loop(n_side=25, laps=3)
    aps = rng.uniform(-5, 15, (12, 2))
    prints = -40 - 20 * np.log10(1 + np.linalg.norm(truth[:, None, :2] - aps[None], axis=2))
    prints = prints + rng.normal(0, 1, prints.shape)
    odometry = [truth[0]]
    for k in range(len(truth) - 1):  # odometry with a heading bias
        dx, dy, dth = relative_pose(truth[k], truth[k + 1])
        odometry.append(compose_pose(odometry[-1], (dx, dy, dth + 0.01)))
    odometry = np.array(odometry)
    false = np.array([[0, 150, 0.5], [25, 175, 0.5], [10, 260, 0.3]])
    apart = np.linalg.norm(
        truth[false[:, 0].astype(int), :2] - truth[false[:, 1].astype(int), :2], axis=1
    )
    assert apart.min() > 5.0  # claimed 0.3-0.5 m: false
    cfg = RadioSlamConfig(odometry_sigma_m=0.01)
    kept = radio_slam(odometry, prints, cfg, extra_closures=false).closures.tolist()
    assert not {(0, 150), (25, 175), (10, 260)} & {tuple(c) for c in kept}
    assert len(kept) > 10  # the true ones stay
