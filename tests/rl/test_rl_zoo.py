"""rl-baselines3-zoo reads the shipped hyperparameters and agents as they are: ``python -m
rl_zoo3.train`` trains from ``agents/hyperparams/ppo.yml`` (custom policy and ``env_wrapper``
imported from their YAML strings) and ``python -m rl_zoo3.enjoy`` replays the shipped
``agents/ppo`` folder and a run of ``sfw-gym train`` (the README's commands).

rl_zoo3 comes with the ``zoo`` extra (``pip install 'sfw-gym[zoo]'``; CI installs it); without
it these tests are skipped.
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import pytest
import yaml

REPO = Path(__file__).resolve().parents[2]

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(
        importlib.util.find_spec("rl_zoo3") is None,
        reason="rl_zoo3 is not installed (pip install 'sfw-gym[zoo]'; CI installs it)",
    ),
]


@pytest.fixture(scope="module", autouse=True)
def rl_zoo3():
    """rl_zoo3 itself, importable with what its train and enjoy import."""
    try:
        import rl_zoo3
        import rl_zoo3.enjoy
        import rl_zoo3.train
    except ImportError as exc:
        pytest.skip(f"rl_zoo3 is installed but cannot be imported: {exc}")
    return rl_zoo3


def zoo(*argv: str, code: str | None = None) -> str:
    """Run ``python -m rl_zoo3.<argv[0]> argv[1:]`` (or ``python -c code argv``) in the checkout
    (``agents`` is the shipped folder there) on one torch thread; its output, checked."""
    cmd = [sys.executable, "-m", f"rl_zoo3.{argv[0]}", *argv[1:]]
    if code is not None:
        cmd = [sys.executable, "-c", code, *argv]
    proc = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return proc.stdout


def episodes(log_dir: Path) -> list[list[str]]:
    """The episodes (return, length, time) in the Monitor log that enjoy's --reward-log writes."""
    (csv,) = log_dir.glob("*.monitor.csv")
    return [line.split(",") for line in csv.read_text().splitlines()[2:]]


COMMON = ["--gym-packages", "sfw_gym", "--num-threads", "1", "--seed", "0"]


@pytest.mark.parametrize(
    ("env_id", "budget", "overrides", "policy", "policy_class"),
    [
        (
            "SfW-ExploreSmall-v0",
            "64",
            [],
            "MultiInputPolicy",
            "stable_baselines3.common.policies.MultiInputActorCriticPolicy",
        ),
        # the shipped block: WheelsPolicy by its dotted path, on the unwrapped env (one short
        # rollout instead of the block's 16 x 256 steps)
        (
            "SfW-Explore-v0",
            "16",
            ["--hyperparams", "n_envs:1", "n_steps:16", "batch_size:16", "n_epochs:1"],
            "sfw_gym.rl.wheels_policy.WheelsPolicy",
            "sfw_gym.rl.wheels_policy.WheelsPolicy",
        ),
    ],
    ids=["small", "wheels-block"],
)
def test_rl_zoo_trains_from_the_shipped_hyperparameters(
    tmp_path, env_id, budget, overrides, policy, policy_class
):
    from stable_baselines3 import PPO

    conf = "agents/hyperparams/ppo.yml"
    out = zoo(
        "train", "--algo", "ppo", "--env", env_id, "--conf-file", conf, "-n", budget,
        "--eval-freq", "-1", "-f", str(tmp_path), *COMMON, *overrides,
    )  # fmt: skip
    run = tmp_path / "ppo" / f"{env_id}_1"
    assert f"Log path: {run}" in out
    model = PPO.load(run / f"{env_id}.zip", device="cpu")
    assert model.num_timesteps >= int(budget)
    assert f"{type(model.policy).__module__}.{type(model.policy).__name__}" == policy_class
    saved = yaml.unsafe_load((run / env_id / "config.yml").read_text())  # rl-zoo's OrderedDict
    assert saved["policy"] == policy
    assert isinstance(model.action_space, gym.spaces.Box)  # the env's own wheel commands


