"""RSSI -> k estimation: thresholds, filter, schedule, prior, calibration, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from sfw_gym.errors import ConfigError
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
