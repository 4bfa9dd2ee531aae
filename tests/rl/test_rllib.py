"""RLlib training (``sfw-gym train ppo --backend rllib``, where ``ray[rllib]`` is installed; CI
runs these in its Ray venv): it learns, resumes, masks, and without Ray says how to get it."""

from __future__ import annotations

import importlib.util

import gymnasium as gym
import numpy as np
import pytest

from sfw_gym.cli import main

HAS_RLLIB = importlib.util.find_spec("ray") is not None
needs_rllib = pytest.mark.skipif(not HAS_RLLIB, reason="needs Ray (pip install 'sfw-gym[ray]')")
SMALL = "SfW-ExploreSmall-v0"
HELD_OUT = list(range(500, 510))


@pytest.mark.skipif(HAS_RLLIB, reason="Ray is installed here")
def test_without_ray_the_rllib_backend_is_one_line_naming_the_extra(tmp_path, capsys):
    argv = ["train", "ppo", "--env", SMALL, "--backend", "rllib", "--out", str(tmp_path)]
    assert main([*argv, "--timesteps", "100", "--no-progress"]) == 2
    assert "pip install 'sfw-gym[ray]'" in capsys.readouterr().err


def test_rllib_options_without_the_rllib_backend_are_refused(tmp_path, capsys):
    argv = ["train", "ppo", "--env", SMALL, "--num-env-runners", "2", "--out", str(tmp_path)]
    assert main(argv) == 2
    assert "--backend rllib" in capsys.readouterr().err


def _random_returns(seeds: list[int]) -> list[float]:
    returns = []
    for seed in seeds:
        env = gym.make(SMALL, collision_penalty=0.0)
        env.reset(seed=seed)
        env.action_space.seed(seed)
        total, done = 0.0, False
        while not done:
            _, reward, terminated, truncated, _ = env.step(env.action_space.sample())
            total, done = total + float(reward), terminated or truncated
        returns.append(total)
    return returns


@needs_rllib
def test_rllib_ppo_beats_random_actions_after_five_iterations(tmp_path):
    from sfw_gym.rl.rllib import greedy_returns, read_progress

    out = tmp_path / "run"
    argv = ["train", "ppo", "--env", SMALL, "--backend", "rllib", "--out", str(out)]
    assert main([*argv, "--timesteps", str(5 * 2048), "--no-progress"]) == 0
    progress = read_progress(out / "progress.csv")
    assert [int(r["iteration"]) for r in progress] == [1, 2, 3, 4, 5]
    learned = greedy_returns(out / "model", SMALL, HELD_OUT, {"collision_penalty": 0.0})
    random = _random_returns(HELD_OUT)
    # paired on the same held-out plans: about 0.74 against 0.43 when measured
    assert np.mean(learned) > np.mean(random), (learned, random)


TINY = """
SfW-ExploreSmall-v0:
  n_envs: 2
  env_kwargs: {max_steps: 40}
  n_steps: 32
  batch_size: 32
  n_epochs: 1
"""


@needs_rllib
def test_a_resumed_rllib_run_continues_from_its_last_checkpoint_with_runners(tmp_path):
    from ray.rllib.core.rl_module.rl_module import RLModule

    from sfw_gym.rl.rllib import latest_rllib_checkpoint, read_progress, train_rllib

    hyperparams = tmp_path / "tiny.yml"
    hyperparams.write_text(TINY)
    out = tmp_path / "run"
    run = dict(hyperparams_path=hyperparams, checkpoint_every=64, progress_bar=False)
    # one Ray runner: the plain id must be found in a process that never imported sfw_gym
    first = train_rllib(SMALL, 128, out, num_env_runners=1, **run)
    assert first["iterations"] == 2 and latest_rllib_checkpoint(out)[1] == 2
    (out / "progress.csv").open("a").write("3,192,0.5,0.1\n")  # an iteration past the checkpoint
    resumed = train_rllib(SMALL, 192, out, num_env_runners=1, resume=True, **run)
    assert resumed["iterations"] == 3 and resumed["steps"] == 192
    rows = read_progress(out / "progress.csv")
    assert [(int(r["iteration"]), int(r["env_steps"])) for r in rows] == [
        (1, 64),
        (2, 128),
        (3, 192),
    ]

    def weights(path):
        module = RLModule.from_checkpoint(
            str(path / "learner_group" / "learner" / "rl_module" / "default_policy")
        )
        return {k: v.detach().numpy().copy() for k, v in module.state_dict().items()}

    # the resumed run started from iteration 2's weights and trained them further
    second, third = weights(out / "checkpoints" / "iter_000002"), weights(out / "model")
    assert any(not np.array_equal(second[k], third[k]) for k in second)
    assert not list(out.rglob(".*.tmp*"))


