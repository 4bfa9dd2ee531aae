"""``scripts/studies/wheels_study.py`` and ``scripts/figures/plot_wheels_curve.py``: the figures
the wheels-ppo page quotes, checked against hand-computed cases."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"


def _load(relative: str):
    spec = importlib.util.spec_from_file_location(Path(relative).stem, SCRIPTS / relative)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_return_from_a_record_is_what_the_env_paid():
    """Summed rewards of a real episode equal 0.01 · bits − 0.1 · contact steps of its record."""
    study = _load("studies/wheels_study.py")
    env = gym.make("SfW-ExploreSmall-v0")
    _, info = env.reset(seed=5)
    start, total = info["entropy_bits"], 0.0
    for _ in range(150):  # straight ahead: some mapping, then a wall and contact
        _, reward, terminated, truncated, info = env.step(np.array([1.0, 0.0], np.float32))
        total += reward
        if terminated or truncated:
            break
    record = {
        "info_gain_total_bits": start - info["entropy_bits"],
        "collisions": info["collisions"],
    }
    assert info["collisions"] > 0
    assert study.episode_return(record, 0.01, 0.1) == pytest.approx(total, abs=1e-9)


def test_the_geometric_mean_ratio_of_hand_made_plans():
    study = _load("studies/wheels_study.py")
    reference = np.array([0.5, 0.8, 0.4, 0.6])
    other = reference * np.array([0.5, 2.0, 1.0, 1.0])  # ratios 1/2, 2, 1, 1: geometric mean 1
    mean, low, high = study.geometric_mean_ratio(reference, other)
    assert mean == pytest.approx(1.0) and low < 1.0 < high
    mean, low, high = study.geometric_mean_ratio(reference, 0.6 * reference)  # all alike
    assert mean == low == high == pytest.approx(0.6)
    zero = study.geometric_mean_ratio(np.array([0.5, 0.0]), np.array([0.25, 0.3]))
    assert zero[0] == pytest.approx(0.5)  # the plan with a zero is left out


def test_tenths_take_the_first_and_last_tenth_of_the_evaluations():
    curve = _load("figures/plot_wheels_curve.py")
    rows = [
        {"steps": s, "episode": e, "return": float(s) + e, "coverage": 0.0}
        for s in range(1, 21)  # 20 evaluations: a tenth is 2 of them
        for e in range(2)
    ]
    (m0, lo0, hi0), (m1, lo1, _) = curve.tenths(rows, "return")
    assert m0 == pytest.approx(np.mean([1, 2, 2, 3]))  # steps 1 and 2, episodes 0 and 1
    assert m1 == pytest.approx(np.mean([19, 20, 20, 21]))
    sd = np.std([1, 2, 2, 3], ddof=1)
    from scipy import stats

    half = stats.t.ppf(0.975, 3) * sd / math.sqrt(4)
    assert hi0 - m0 == pytest.approx(half) and m0 - lo0 == pytest.approx(half)
    assert lo1 > hi0


def test_the_curve_evaluates_every_nth_checkpoint_back_from_the_last_and_the_first():
    curve = _load("figures/plot_wheels_curve.py")
    assert curve.every_nth(list(range(10)), 3) == [0, 3, 6, 9]
    assert curve.every_nth(list(range(9)), 3) == [0, 2, 5, 8]  # the first, where it starts
    assert curve.every_nth(list(range(4)), 1) == [0, 1, 2, 3]
    assert curve.every_nth([], 3) == []


def test_the_training_diagnostics_average_each_tenth_of_the_updates(tmp_path):
    """A TensorBoard log of 20 updates: the rows give the mean of the first 2, the middle 2 and
    the last 2 values of each logged quantity."""
    from torch.utils.tensorboard import SummaryWriter

    curve = _load("figures/plot_wheels_curve.py")
    run = tmp_path / "run"
    writer = SummaryWriter(str(run / "tb" / "ppo_1"))
    for step in range(20):
        writer.add_scalar("train/approx_kl", float(step), step)
        writer.add_scalar("train/grad_norm_actor", 2.0 * step, step)
    writer.close()
    rows = curve.training_diagnostics(run)
    assert rows == [
        "| run | approx_kl | 0.5 | 9.5 | 18.5 |",
        "| run | grad_norm_actor | 1 | 19 | 37 |",
    ]
