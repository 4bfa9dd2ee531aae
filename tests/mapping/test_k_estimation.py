"""RSSI -> k estimation: thresholds, filter, schedule, prior, calibration, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping import KEstimator, MapperConfig
from sfw_gym.mapping.k_estimation import fit_levels, merge_levels, thresholds_from_levels

K0 = 20.0 - 40.2  # distance-corrected RSSI with no wall


def levels_data(levels, n=300, spread=1.0):
    jitter = np.linspace(-spread, spread, n)
    return np.concatenate([lv + jitter for lv in levels])


def test_thresholds_at_midpoints_of_well_separated_clusters():
    levels, _ = fit_levels(levels_data([-20.0, -30.0, -40.0]), max_k=3, min_gap_db=5.0)
    assert levels == pytest.approx([-20.0, -30.0, -40.0], abs=1e-9)
    thr = thresholds_from_levels(levels, max_k=3, wall_loss_db=10.0)
    # midpoints between the levels, then one extrapolated half a wall below the last
    assert thr == pytest.approx([-25.0, -35.0, -45.0], abs=1e-9)


def test_paper_mode_without_merging_keeps_k_plus_1_clusters():
    levels, _ = fit_levels(levels_data([-20.0, -30.0, -40.0]), max_k=3, min_gap_db=0.0)
    assert len(levels) == 4  # one real level split in two: the failure merging avoids


def test_merge_levels_by_gap_and_by_size():
    assert merge_levels(np.array([-20.0, -22.0, -40.0]), np.array([1, 1, 2]), 5.0) == (
        pytest.approx([-21.0, -40.0])
    )
    # a tiny top cluster (outliers) joins its neighbour instead of becoming k = 0
    merged = merge_levels(np.array([-5.0, -20.0, -30.0]), np.array([1, 99, 100]), 5.0, 0.02)
    assert merged == pytest.approx([-19.85, -30.0])  # (-5 + 99 * -20) / 100


def test_thresholds_from_levels_with_calibrated_top():
    thr = thresholds_from_levels(np.array([-30.0, -40.0]), max_k=3, wall_loss_db=10.0, k_top=1)
    assert thr == pytest.approx([-25.0, -35.0, -45.0])
    assert thresholds_from_levels(np.array([-20.0]), 2, 10.0) == pytest.approx([-25.0, -35.0])


def test_distance_aware_recovers_k_where_raw_rssi_cannot():
    rng = np.random.default_rng(1)
    n = 600
    d = rng.uniform(1.0, 12.0, n)
    k = rng.integers(0, 3, n)
    rssi = np.round(K0 - 20.0 * np.log10(d) - 10.0 * k)
    acc = {}
    for mode in ("distance_aware", "kmeans"):
        est = KEstimator(1, MapperConfig(k_estimator=mode, filter_window=1))
        for i in range(n):
            est.update([rssi[i]], [d[i]])
        est.refit(force=True)
        ks = np.array([est.estimate(est.add([rssi[i]], [d[i]]))[0] for i in range(n)])
        acc[mode] = np.mean(ks == k)
    assert acc["distance_aware"] == 1.0
    assert acc["kmeans"] < 0.8


def test_not_heard_is_skipped():
    est = KEstimator(2, MapperConfig())
    k = est.update([-100.0, -40.0], [3.0, 3.0])
    assert k.tolist() == [-1, 0]
    assert est.n_samples.tolist() == [0, 1]
    assert np.isnan(est.add([-120.0, -40.0], [3.0, 3.0])[0])


def test_sliding_window_mean():
    est = KEstimator(1, MapperConfig(k_estimator="kmeans", filter_window=3))
    feats = [est.add([v], [1.0])[0] for v in (-40.0, -43.0, -46.0, -49.0)]
    assert feats == pytest.approx([-40.0, -41.5, -43.0, -46.0])


def test_filter_restarts_at_a_step_but_averages_noise():
    est = KEstimator(1, MapperConfig(k_estimator="kmeans", filter_window=3))
    assert est.filter_reset_db == pytest.approx(7.0)  # 0.7 of the prior wall loss
    feats = [est.add([v], [1.0])[0] for v in (-40.0, -41.0, -39.0, -46.0)]
    # -46 is within 7 dB of a held reading (-39): noise, averaged as by a plain sliding mean
    assert feats == pytest.approx([-40.0, -40.5, -40.0, -42.0])
    est = KEstimator(1, MapperConfig(k_estimator="kmeans", filter_window=3))
    feats = [est.add([v], [1.0])[0] for v in (-40.0, -41.0, -39.0, -50.0, -51.0, -49.0)]
    # one wall lower: -50 is far from all of -40, -41, -39, so the window restarts there and
    # no feature lies between the two levels
    assert feats == pytest.approx([-40.0, -40.5, -40.0, -50.0, -50.5, -50.0])
    plain = KEstimator(1, MapperConfig(k_estimator="kmeans", filter_window=3, filter_reset_db=0))
    feats = [plain.add([v], [1.0])[0] for v in (-40.0, -41.0, -39.0, -50.0)]
    assert feats[3] == pytest.approx(-130.0 / 3)  # the plain sliding mean smears the step


def test_fit_finds_sparse_levels_beside_a_dominant_one():
    # Most samples from one room (k = 0), a few through one and two walls: sample-quantile
    # starts alone put three clusters in the dominant level and one between the sparse ones.
    x = levels_data([-20.0], n=180, spread=0.5)
    x = np.concatenate([x, levels_data([-30.0, -40.0], n=10, spread=0.5)])
    levels, _ = fit_levels(x, max_k=3, min_gap_db=7.0, min_fraction=0.02)
    assert levels == pytest.approx([-20.0, -30.0, -40.0], abs=1e-9)


def test_prior_before_first_fit():
    est = KEstimator(1, MapperConfig(k_estimator="kmeans", filter_window=1))
    assert est.update([-40.0], [1.0]).tolist() == [0]
    assert est.thresholds(0) == pytest.approx([-45.0, -55.0, -65.0])
    assert est.update([-52.0], [1.0]).tolist() == [1]  # outside the top level's band
    assert est.update([-42.0], [1.0]).tolist() == [0]  # joins the top level: mean -41
    assert est.thresholds(0) == pytest.approx([-46.0, -56.0, -66.0])
    assert est.update([-30.0], [1.0]).tolist() == [0]  # far stronger: the new top level
    assert est.thresholds(0) == pytest.approx([-35.0, -45.0, -55.0])


def test_geometric_refit_schedule():
    cfg = MapperConfig(k_estimator="kmeans", refit_min_samples=32, refit_growth=1.5)
    est = KEstimator(1, cfg)
    for i in range(200):
        est.update([-50.0 - (i % 2)], [1.0])
    assert est.n_refits == 5  # at 32, 48, 72, 108 and 162 samples


def test_new_level_triggers_early_refit():
    cfg = MapperConfig(refit_min_samples=32, refit_growth=1.5, refit_max_interval=10_000)
    est = KEstimator(1, cfg)
    for i in range(1000):
        est.update([K0 - 20 * np.log10(2.0) + (i % 3) - 1], [2.0])
    refits = est.n_refits
    for i in range(40):  # behind a wall now: 10 dB lower
        est.update([K0 - 20 * np.log10(2.0) - 10.0 + (i % 3) - 1], [2.0])
    assert est.n_refits == refits + 1  # long before the geometric schedule (at ~1140)
    assert est.thresholds(0)[0] == pytest.approx(K0 - 5.0, abs=0.5)


def test_calibration_reads_a_router_heard_only_through_a_wall():
    d = 4.0
    rssi = K0 - 20.0 * np.log10(d) - 10.0
    for k0, expected in ((None, 0), (K0, 1)):
        est = KEstimator(1, MapperConfig(k0_level_dbm=k0))
        for i in range(100):
            k = est.update([rssi + (i % 2)], [d])
        assert k.tolist() == [expected]


def test_fit_buffer_stays_bounded():
    est = KEstimator(1, MapperConfig(fit_buffer_size=16))
    for i in range(100):
        est.update([-50.0 - (i % 7)], [2.0])
    assert est._fit_n[0] <= 16
    assert est._fit_stride[0] in (8, 16)


def test_bad_input_raises():
    est = KEstimator(2, MapperConfig())
    with pytest.raises(ConfigError, match="rssi_dbm"):
        est.update([-40.0], [1.0])
    with pytest.raises(ConfigError, match="rssi_dbm"):
        est.update([np.nan, -40.0], [1.0, 1.0])
    with pytest.raises(ConfigError, match="distances_m"):
        est.update([-40.0, -40.0], [1.0, np.inf])
    with pytest.raises(ConfigError, match="n_routers"):
        KEstimator(0)
    assert est.n_samples.tolist() == [0, 0]


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("k_estimator", "magic"),
        ("router_policy", "best"),
        ("max_k", 0),
        ("filter_window", 0),
        ("refit_growth", 1.0),
        ("wall_peak_probability", 1.0),
        ("free_log_odds", 0.1),
        ("robot_radius_m", -0.1),
        ("min_level_fraction", 0.6),
        ("outer_bounds_m", (0.0, 0.0, -1.0, 1.0)),
        ("k0_level_dbm", float("nan")),
        ("filter_reset_db", -1.0),
    ],
)
def test_config_validation_names_the_field(field, value):
    with pytest.raises(ConfigError, match=field):
        MapperConfig(**{field: value})


def test_calibration_needs_distance_aware():
    with pytest.raises(ConfigError, match="k0_level_dbm"):
        MapperConfig(k_estimator="kmeans", k0_level_dbm=-20.0)


def test_config_round_trips_through_dict():
    cfg = MapperConfig(outer_bounds_m=(0.0, 0.0, 5.0, 5.0), router_policy="all")
    assert MapperConfig(**cfg.to_dict()) == cfg


# -- from the mutation review: merging rules worked by hand, reset, refit, messages, dtypes ------
def test_merge_levels_gap_then_size_worked_example():
    # sorted: -40 (10), -45 (30), -52 (10), -70 (5). Gap step (6 dB): -40/-45 merge to
    # (-400 - 1350) / 40 = -43.75. Size step (15 % of 55 = 8.25): -70 (5 samples) joins its
    # only neighbour -52: (-520 - 350) / 15 = -58.
    out = merge_levels(np.array([-40.0, -52.0, -45.0, -70.0]), np.array([10, 10, 30, 5]), 6.0, 0.15)
    assert out == pytest.approx([-43.75, -58.0])


def test_merge_levels_boundaries_are_kept():
    assert merge_levels([-40.0, -46.0], [1, 1], 6.0).tolist() == [-40.0, -46.0]  # gap == min
    assert merge_levels([-40.0, -60.0], [3, 1], 6.0, 0.25).tolist() == [-40.0, -60.0]  # 1/4
    assert merge_levels([-50.0], [3], 6.0).tolist() == [-50.0]  # one level: nothing to merge
    assert merge_levels([-40.0, -42.0], [1, 1], 6.0).tolist() == [-41.0]  # two close levels
    assert merge_levels([-40, -60], [1, 1], 6.0).dtype == np.float64  # levels are float dB


def test_merge_levels_empty_cluster_has_no_weight():
    assert merge_levels([-40.0, -42.0], [5, 0], 6.0) == pytest.approx([-40.0])


@pytest.mark.parametrize(
    ("levels", "expected"),
    [
        # a small middle level joins the nearer neighbour: -50 is 10 dB from -40, 30 from -80
        ([-40.0, -50.0, -80.0], [(-400.0 - 50.0) / 11, -80.0]),
        ([-40.0, -70.0, -80.0], [-40.0, (-70.0 - 800.0) / 11]),
        # equidistant: the stronger neighbour
        ([-40.0, -60.0, -80.0], [(-400.0 - 60.0) / 11, -80.0]),
    ],
)
def test_merge_levels_small_cluster_joins_its_nearer_neighbour(levels, expected):
    assert merge_levels(levels, [10, 1, 10], 6.0, 0.1) == pytest.approx(expected)


def test_fit_levels_two_values_and_a_single_reading_level():
    levels, (lo, hi) = fit_levels([-40.0] * 5 + [-60.0] * 5, 3, 5.0)
    assert levels == pytest.approx([-40.0, -60.0]) and (lo, hi) == (-60.0, -40.0)
    # one reading of a level is a level (no size filter) ...
    levels, _ = fit_levels([-40.0] * 10 + [-70.0], 3, 5.0)
    assert levels == pytest.approx([-40.0, -70.0])
    # ... unless it holds less than min_fraction of the samples: then it joins its neighbour
    levels, extremes = fit_levels([-40.0] * 10 + [-70.0], 3, 5.0, 0.2)
    assert levels == pytest.approx([(-400.0 - 70.0) / 11]) and extremes == (-70.0, -40.0)
    assert fit_levels([-50.0] * 4, 3, 5.0) is None


def test_estimator_input_messages_and_default_config():
    with pytest.raises(ConfigError, match=r"^n_routers must be an int >= 1, got '3'$"):
        KEstimator("3")
    with pytest.raises(ConfigError, match=r"^config must be a MapperConfig, got dict$"):
        KEstimator(2, {"max_k": 3})
    est = KEstimator(2)  # the default configuration
    assert est.config == MapperConfig()
    with pytest.raises(ConfigError, match=r"^rssi_dbm must have shape \(2,\)"):
        est.add([-40.0], [1.0, 1.0])
    with pytest.raises(ConfigError, match=r"^distances_m must have shape \(2,\)"):
        est.add([-40.0, -50.0], [1.0])
    with pytest.raises(ConfigError, match=r"^features must have shape \(2,\), got \(3,\)"):
        est.estimate([-40.0, -50.0, -60.0])


def test_k_values_are_integers_and_minus_one_before_any_reading():
    est = KEstimator(2, MapperConfig(k0_level_dbm=-40.0))
    assert est.last_k.tolist() == [-1, -1]
    k = est.update([-40.0, -100.0], [1.0, 1.0])
    assert k.dtype.kind == "i" and k.tolist() == [0, -1]
    assert est.estimate([-40.0, -65.0]).dtype.kind == "i"


def test_reset_gives_a_fresh_estimator():
    cfg = MapperConfig(refit_min_samples=8)
    readings = [([-40.0 - 20.0 * (i // 10 % 2), -55.0], [2.0, 3.0]) for i in range(40)]
    fresh, used = KEstimator(2, cfg), KEstimator(2, cfg)
    for i in range(50):
        used.update([-30.0 - (i % 3) * 25.0, -70.0], [1.5, 4.0])
    used.reset()
    assert used.last_k.tolist() == [-1, -1] and used.n_samples.tolist() == [0, 0]
    assert used.n_samples.dtype.kind == "i"  # a count of readings
    for rssi, dist in readings:
        np.testing.assert_array_equal(used.update(rssi, dist), fresh.update(rssi, dist))
        np.testing.assert_array_equal(used.add(rssi, dist), fresh.add(rssi, dist))
    assert used.n_refits == fresh.n_refits
    for r in range(2):
        np.testing.assert_array_equal(used.thresholds(r), fresh.thresholds(r))


def two_levels(est, r_heard, other):
    """20 readings at -40 dBm then 20 at -60 dBm at 1 m from router r_heard."""
    for level in (-40.0, -60.0):
        for _ in range(20):
            rssi = np.full(est.n_routers, other)
            rssi[r_heard] = level
            est.add(rssi, np.ones(est.n_routers))


def test_forced_refit_fits_every_router_with_two_levels_and_skips_the_others():
    # router 0 never heard, router 1 heard at one level only (no fit), router 2 at two levels
    est = KEstimator(3, MapperConfig(refit_min_samples=1000))
    for level in (-40.0, -60.0):
        for _ in range(20):
            est.add([-100.0, -50.0, level], [1.0, 1.0, 1.0])
    est.refit()  # not due yet (1000 samples)
    assert est.n_refits == 0
    est.refit(force=True)
    assert est.n_refits == 1
    # levels -40 / -60, k_top 0: thresholds at the midpoint, then 10 dB walls below the lowest
    assert est.thresholds(2) == pytest.approx([-50.0, -65.0, -75.0])


def test_a_level_stronger_than_the_calibrated_k0_is_k_zero():
    # k0 = -50 dBm but a level at -40 dBm is seen: round((-50 + 40) / 10) = -1 → clamped to 0
    est = KEstimator(1, MapperConfig(k0_level_dbm=-50.0, refit_min_samples=1000))
    two_levels(est, 0, -100.0)
    est.refit(force=True)
    assert est.thresholds(0) == pytest.approx([-50.0, -65.0, -75.0])


def test_reset_restores_the_every_sample_reservoir():
    # readings alternate between two levels: a reservoir that kept every other sample would
    # see one level only and fit nothing
    cfg = MapperConfig(filter_window=1, refit_min_samples=1000)
    est = KEstimator(1, cfg)
    for i in range(3000):  # long enough to fill and thin the fit buffer
        est.add([-45.0 - (i % 5)], [1.0])
    est.reset()
    for i in range(20):
        est.add([-40.0 if i % 2 == 0 else -60.0], [1.0])
    est.refit(force=True)
    assert est.n_refits == 1
    assert est.thresholds(0) == pytest.approx([-50.0, -65.0, -75.0])


def test_refit_merges_levels_below_the_minimum_fraction():
    # 20 readings at -40 dBm, 2 at -70 dBm (9 % < 20 %): one level at (-800 - 140) / 22
    cfg = MapperConfig(filter_window=1, refit_min_samples=1000, min_level_fraction=0.2)
    est = KEstimator(1, cfg)
    for rssi in [-40.0] * 20 + [-70.0] * 2:
        est.add([rssi], [1.0])
    est.refit(force=True)
    top = (-800.0 - 140.0) / 22
    assert est.thresholds(0) == pytest.approx([top - 5.0, top - 15.0, top - 25.0])


# -- issue 31: the compiled 1-D k-means against scikit-learn, and the refit schedule -------------
def sklearn_kmeans(x, init, max_iter=100):
    """scikit-learn's KMeans from ``init``, one thread (as fit_levels ran it)."""
    import warnings

    from sklearn.cluster import KMeans

    from sfw_gym.core.threads import single_threaded_openmp

    with single_threaded_openmp(), warnings.catch_warnings():
        warnings.simplefilter("ignore")  # fewer distinct clusters than asked
        km = KMeans(
            len(init), init=np.asarray(init)[:, None], n_init=1, max_iter=max_iter, tol=1e-4
        )
        km.fit(np.asarray(x)[:, None])
    return km


