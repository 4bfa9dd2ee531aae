"""Radio model: the formula to 1e-9, walls, cap, shadowing, noise, bad routers."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from shapely.geometry import Polygon

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.core.constants import NOT_HEARD_DBM
from sfw_gym.core.errors import ConfigError
from sfw_gym.world.floorplan import MATERIALS, Floorplan, floorplan_from_polygon
from sfw_gym.world.generator import generate_floorplan
from sfw_gym.world.radio import RadioConfig, RadioModel


def noiseless(**kw) -> RadioConfig:
    return RadioConfig(**kw).noiseless()


def test_line_of_sight_rssi_equals_the_formula(open_hall):
    model = RadioModel(open_hall, [[2.0, 5.0]], noiseless(), np.random.default_rng(0))
    pts = np.array([[12.0, 5.0], [2.0, 9.0], [2.5, 5.0], [17.0, 1.0]])
    d = np.linalg.norm(pts - [2.0, 5.0], axis=1)
    fspl_1m = 20 * math.log10(4 * math.pi * 2.437e9 / 299_792_458.0)
    expected = 20.0 - (fspl_1m + 20.0 * np.log10(np.maximum(d, 1.0)))
    assert fspl_1m == pytest.approx(40.18, abs=0.01)
    np.testing.assert_allclose(model.mean_rssi(pts)[:, 0], expected, rtol=0, atol=1e-9)
    assert model.true_k(pts).tolist() == [[0]] * 4


def test_one_wall_costs_its_loss_and_the_total_is_capped(two_rooms):
    for preset, per_wall in [("default", 10.0), ("thick", 15.0)]:
        cfg = RadioConfig.preset(preset).noiseless()
        model = RadioModel(two_rooms, [[2.0, 2.0]], cfg, np.random.default_rng(0))
        across, free = np.array([[8.0, 2.0]]), np.array([[4.0, 4.5]])
        los = cfg.tx_power_dbm - model.path_loss_db(across)[0, 0]
        assert model.mean_rssi(across)[0, 0] == pytest.approx(los - per_wall, abs=1e-9)
        assert model.true_k(across)[0, 0] == 1 and model.true_k(free)[0, 0] == 0
    # Ten 0.1 m walls in a row: 100 dB of walls, capped at 45 dB.
    ring = [(0, 0)]
    for i in range(10):
        x = 2.0 + 2.0 * i
        ring += [(x, 0), (x, 4), (x + 0.1, 4), (x + 0.1, 0)]
    ring += [(24, 0), (24, 5), (0, 5)]
    comb = floorplan_from_polygon(Polygon(ring))
    model = RadioModel(comb, [[1.0, 2.0]], noiseless(), np.random.default_rng(0))
    far = np.array([[23.0, 2.0]])
    assert model.true_k(far)[0, 0] == 10
    los = 20.0 - model.path_loss_db(far)[0, 0]
    assert model.mean_rssi(far)[0, 0] == pytest.approx(los - 45.0, abs=1e-9)


def test_residential_losses_follow_the_wall_material():
    shell = [(0, 0), (8, 0), (8, 6), (0, 6)]
    pillar = [(3, 2), (4, 2), (4, 3), (3, 3)]  # a glass box in a brick room
    fp = Floorplan(
        Polygon(shell, [pillar]),
        Polygon([(-0.2, -0.2), (8.2, -0.2), (8.2, 6.2), (-0.2, 6.2)]),
        ("brick",) * 4 + ("glass",) * 4,
    )
    cfg = RadioConfig.preset("residential").noiseless()
    model = RadioModel(fp, [[1.0, 2.5]], cfg, np.random.default_rng(0))
    behind = np.array([[7.0, 2.5]])
    assert model.mean_rssi(behind)[0, 0] == pytest.approx(
        20 - model.path_loss_db(behind)[0, 0] - 2.0
    )


def test_shadowing_is_fixed_within_an_episode_and_differs_across_seeds(open_hall):
    pts = np.random.default_rng(1).uniform((0.5, 0.5), (19.5, 9.5), (200, 2))
    cfg = RadioConfig(noise_sigma_db=0.0)
    a = RadioModel(open_hall, [[5.0, 5.0], [15.0, 5.0]], cfg, np.random.default_rng(7))
    again = RadioModel(open_hall, [[5.0, 5.0], [15.0, 5.0]], cfg, np.random.default_rng(7))
    other = RadioModel(open_hall, [[5.0, 5.0], [15.0, 5.0]], cfg, np.random.default_rng(8))
    first = a.mean_rssi(pts)
    np.testing.assert_array_equal(first, a.mean_rssi(pts))  # fixed within the episode
    np.testing.assert_array_equal(first, again.mean_rssi(pts))  # deterministic per seed
    assert np.abs(first - other.mean_rssi(pts)).mean() > 0.5


def test_shadowing_statistics_match_the_config(open_hall):
    """Across episodes: σ ≈ 4 dB at a point; correlation exp(-r/5 m) between points r apart."""
    cfg = RadioConfig(noise_sigma_db=0.0)
    pts = np.array([[10.0, 5.0], [11.0, 5.0], [15.0, 5.0]])
    los = RadioModel(open_hall, [[2.0, 5.0]], cfg.noiseless(), np.random.default_rng(0)).mean_rssi(
        pts
    )
    samples = (
        np.array(
            [
                RadioModel(open_hall, [[2.0, 5.0]], cfg, np.random.default_rng(s)).mean_rssi(pts)[
                    :, 0
                ]
                for s in range(600)
            ]
        )
        - los[:, 0]
    )
    assert samples.std(axis=0) == pytest.approx([4.0] * 3, rel=0.15)
    corr = np.corrcoef(samples.T)
    assert corr[0, 1] == pytest.approx(math.exp(-1 / 5), abs=0.1)
    assert corr[0, 2] == pytest.approx(math.exp(-5 / 5), abs=0.12)


def test_measure_is_integer_noisy_and_reports_not_heard(open_hall):
    cfg = RadioConfig(shadowing_sigma_db=0.0)
    model = RadioModel(open_hall, [[1.0, 5.0]], cfg, np.random.default_rng(3))
    near = np.array([6.0, 5.0])
    readings = np.array([model.measure(near)[0] for _ in range(2000)])
    assert readings.dtype.kind == "i"
    assert readings.mean() == pytest.approx(model.mean_rssi(near)[0, 0], abs=0.15)
    assert readings.std() == pytest.approx(math.hypot(2.0, 1 / math.sqrt(12)), rel=0.1)
    weak = RadioConfig(tx_power_dbm=-40.0, shadowing_sigma_db=0.0, noise_sigma_db=0.0)
    far = RadioModel(open_hall, [[1.0, 5.0]], weak, np.random.default_rng(0))
    assert far.measure(np.array([19.0, 5.0])).tolist() == [NOT_HEARD_DBM]


def test_a_reading_at_floats_is_the_reading_at_a_point(two_rooms):
    """``measure_at(x, y)`` (the env's step) = ``measure_with_k(point)``: the same readings,
    walls and random draws, and the same error for a point that is no number."""
    cfg = RadioConfig(noise_sigma_db=2.0)
    routers = np.array([[1.0, 1.0], [8.0, 3.0]])
    a = RadioModel(two_rooms, routers, cfg, np.random.default_rng(3))
    b = RadioModel(two_rooms, routers, cfg, np.random.default_rng(3))
    for x, y in np.random.default_rng(0).uniform((0.3, 0.3), (9.7, 4.7), (50, 2)).tolist():
        reading, k = a.measure_at(x, y)
        expected, expected_k = b.measure_with_k(np.array([x, y]))
        np.testing.assert_array_equal(reading, expected)
        np.testing.assert_array_equal(k, expected_k)
    with pytest.raises(ConfigError, match="finite"):
        a.measure_at(math.nan, 1.0)


def test_routers_in_walls_or_outside_are_rejected(two_rooms):
    with pytest.raises(ConfigError, match=r"router 1 at \(5\.000, 2\.000\) is inside a wall"):
        RadioModel(two_rooms, [[1.0, 1.0], [5.0, 2.0]])
    with pytest.raises(ConfigError, match="outside the building"):
        RadioModel(two_rooms, [[50.0, 2.0]])
    with pytest.raises(ConfigError, match="shape"):
        RadioModel(two_rooms, [1.0, 2.0])
    with pytest.raises(ConfigError, match="finite"):
        RadioModel(two_rooms, [[np.nan, 2.0]])


def test_config_validation_and_presets():
    assert RadioConfig.preset("thick").wall_loss_db["brick"] == 15.0
    assert RadioConfig.preset("residential").wall_loss_db["drywall"] == 3.0
    assert RadioConfig.preset("default", band="5").d0_loss_db == pytest.approx(46.8, abs=0.1)
    with pytest.raises(ConfigError, match="preset"):
        RadioConfig.preset("swamp")
    with pytest.raises(ConfigError, match="noise_sigma_db"):
        RadioConfig(noise_sigma_db=-1.0)
    with pytest.raises(ConfigError, match="wall_loss_db"):
        RadioConfig(wall_loss_db={"brick": 3.0})
    with pytest.raises(ConfigError, match="tx_power_dbm"):
        RadioConfig(tx_power_dbm=float("nan"))
    assert RadioConfig().to_dict()["wall_loss_db"]["generic"] == 10.0


# -- from the mutation review: formulas at hand-computed points, boundaries, messages ------------
def test_free_space_path_loss_follows_friis():
    from sfw_gym.world.radio import free_space_path_loss_db

    # 20 log10(4π d f / c): 2.4 GHz at 1 m is 40.05 dB; doubling the distance adds 6.02 dB
    assert free_space_path_loss_db(1.0, 2.4) == pytest.approx(40.05, abs=0.01)
    assert free_space_path_loss_db(2.0, 2.4) == pytest.approx(40.05 + 6.02, abs=0.01)
    assert free_space_path_loss_db(1.0, 4.8) == pytest.approx(40.05 + 6.02, abs=0.01)


def test_path_loss_is_log_distance_from_the_reference_distance(open_hall):
    cfg = RadioConfig(path_loss_d0_db=40.0, path_loss_exponent=3.0, reference_distance_m=2.0)
    model = RadioModel(open_hall, [[1.0, 5.0]], cfg.noiseless(), np.random.default_rng(0))
    # 8 m = 4 d0: 40 + 30 log10(4) = 58.06 dB; closer than d0 the loss stays PL(d0)
    pl = model.path_loss_db(np.array([[9.0, 5.0], [2.0, 5.0]]))
    assert pl[:, 0] == pytest.approx([40.0 + 30.0 * math.log10(4.0), 40.0])


def test_a_reading_at_the_sensitivity_is_heard(open_hall):
    base = RadioConfig(shadowing_sigma_db=0.0, noise_sigma_db=0.0)
    probe = RadioModel(open_hall, [[1.0, 5.0]], base, np.random.default_rng(0))
    p = np.array([15.0, 5.0])
    mean = probe.mean_rssi(p)[0, 0]
    # shift the transmit power so that the mean at p is -90.2 dBm: the reading rounds to -90
    cfg = RadioConfig(
        tx_power_dbm=base.tx_power_dbm - (mean + 90.2),
        shadowing_sigma_db=0.0,
        noise_sigma_db=0.0,
        sensitivity_dbm=-90.0,
    )
    model = RadioModel(open_hall, [[1.0, 5.0]], cfg, np.random.default_rng(0))
    assert model.measure(p).tolist() == [-90]


def test_noise_is_drawn_per_router_and_even_below_one_db(open_hall):
    cfg = RadioConfig(shadowing_sigma_db=0.0, noise_sigma_db=0.8)
    model = RadioModel(open_hall, [[1.0, 4.0], [1.0, 6.0]], cfg, np.random.default_rng(1))
    p = np.array([6.0, 5.0])  # equidistant: both routers have the same mean
    mean = model.mean_rssi(p)[0]
    assert mean[0] == pytest.approx(mean[1])
    readings = np.array([model.measure(p) for _ in range(200)])
    assert len(np.unique(readings[:, 0])) > 1  # 0.8 dB of noise changes the rounded reading
    assert (readings[:, 0] != readings[:, 1]).any()  # independent draws per router


def test_a_model_without_an_rng_makes_its_own(open_hall):
    model = RadioModel(open_hall, [[1.0, 5.0]])
    assert model.measure(np.array([3.0, 5.0])).dtype.kind == "i"


def test_shadowing_below_one_db_is_applied(open_hall):
    cfg = RadioConfig(shadowing_sigma_db=0.5, noise_sigma_db=0.0)
    model = RadioModel(open_hall, [[1.0, 5.0]], cfg, np.random.default_rng(2))
    flat = RadioModel(open_hall, [[1.0, 5.0]], cfg.noiseless(), np.random.default_rng(2))
    pts = np.array([[x, 5.0] for x in range(3, 19)], np.float64)
    assert not np.allclose(model.mean_rssi(pts), flat.mean_rssi(pts))


def test_router_and_point_input_checks(open_hall):
    model = RadioModel(open_hall, [[1, 5]])  # integer positions are metres too
    assert model.routers.dtype == np.float64 and model.routers.tolist() == [[1.0, 5.0]]
    for bad in (np.zeros((1, 3)), np.zeros((0, 2))):
        with pytest.raises(ConfigError, match=r"routers must have shape \(R, 2\) with R ≥ 1"):
            RadioModel(open_hall, bad)
    with pytest.raises(ConfigError, match=r"^points must be finite \(got NaN or inf\)$"):
        model.mean_rssi(np.array([np.inf, 1.0]))


def test_router_outside_message(two_rooms):
    with pytest.raises(ConfigError, match=r"\(50\.000, 2\.000\) is outside the building of"):
        RadioModel(two_rooms, [[50.0, 2.0]])


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        (
            {"frequency_ghz": 0.0},
            r"^RadioConfig\.frequency_ghz must be a finite number in \[0\.1, 100\], got 0\.0$",
        ),
        # physical bounds: a 2e9 dBm transmitter would overflow the int32 readings
        ({"tx_power_dbm": 2.1e9}, r"^RadioConfig\.tx_power_dbm must be a finite number in"),
        ({"frequency_ghz": True}, r"^RadioConfig\.frequency_ghz must be a finite number"),
        (
            {"path_loss_d0_db": math.inf},
            r"^RadioConfig\.path_loss_d0_db must be None or a finite number in \[0, 200\], got inf",
        ),
        ({"wall_loss_db": [10.0]}, r"^RadioConfig\.wall_loss_db must map material names to"),
        ({"wall_loss_db": "generic"}, r"^RadioConfig\.wall_loss_db must map material names to"),
    ],
)
def test_config_messages_name_the_field(kwargs, message):
    with pytest.raises(ConfigError, match=message):
        RadioConfig(**kwargs)


def test_wall_losses_need_every_material_once_and_non_negative_numbers():
    losses = dict(RadioConfig().wall_loss_db)
    with pytest.raises(ConfigError, match=r"missing \[\], unknown \['steel'\]"):
        RadioConfig(wall_loss_db=losses | {"steel": 20.0})
    for bad in (-1.0, math.nan, "10"):
        with pytest.raises(
            ConfigError, match=r"^RadioConfig\.wall_loss_db\['glass'\] must be a finite number >= 0"
        ):
            RadioConfig(wall_loss_db=losses | {"glass": bad})
    ok = RadioConfig(wall_loss_db=losses | {"glass": 0, "wood": 0.5})  # zero and small are fine
    assert ok.wall_loss_db["glass"] == 0.0 and ok.wall_loss_db["wood"] == 0.5


def test_config_keeps_a_private_float_copy_of_the_losses():
    losses = dict.fromkeys(RadioConfig().wall_loss_db, 7)
    cfg = RadioConfig(wall_loss_db=losses)
    losses["glass"] = 99
    assert cfg.wall_loss_db["glass"] == 7.0 and type(cfg.wall_loss_db["glass"]) is float
    assert type(cfg.wall_loss_db) is dict


def test_d0_loss_uses_a_configured_value():
    assert RadioConfig(path_loss_d0_db=35.5).d0_loss_db == 35.5


def test_presets_defaults_overrides_and_messages():
    default = RadioConfig.preset()
    assert default.frequency_ghz == 2.437 and set(default.wall_loss_db.values()) == {10.0}
    assert RadioConfig.preset("thick", noise_sigma_db=0.5).noise_sigma_db == 0.5
    with pytest.raises(ConfigError, match=r"unknown radio band '6'; choose one of \['2\.4', '5'\]"):
        RadioConfig.preset(band="6")
    with pytest.raises(ConfigError, match=r"^radio: unknown key 'colour'; valid keys"):
        RadioConfig.preset(colour="red")
    with pytest.raises(
        ConfigError, match=r"unknown key 'noise_sigma'; did you mean 'noise_sigma_db'"
    ):
        RadioConfig.preset(noise_sigma=1.0)


def test_noiseless_removes_shadowing_and_noise():
    cfg = RadioConfig().noiseless()
    assert cfg.shadowing_sigma_db == 0.0 and cfg.noise_sigma_db == 0.0


def test_shadowing_table_covers_the_bounds_and_interpolates_between_nodes():
    from sfw_gym.world.radio import ShadowingField

    f = ShadowingField((2.0, 3.0, 7.2, 5.0), 2, 4.0, 5.0, np.random.default_rng(0))
    assert f.origin.tolist() == [1.5, 2.5]  # one node spacing (0.5 m) below-left of the bounds
    n_r, ny, nx = f.table_db.shape
    assert n_r == 2
    assert f.origin[0] + 0.5 * (nx - 1) >= 7.2 + 0.5 and f.origin[1] + 0.5 * (ny - 1) >= 5.0 + 0.5
    node = f.origin + 0.5 * np.array([3.0, 2.0])  # node (row 2, column 3)
    np.testing.assert_allclose(f(node[None]), f.table_db[None, :, 2, 3])
    halfway = (f.table_db[:, 2, 3] + f.table_db[:, 2, 4]) / 2
    np.testing.assert_allclose(f((node + np.array([0.25, 0.0]))[None])[0], halfway)


def test_shadowing_table_covers_bounds_left_of_and_below_the_origin():
    from sfw_gym.world.radio import ShadowingField

    f = ShadowingField((-4.0, -3.0, 1.2, -1.0), 1, 4.0, 5.0, np.random.default_rng(0))
    _, ny, nx = f.table_db.shape
    assert f.origin.tolist() == [-4.5, -3.5]
    assert f.origin[0] + 0.5 * (nx - 1) >= 1.7 and f.origin[1] + 0.5 * (ny - 1) >= -0.5


def test_a_wall_loss_override_may_name_some_materials_only():
    radio = RadioConfig.preset("residential", wall_loss_db={"glass": 2.0})
    assert radio.wall_loss_db["glass"] == 2.0
    assert (
        radio.wall_loss_db["concrete"] == RadioConfig.preset("residential").wall_loss_db["concrete"]
    )
    with pytest.raises(ConfigError, match=r"unknown \['lava'\]"):
        RadioConfig.preset(wall_loss_db={"lava": 5.0})


def test_one_wall_loss_number_means_every_material():
    """``radio={"wall_loss_db": 12}`` (the shorthand a user types) is 12 dB for every material,
    through the env's keyword, a preset override and the plan's loss query alike."""
    assert RadioConfig(wall_loss_db=12).wall_loss_db == dict.fromkeys(MATERIALS, 12.0)
    assert RadioConfig.preset("residential", wall_loss_db=7.5).wall_loss_db == dict.fromkeys(
        MATERIALS, 7.5
    )
    env = gym.make("SfW-ExploreSmall-v0", radio={"wall_loss_db": 12})
    assert env.unwrapped.config.radio.wall_loss_db == dict.fromkeys(MATERIALS, 12.0)
    env.close()
    for bad in (-1, math.nan, True):
        with pytest.raises(ConfigError, match=r"^RadioConfig\.wall_loss_db must"):
            RadioConfig(wall_loss_db=bad)
    plan = generate_floorplan(3)
    a, b = np.array([[0.5, 0.5]]), np.array([[9.0, 9.0]])
    counts, loss = plan.wall_loss_db(a, b, 12.0)
    assert loss[0] == 12.0 * counts[0]
    assert np.array_equal(plan.wall_loss_db(a, b, dict.fromkeys(MATERIALS, 12.0))[1], loss)


@pytest.mark.parametrize("seed", [0, 1])
def test_the_parallel_path_equals_the_serial_one_point_by_point(seed):
    """From 256 points on the model runs a parallel kernel (chunks of 512): the same mean RSSI
    and k as the serial one, each point read alone (a generated plan: walls, shadowing)."""
    plan = generate_floorplan(seed)
    x0, y0, x1, y1 = plan.bounds
    rng = np.random.default_rng(seed)
    candidates = rng.uniform((x0, y0), (x1, y1), (500, 2))
    routers = candidates[plan.is_free(candidates)][:2]
    model = RadioModel(plan, routers, RadioConfig(), np.random.default_rng(seed))
    pts = rng.uniform((x0, y0), (x1, y1), (1100, 2))  # three chunks of 512
    many_rssi, many_k = model.mean_rssi(pts), model.true_k(pts)
    one = [(model.mean_rssi(p[None]), model.true_k(p[None])) for p in pts]
    np.testing.assert_array_equal(many_rssi, np.concatenate([r for r, _ in one]))
    np.testing.assert_array_equal(many_k, np.concatenate([k for _, k in one]))
    assert many_k.max() >= 1  # walls were crossed