def test_rl_zoo_enjoy_replays_the_shipped_agent(tmp_path):
    """The shipped wheels policy, found by rl-zoo as the latest ``ppo`` run of the env
    (``agents/ppo/SfW-Explore-v0_2``) and loaded with no custom unpickler, on the env its saved
    config makes: ActionRepeat around the env with the training's kwargs (600-step episodes;
    rl-zoo knows nothing of sfw-gym's curriculum). 300 decisions: two whole episodes."""
    out = zoo(
        "enjoy", "--algo", "ppo", "--env", "SfW-Explore-v0", "-f", "agents", "-n", "300",
        "--no-render", "--device", "cpu", "--reward-log", str(tmp_path), *COMMON,
    )  # fmt: skip
    assert "Loading agents/ppo/SfW-Explore-v0_2/SfW-Explore-v0.zip" in out
    assert [int(e[1]) for e in episodes(tmp_path)] == [600, 600]  # env steps, 150 decisions each


def test_rl_zoo_enjoy_replays_a_run_of_sfw_gym_train(tmp_path):
    """``sfw-gym train`` writes rl-zoo's layout: enjoy finds the model and builds the env with
    the run's env_kwargs (from its args.yml: episodes of 40 steps, not the env's 1,000)."""
    from sfw_gym.rl.training import train_ppo

    hyper = tmp_path / "ppo.yml"
    hyper.write_text(
        "SfW-ExploreSmall-v0:\n  policy: MultiInputPolicy\n  n_envs: 1\n  n_steps: 32\n"
        "  batch_size: 32\n  n_epochs: 1\n  policy_kwargs: 'dict(net_arch=[8])'\n"
    )
    folder = tmp_path / "logs"
    run = folder / "ppo" / "SfW-ExploreSmall-v0_1"
    train_ppo(
        "SfW-ExploreSmall-v0", 32, run, hyperparams_path=hyper, env_kwargs={"max_steps": 40},
        eval_every=10**6, progress_bar=False,
    )  # fmt: skip
    out = zoo(
        "enjoy", "--algo", "ppo", "--env", "SfW-ExploreSmall-v0", "-f", str(folder), "-n", "85",
        "--no-render", "--device", "cpu", "--reward-log", str(tmp_path / "replay"), *COMMON,
    )  # fmt: skip
    assert f"Loading {run}/SfW-ExploreSmall-v0.zip" in out
    assert [int(e[1]) for e in episodes(tmp_path / "replay")] == [40, 40]


MASKABLE = """
import sys
import rl_zoo3
from sb3_contrib import MaskablePPO

assert "ppo_mask" not in rl_zoo3.ALGOS  # rl-zoo 2.9.2 has no MaskablePPO (the README says so)
rl_zoo3.ALGOS["ppo_mask"] = MaskablePPO
command = sys.argv[1]
sys.argv = [command, *sys.argv[2:]]
if command == "train":
    from rl_zoo3.train import train

    train()
else:
    from rl_zoo3.enjoy import enjoy

    enjoy()
"""


def test_the_maskable_blocks_and_agents_work_in_rl_zoo_once_it_knows_maskable_ppo(tmp_path):
    """ppo_mask.yml holds nothing rl-zoo would hand MaskablePPO by mistake (cloning and
    fine-tuning are in its sfw_gym block), and the shipped ppo_mask folders are in rl-zoo's
    layout: with MaskablePPO added to rl-zoo's algorithms, train and enjoy run on them."""
    env = "SfW-ExploreGoals-v0"
    conf = "agents/hyperparams/ppo_mask.yml"
    small = ["n_envs:1", "n_steps:8", "batch_size:8", "n_epochs:1"]
    out = zoo(
        "train", "--algo", "ppo_mask", "--env", env, "--conf-file", conf, "-n", "8",
        "--eval-freq", "-1", "-f", str(tmp_path), *COMMON, "--hyperparams", *small, code=MASKABLE,
    )  # fmt: skip
    assert (tmp_path / "ppo_mask" / f"{env}_1" / f"{env}.zip").is_file(), out
    out = zoo(
        "enjoy", "--algo", "ppo_mask", "--env", "SfW-ExploreRegions-v0", "-f", "agents",
        "-n", "5", "--no-render", "--device", "cpu", *COMMON, code=MASKABLE,
    )  # fmt: skip
    assert "Loading agents/ppo_mask/SfW-ExploreRegions-v0_1/SfW-ExploreRegions-v0.zip" in out