def random_levels(rng, rounded):
    n, k = int(rng.integers(20, 1500)), int(rng.integers(2, 6))
    x = rng.choice(rng.uniform(-90, -20, k), n) + rng.normal(0, rng.uniform(0.5, 4), n)
    return (np.round(x) if rounded else x), k


@pytest.mark.parametrize("rounded", [False, True], ids=["continuous", "integer_dbm"])
def test_kmeans_1d_matches_sklearn(rounded):
    # Same starts as fit_levels (quantiles, evenly spaced); integer dBm has ties at midpoints
    # and empty clusters (relocated). Tolerance: centroids 1e-9 dB, inertia 1e-9 relative (the
    # arithmetic is scikit-learn's, in its order, so they agree to the bit here); labels and
    # iteration counts exactly.
    from sfw_gym.mapping.kmeans1d import kmeans_1d

    rng = np.random.default_rng(31)
    for _ in range(60):
        x, k = random_levels(rng, rounded)
        for init in (np.quantile(x, (np.arange(k) + 0.5) / k), np.linspace(x.min(), x.max(), k)):
            if np.unique(init).size < k:
                continue
            km = sklearn_kmeans(x, init)
            c, labels, inertia, n_iter = kmeans_1d(x, init)
            np.testing.assert_allclose(c, km.cluster_centers_[:, 0], rtol=0, atol=1e-9)
            np.testing.assert_array_equal(labels, km.labels_)
            assert inertia == pytest.approx(km.inertia_, rel=1e-9)
            assert n_iter == km.n_iter_