@needs_rllib
def test_the_module_never_picks_a_masked_candidate_goal():
    import torch
    from ray.rllib.core.columns import Columns

    from sfw_gym.rl.rllib_module import MASK_KEY, DictObsModule

    env = gym.make("SfW-ExploreGoals-v0")
    module = DictObsModule(
        observation_space=env.observation_space,
        action_space=env.action_space,
        model_config={"hidden": 16},
    )
    obs, _ = env.reset(seed=3)
    batch = {k: torch.as_tensor(np.repeat(np.asarray(v)[None], 4, axis=0)) for k, v in obs.items()}
    batch[MASK_KEY][:] = 0
    batch[MASK_KEY][:, [2, 5]] = 1
    logits = module.forward_exploration({Columns.OBS: batch})[Columns.ACTION_DIST_INPUTS]
    dist = module.get_exploration_action_dist_cls().from_logits(logits)
    picks = torch.stack([dist.sample() for _ in range(200)]).unique().tolist()
    assert set(picks) <= {2, 5}
    values = module.compute_values({Columns.OBS: batch})
    assert values.shape == (4,)


@needs_rllib
def test_the_rl_zoo_block_maps_onto_rllibs_ppo_config():
    from sfw_gym.rl.rllib import ppo_config
    from sfw_gym.rl.rllib_module import DictObsModule

    params = {
        "policy": "MultiInputPolicy",  # an SB3 name: the Dict-observation module instead
        "n_envs": 2,
        "n_steps": 64,
        "batch_size": 256,
        "n_epochs": 3,
        "gae_lambda": 0.9,
        "learning_rate": 1e-3,
        "policy_kwargs": {"net_arch": {"pi": [32], "vf": [32]}},
    }
    config = ppo_config(SMALL, params, num_env_runners=2, seed=5)
    assert config.train_batch_size_per_learner == 128  # one SB3 rollout: n_steps x n_envs
    assert config.minibatch_size == 128  # never above the batch
    assert (config.num_epochs, config.lambda_, config.lr) == (3, 0.9, 1e-3)
    assert config.num_envs_per_env_runner == 1 and config.seed == 5
    assert config.gym_env_vectorize_mode == "vector_entry_point"  # the native vector env
    wrapped = {**params, "env_wrapper": [{"sfw_gym.envs.waypoint.WaypointWrapper": {}}]}
    assert ppo_config(SMALL, wrapped).gym_env_vectorize_mode == "sync"
    spec = config.rl_module_spec
    assert spec.module_class is DictObsModule and spec.model_config == {"hidden": 32}


@needs_rllib
def test_rllibs_runners_step_the_native_vector_env(tmp_path):
    """``gym_env_vectorize_mode="vector_entry_point"``: a runner's envs are sfw_gym's native
    vector env, and an iteration trains on it."""
    import ray

    from sfw_gym.envs.vector import SfWVectorEnv
    from sfw_gym.rl.rllib import ppo_config, register_rllib_envs

    params = {"n_envs": 2, "n_steps": 32, "batch_size": 32, "n_epochs": 1}
    ray.init(num_cpus=1, include_dashboard=False, log_to_driver=False)
    try:
        register_rllib_envs()
        algo = ppo_config(SMALL, params, env_kwargs={"max_steps": 40}).build_algo()
        vec = algo.env_runner.env.unwrapped
        assert isinstance(vec, SfWVectorEnv) and vec.num_envs == 2 and vec._batched
        assert algo.train()["env_runners"]["num_env_steps_sampled_lifetime"] >= 64
        algo.stop()
    finally:
        ray.shutdown()
