"""WiFi localisation on Gaussian gridmaps: surveys, GP models, gridmaps, Monte-Carlo
localisation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sfw_gym.core.errors import ConfigError
from sfw_gym.localization import (
    GaussianGridmaps,
    MclConfig,
    SignalModel,
    Survey,
    WifiMCL,
    log_likelihood,
    low_variance_indices,
    normalise_rssi,
)

APS = np.array([[1.0, 1.0], [9.0, 2.0], [5.0, 9.0], [1.0, 8.0], [9.0, 9.0]])


def field(xy: np.ndarray) -> np.ndarray:
    """A smooth signal per AP in [0, 1]: strongest at the AP, falling off with distance."""
    d = np.linalg.norm(xy[:, None, :] - APS[None], axis=2)
    return 0.8 * np.exp(-d / 4.0)


def test_rssi_is_normalised_as_the_paper_does():
    np.testing.assert_allclose(normalise_rssi([0, -50, -100, -120, np.nan]), [1, 0.5, 0, 0, 0])


def test_binning_averages_the_readings_of_each_cell():
    survey = Survey([[0.1, 0.1], [0.2, 0.2], [1.1, 0.1]], [[0.2, 0.0], [0.4, 0.0], [0.6, 0.6]])
    binned = survey.binned(1.0)
    np.testing.assert_allclose(binned.positions, [[0.15, 0.15], [1.1, 0.1]])
    np.testing.assert_allclose(binned.signals, [[0.3, 0.0], [0.6, 0.6]])
    with pytest.raises(ConfigError, match="positions"):
        Survey(np.zeros((3, 3)), np.zeros((3, 2)))


def test_a_survey_reads_from_csv_and_a_bad_one_is_named(tmp_path):
    path = tmp_path / "survey.csv"
    path.write_text("x,y,ap_a,ap_b\n0,0,-50,\n1,2,-100,-30\n")
    survey = Survey.from_csv(path)
    np.testing.assert_allclose(survey.positions, [[0, 0], [1, 2]])
    np.testing.assert_allclose(survey.signals, [[0.5, 0.0], [0.0, 0.7]])
    path.write_text("x,y,ap_a\n0,0,-50\n1,oops,-40\n")
    with pytest.raises(ConfigError, match=r"survey\.csv:3: y is not a number"):
        Survey.from_csv(path)
    path.write_text("a,b,c\n1,2,3\n")
    with pytest.raises(ConfigError, match="header is x, y"):
        Survey.from_csv(path)


@pytest.fixture(scope="module")
def survey() -> Survey:
    rng = np.random.default_rng(0)
    xy = rng.uniform(0, 10, (300, 2))
    z = field(xy) + rng.normal(0, 0.02, (300, len(APS)))
    z[xy[:, 0] > 6, 0] = 0.0  # AP 0 unheard on the right: as far away indoors
    return Survey(xy, np.clip(z, 0, 1))


@pytest.fixture(scope="module")
def models(survey):
    return SignalModel(survey, per_ap=True), SignalModel(survey, per_ap=False)


@pytest.mark.episode
def test_gp_models_learn_the_signal_field(models):
    test = np.random.default_rng(1).uniform(1, 9, (200, 2))
    truth = field(test)
    for model in models:
        mean, var = model.predict(test)
        assert mean.shape == var.shape == (200, len(APS)) and (var > 0).all()
        assert np.abs(mean[:, 1:] - truth[:, 1:]).mean() < 0.03
    # where AP 0 was unheard, mGP (trained only where heard) keeps to the field; the single GP
    # (unheard as 0) is pulled down toward 0 near the boundary
    left = test[:, 0] < 5
    mgp, gp = (np.abs(m.predict(test)[0][left, 0] - truth[left, 0]).mean() for m in models)
    assert mgp < gp


@pytest.mark.episode
def test_gridmaps_store_the_direct_prediction_at_cell_centres(models):
    mgp = models[0]
    maps = GaussianGridmaps.from_model(mgp, (0, 0, 10, 10), 0.5)
    assert maps.shape == (20, 20) and maps.memory_bytes == 2 * 5 * 20 * 20 * 8
    centres = maps.cell_centres()
    direct_mean, direct_var = mgp.predict(centres)
    mean, var = maps.lookup(centres)
    np.testing.assert_allclose(mean, direct_mean)
    np.testing.assert_allclose(var, direct_var)
    # a point anywhere in a cell reads that cell (Eq. 11, rows from the top)
    row, col = maps.cells(np.array([[0.1, 0.1], [9.9, 9.9], [2.6, 7.4]]))
    assert row.tolist() == [19, 0, 5] and col.tolist() == [0, 19, 5]
    u8 = GaussianGridmaps.from_model(mgp, (0, 0, 10, 10), 0.5, "uint8")
    assert u8.memory_bytes == maps.memory_bytes // 8 and u8.variance.min() >= 1
    m8, v8 = u8.lookup(centres)
    assert np.abs(m8 - direct_mean).max() <= 0.5 / 255 + 1e-12
    assert np.abs(v8 - direct_var).max() <= np.max(u8.variance_scale) / 255
    mixed = GaussianGridmaps.from_model(mgp, (0, 0, 10, 10), 0.5, ("uint8", "float64"))
    m, v = mixed.lookup(centres)
    np.testing.assert_array_equal(m, m8)
    np.testing.assert_allclose(v, direct_var)


@pytest.mark.episode
def test_gridmaps_round_trip_through_npz(tmp_path, models):
    maps = GaussianGridmaps.from_model(models[1], (0, 0, 10, 10), 1.0, "float16")
    loaded = GaussianGridmaps.load(maps.save(tmp_path / "maps.npz"))
    np.testing.assert_array_equal(loaded.mean, maps.mean)
    assert loaded.origin_xy == maps.origin_xy and loaded.mean.dtype == np.float16
    (tmp_path / "bad.npz").write_bytes(b"nope")
    with pytest.raises(ConfigError, match=r"bad\.npz: not Gaussian gridmaps"):
        GaussianGridmaps.load(tmp_path / "bad.npz")


def test_the_sensor_model_is_eq_12_13_by_hand():
    z = np.array([0.6, 0.2, 0.0])
    mean, var = np.array([[0.5, 0.1, 0.3]]), np.array([[0.04, 0.01, 0.5]])
    lam = [0.75, 0.25]  # the unheard AP weighs nothing
    by_hand = sum(
        w * math.log(math.exp(-((zj - m) ** 2) / (2 * v)) / math.sqrt(2 * math.pi * v))
        for w, zj, m, v in zip(lam, z[:2], mean[0, :2], var[0, :2], strict=True)
    )
    assert log_likelihood(z, mean, var)[0] == pytest.approx(by_hand)


def test_low_variance_resampling_follows_the_weights():
    rng = np.random.default_rng(0)
    assert set(low_variance_indices(np.array([0.0, 1.0, 0.0]), 50, rng).tolist()) == {1}
    counts = np.bincount(low_variance_indices(np.array([0.25, 0.75]), 100, rng), minlength=2)
    assert counts.tolist() == [25, 75]  # systematic: exact to one particle


def synthetic_maps(resolution: float = 0.25) -> GaussianGridmaps:
    n = int(10 / resolution)
    centres = (np.arange(n) + 0.5) * resolution
    gx, gy = np.meshgrid(centres, centres[::-1])
    mean = field(np.column_stack([gx.ravel(), gy.ravel()])).T.reshape(-1, n, n)
    var = np.full_like(mean, 0.02**2 + 0.01)
    return GaussianGridmaps.quantised(mean, var, (0, 0), resolution, np.ones(len(APS)), "float64")


def drive(mcl: WifiMCL, path: np.ndarray, rng: np.random.Generator, kidnap_at: int | None = None):
    """Readings from the true ``path`` (noisy), odometry increments from it; the error per step."""
    errors = []
    for k in range(1, len(path)):
        a, b = path[k - 1], path[k]
        d = b[:2] - a[:2]
        c, s = math.cos(a[2]), math.sin(a[2])
        delta = (c * d[0] + s * d[1], -s * d[0] + c * d[1], b[2] - a[2])
        if kidnap_at is not None and k == kidnap_at:
            delta = (0.0, 0.0, 0.0)  # carried away: odometry saw nothing
        mcl.predict(delta)
        z = np.clip(field(b[None, :2])[0] + rng.normal(0, 0.02, len(APS)), 0, 1)
        mcl.update(-100 + 100 * z)
        errors.append(float(np.hypot(*(mcl.estimate()[0][:2] - b[:2]))))
    return np.array(errors)


def loop_path(n: int, centre=(5.0, 5.0), radius=3.0) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, n)
    return np.column_stack(
        [centre[0] + radius * np.cos(t), centre[1] + radius * np.sin(t), t + np.pi / 2]
    )


def test_global_localisation_finds_the_robot_from_one_reading():
    rng = np.random.default_rng(2)
    mcl = WifiMCL(synthetic_maps(), MclConfig(particles=1000), rng)
    path = loop_path(120)
    z0 = np.clip(field(path[:1, :2])[0] + rng.normal(0, 0.02, len(APS)), 0, 1)
    mcl.global_init(-100 + 100 * z0)
    errors = drive(mcl, path, rng)
    assert errors[:5].min() < 1.0 and errors[10:].mean() < 0.5


def test_a_kidnapped_robot_is_found_again():
    rng = np.random.default_rng(3)
    mcl = WifiMCL(synthetic_maps(), MclConfig(particles=1000), rng)
    path = loop_path(80)
    mcl.init_at(path[0])
    assert drive(mcl, path, rng)[-10:].mean() < 0.5
    elsewhere = loop_path(80, centre=(3.0, 3.0), radius=1.5)  # carried 4.3 m away
    errors = drive(mcl, np.vstack([path[-1:], elsewhere]), rng, kidnap_at=1)
    assert errors[0] > 2.0  # lost at first
    assert errors[-20:].mean() < 0.7  # found again


@pytest.mark.episode
def test_mcl_on_direct_gp_prediction_tracks_like_on_its_gridmaps(models):
    mgp = models[0]
    maps = GaussianGridmaps.from_model(mgp, (0, 0, 10, 10), 0.25)
    path = loop_path(60)
    for direct in (None, mgp):
        rng = np.random.default_rng(4)
        mcl = WifiMCL(maps, MclConfig(particles=300), rng, direct=direct)
        mcl.init_at(path[0])
        assert drive(mcl, path, rng)[10:].mean() < 0.6


@pytest.mark.episode
def test_a_path_loss_mean_extrapolates_where_the_zero_mean_falls_to_zero():
    """Our option: surveyed on the left half only, predicted on the right half of a log-distance
    field; the zero mean decays toward 0 away from the data, the fitted curves follow it."""
    aps = APS

    def log_field(xy):
        d = np.maximum(np.linalg.norm(xy[:, None, :] - aps[None], axis=2), 0.5)
        return np.clip((-30 - 25 * np.log10(d / 0.5) + 100) / 100, 0, 1)

    rng = np.random.default_rng(0)
    xy = rng.uniform(0, 5, (200, 2)) * [1, 2]
    survey = Survey(xy, np.clip(log_field(xy) + rng.normal(0, 0.02, (200, len(aps))), 0, 1))
    right = rng.uniform([6, 0], [10, 10], (200, 2))
    errors = {
        mean: np.abs(SignalModel(survey, mean=mean).predict(right)[0] - log_field(right)).mean()
        for mean in ("zero", "path_loss")
    }
    assert errors["path_loss"] < 0.5 * errors["zero"]  # measured 0.013 vs 0.062
    with pytest.raises(ConfigError, match="mean must be one of"):
        SignalModel(survey, mean="linear")