def test_kmeans_1d_relocates_empty_clusters_as_sklearn():
    # Evenly spaced starts -95, -75.5, -56, -36.5, -17: -36.5 gets nothing and takes the
    # farthest point (-66, 9.5 dB from -75.5), which empties -75.5; scikit-learn then parks
    # -75.5 on the heaviest cluster's not-yet-averaged sum (its quirk), outside the data.
    from sfw_gym.mapping.kmeans1d import kmeans_1d

    x = np.array([-95.0] * 3 + [-86.0] * 2 + [-66.0] + [-56.0, -50.0, -47.0] * 6 + [-25, -17] * 3)
    init = np.linspace(-95.0, -17.0, 5)
    for max_iter in (1, 100):
        km = sklearn_kmeans(x, init, max_iter)
        c, labels, _, n_iter = kmeans_1d(x, init, max_iter=max_iter)
        np.testing.assert_allclose(c, km.cluster_centers_[:, 0], rtol=0, atol=1e-9)
        np.testing.assert_array_equal(labels, km.labels_)
        assert n_iter == km.n_iter_
        if max_iter == 1:  # -75.5 parked on the heaviest cluster's sum of centred values
            heavy = x[(x >= -56.0) & (x <= -47.0)]
            assert c[1] == pytest.approx(x.mean() + np.sum(heavy - x.mean()), abs=1e-9)
            assert not heavy.min() <= c[1] <= heavy.max()  # not the heaviest's mean


def test_kmeans_1d_relocation_that_empties_a_later_cluster_is_sklearns():
    # Quantile starts, 6 clusters on 9 points: one cluster is empty and takes the farthest
    # point, the only point of a later cluster, which empties it; scikit-learn relocates only
    # the clusters empty before the relocation (the later one is parked on the heaviest's sum).
    # Re-checking the weights while relocating read past the farthest points (a segfault).
    from sfw_gym.mapping.kmeans1d import kmeans_1d

    x = np.array([-69.19, -24.11, -69.09, -68.68, -68.95, -69.7, -23.22, -24.34, -24.56])
    init = np.quantile(x, (np.arange(6) + 0.5) / 6)
    for max_iter in (1, 2, 100):
        km = sklearn_kmeans(x, init, max_iter)
        c, labels, inertia, n_iter = kmeans_1d(x, init, max_iter=max_iter)
        np.testing.assert_allclose(c, km.cluster_centers_[:, 0], rtol=0, atol=1e-9)
        np.testing.assert_array_equal(labels, km.labels_)
        assert n_iter == km.n_iter_ and inertia == pytest.approx(km.inertia_, rel=1e-9)
    new, old = fit_levels(x, 5, 3.0, 0.1), fit_levels(x, 5, 3.0, 0.1, backend="sklearn")
    np.testing.assert_allclose(new[0], old[0], rtol=0, atol=1e-9)


@pytest.mark.parametrize("rounded", [False, True], ids=["continuous", "integer_dbm"])
def test_fit_levels_matches_the_sklearn_backend(rounded):
    rng = np.random.default_rng(5)
    for _ in range(40):
        x, _ = random_levels(rng, rounded)
        for gap, frac in ((0.0, 0.0), (7.0, 0.02)):
            new = fit_levels(x, 3, gap, frac)
            old = fit_levels(x, 3, gap, frac, backend="sklearn")
            np.testing.assert_allclose(new[0], old[0], rtol=0, atol=1e-9)
            assert new[1] == pytest.approx(old[1], abs=1e-9)
    with pytest.raises(ConfigError, match="backend"):
        fit_levels(x, 3, 7.0, backend="magic")


def survey_readings(n, seed=0):
    """A robot walking past two walls of one router: distance-aware RSSI in integer dBm."""
    rng = np.random.default_rng(seed)
    d = 2.0 + 6.0 * np.abs(np.sin(np.arange(n) / 40.0))
    k = (np.arange(n) // 50) % 3  # rooms behind 0, 1, 2 walls, in turn
    return np.round(K0 - 20.0 * np.log10(d) - 10.0 * k + rng.normal(0.0, 2.0, n)), d


def test_scheduled_refits_equal_a_full_refit():
    cfg = MapperConfig(refit_min_samples=32, refit_growth=1.5)
    rssi, d = survey_readings(1200)
    # Stop at the first scheduled refit after 200 samples: it saw every sample so far, so its
    # thresholds are a full refit's (to the bit; tolerance 1e-9 dB).
    est = KEstimator(1, cfg)
    for i in range(1200):
        before = est.n_refits
        est.update([rssi[i]], [d[i]])
        if est.n_refits > before and i + 1 >= 200:
            break
    assert 200 <= i + 1 < 400 and est.n_refits >= 5
    scheduled = est.thresholds(0)
    est.refit(force=True)
    np.testing.assert_allclose(est.thresholds(0), scheduled, rtol=0, atol=1e-9)
    # Between refits (1200 samples, the last refit some hundreds earlier): the data's mix of
    # levels barely moves, so the thresholds stay within 0.25 dB of a full refit's.
    est = KEstimator(1, cfg)
    for i in range(1200):
        est.update([rssi[i]], [d[i]])
    scheduled = est.thresholds(0)
    assert np.isfinite(scheduled).all() and est._fitted[0]
    est.refit(force=True)
    np.testing.assert_allclose(est.thresholds(0), scheduled, rtol=0, atol=0.25)


def test_estimator_with_either_backend_gives_the_same_k_values(monkeypatch):
    from sfw_gym.mapping import k_estimation

    rssi, d = survey_readings(600, seed=2)
    out = {}
    for backend in ("sklearn", "numba"):
        monkeypatch.setattr(k_estimation, "FIT_BACKEND", backend)
        est = KEstimator(1, MapperConfig(refit_min_samples=16))
        ks = [est.update([rssi[i]], [d[i]])[0] for i in range(600)]
        out[backend] = (ks, est.thresholds(0), est.n_refits)
    assert out["numba"][0] == out["sklearn"][0]
    np.testing.assert_allclose(out["numba"][1], out["sklearn"][1], rtol=0, atol=1e-9)
    assert out["numba"][2] == out["sklearn"][2] > 5


# -- the compiled refit (one call per refit) against the Python path it replaced ----------------
def test_mean_var_are_numpys_to_the_bit():
    # numpy's pairwise sums: 8 accumulators up to 128 values, halves (multiples of 8) above; the
    # variance as numpy >= 2.3 sums it (older numpy's can differ in the last bit)
    from sfw_gym.mapping.kmeans1d import mean_var

    numpy_2_3 = tuple(int(p) for p in np.__version__.split(".")[:2]) >= (2, 3)
    rng = np.random.default_rng(7)
    sizes = [*range(1, 300), 511, 512, 513, 1000, 4095, 4096, 4097, 9999, 70001]
    for n in sizes:
        x = rng.normal(-60.0, 12.0, n)
        for data in (x, np.round(x)):
            mean, var = mean_var(data)
            assert mean == data.mean(), n
            if numpy_2_3:
                assert var == data.var(), n
            else:
                assert var == pytest.approx(data.var(), rel=4 * np.finfo(float).eps), n


def old_fit_levels(x, max_k, gap, frac):
    """fit_levels' numba backend before the fit went compiled end to end (numpy's mean, var,
    the cluster filter and merge_levels in Python around the compiled k-means)."""
    from sfw_gym.mapping.kmeans1d import KMEANS_MAX_ITER, KMEANS_TOL, cluster_1d

    x = np.asarray(x, dtype=np.float64)
    cents, counts = cluster_1d(x, x.mean(), x.var() * KMEANS_TOL, max_k + 1, KMEANS_MAX_ITER)
    if cents.size == 0:
        return None
    keep = counts > 0
    cents = cents[keep]
    return merge_levels(cents, counts[keep], gap, frac), (cents.min(), cents.max())


@pytest.mark.parametrize("rounded", [False, True], ids=["continuous", "integer_dbm"])
def test_compiled_fit_levels_equals_the_python_path_to_the_bit(rounded):
    rng = np.random.default_rng(11)
    for _ in range(300):
        x, _ = random_levels(rng, rounded)
        x = x[: int(rng.integers(1, x.size + 1))]
        for max_k, gap, frac in ((3, 0.0, 0.0), (3, 7.0, 0.02), (5, 3.0, 0.1), (1, 7.0, 0.0)):
            new, old = fit_levels(x, max_k, gap, frac), old_fit_levels(x, max_k, gap, frac)
            if old is None:
                assert new is None
                continue
            np.testing.assert_array_equal(new[0], old[0])
            assert new[1] == old[1]
    assert fit_levels([], 3, 7.0) is None and fit_levels([-50.0], 3, 7.0) is None


def test_fit_levels_falls_back_to_merge_levels_on_tied_centroids(monkeypatch):
    # Tied kept centroids (their order left to numpy's argsort) take the Python merge; forced
    # here, it gives the compiled path's result.
    from sfw_gym.mapping import k_estimation

    x = np.round(np.random.default_rng(3).choice([-40.0, -55.0, -70.0], 400) + 2.0)
    expected = fit_levels(x, 3, 7.0, 0.02)
    real = k_estimation._fit_levels_1d
    monkeypatch.setattr(k_estimation, "_fit_levels_1d", lambda *a: (2, *real(*a)[1:]))
    got = fit_levels(x, 3, 7.0, 0.02)
    np.testing.assert_array_equal(got[0], expected[0])
    assert got[1] == expected[1]


def estimator_state(est):
    return [
        a.copy()
        for a in (est._thresholds, est._n_thr, est._fit_range, est._fitted, est._next_refit)
    ] + [est._novel.copy(), est.n_refits, est.last_k]


@pytest.mark.parametrize(
    "config",
    [
        MapperConfig(refit_min_samples=16),
        MapperConfig(refit_min_samples=16, k_estimator="kmeans", min_level_fraction=0.1),
        MapperConfig(k_estimator="distance_aware", k0_level_dbm=K0, refit_max_interval=50),
        MapperConfig(min_cluster_gap_db=0.0, max_k=5, fit_buffer_size=64, refit_growth=1.1),
    ],
    ids=["default", "kmeans", "calibrated", "small_buffer"],
)
def test_compiled_refit_equals_the_python_refit_to_the_bit(config):
    # Three routers (one never heard, one at a single level most of the time), through every
    # scheduled and forced refit: the compiled loop and the Python one leave the same state.
    rssi, d = survey_readings(1500, seed=4)
    rng = np.random.default_rng(4)
    est_new, est_old = KEstimator(3, config), KEstimator(3, config)
    est_old.refit = est_old._refit_python  # the per-router Python loop through fit_levels
    for i in range(1500):
        r = np.array([-100.0, -50.0 - 10.0 * (i % 97 == 0), rssi[i]])
        dist = np.array([1.0, 2.0 + rng.uniform(0, 3), d[i]])
        est_new.update(r, dist)
        est_old.update(r, dist)
        if i % 500 == 499:
            est_new.refit(force=True)
            est_old.refit(force=True)
        for a, b in zip(estimator_state(est_new), estimator_state(est_old), strict=True):
            np.testing.assert_array_equal(a, b)
    assert est_new.n_refits > 10


def test_compiled_refit_hands_tied_routers_to_the_python_fit(monkeypatch):
    # A router flagged by the compiled loop (tied centroids) keeps the schedule the loop gave it
    # and is fitted by _fit_router instead. Forced here on every router the loop fitted (its
    # writes undone): the same state as the plain compiled run.
    from sfw_gym.mapping import k_estimation

    rssi, d = survey_readings(400, seed=6)
    real = k_estimation._refit_routers

    def flag_all(*args):
        outputs = args[16:20]  # thresholds, n_thr, fit_range, fitted
        saved = [a.copy() for a in outputs]
        next_refit = args[14].copy()
        real(*args)
        for a, b in zip(outputs, saved, strict=True):
            a[...] = b
        fallback = args[20]
        fallback[:] = args[14] != next_refit
        return 0, int(fallback.sum())

    out = []
    for patched in (False, True):
        if patched:
            monkeypatch.setattr(k_estimation, "_refit_routers", flag_all)
        est = KEstimator(2, MapperConfig(refit_min_samples=16))
        calls = []
        real_fit = est._fit_router
        est._fit_router = lambda r, calls=calls, real_fit=real_fit: (calls.append(r), real_fit(r))
        for i in range(400):
            est.update([rssi[i], rssi[i] + 3.0 if i % 3 else -100.0], [d[i], d[i]])
        out.append(estimator_state(est))
        assert bool(calls) == patched and set(calls) <= {0, 1}
    for a, b in zip(*out, strict=True):
        np.testing.assert_array_equal(a, b)
    assert out[1][6] > 10
