"""PPO training: hyperparameters, and a run killed mid-way resumes from its checkpoint."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
import types
from pathlib import Path

import numpy as np
import pytest

from sfw_gym.core.errors import ConfigError
from sfw_gym.rl.training import (
    DEFAULT_HYPERPARAMS,
    curriculum_stages,
    latest_checkpoint,
    load_hyperparams,
    parse_policy_kwargs,
    train_ppo,
)

TINY = {"max_steps": 40}
SMALL_ID = "SfW-ExploreSmall-v0"


def test_hyperparams_load_for_every_block():
    params = load_hyperparams("SfW-Explore-v0")
    assert params["policy"] == "sfw_gym.rl.wheels_policy.WheelsPolicy"
    assert params["env_wrapper"][0]["sfw_gym.envs.action_repeat.ActionRepeat"]["repeat"] == 4
    assert params["policy_kwargs"]["log_std_init"] == -2.0  # a signed number, parsed
    assert params["curriculum"] == [{"from_timestep": 250_000, "max_steps": 3000}]
    small = load_hyperparams("SfW-ExploreSmall-v0")
    assert small["policy_kwargs"]["net_arch"] == {"pi": [64], "vf": [64]}
    with pytest.raises(ConfigError, match="no hyperparameters"):
        load_hyperparams("CartPole-v1", DEFAULT_HYPERPARAMS)


def test_env_kwargs_in_the_yaml_must_be_a_mapping(tmp_path):
    yml = tmp_path / "bad.yml"
    yml.write_text("SfW-ExploreSmall-v0:\n  env_kwargs: [1, 2]\n")
    with pytest.raises(ConfigError, match="env_kwargs must be a mapping"):
        load_hyperparams("SfW-ExploreSmall-v0", yml)


def test_dagger_rounds_follow_the_cloning_episodes_and_refit_on_everything(monkeypatch):
    from sfw_gym.rl import goal_policy, training

    calls, fits = [], []

    def decisions(env_id, env_kwargs, seeds, learner=None, learner_masked=True, teacher="?"):
        seeds = list(seeds)
        assert teacher == "explore_lite"  # the default teacher
        calls.append((seeds, learner, learner_masked))
        obs = [{"seed": s} for s in seeds]
        return obs, np.array(seeds), np.array([[True, False]] * len(seeds))

    monkeypatch.setattr(goal_policy, "teacher_decisions", decisions)

    def clone(policy, demos, epochs):
        assert len(demos.observations) == len(demos.actions) == len(demos.masks)
        fits.append(([o["seed"] for o in demos.observations], bool(demos.masks.all())))

    monkeypatch.setattr(goal_policy, "behaviour_clone", clone)
    monkeypatch.setattr(goal_policy, "teacher_agreement", lambda *args: 1.0)
    model = types.SimpleNamespace(policy="the policy")
    spec = {"episodes": 2, "epochs": 1, "dagger_rounds": 2, "dagger_episodes": 3}
    training._clone_teacher(model, "X", {}, 10, spec)
    policy = "the policy"
    assert calls == [
        ([10, 11], None, True),
        ([12, 13, 14], policy, True),
        ([15, 16, 17], policy, True),
    ]
    assert fits == [([10, 11], False), (list(range(10, 15)), False), (list(range(10, 18)), False)]
    calls.clear(), fits.clear()
    training._clone_teacher(model, "X", {}, 10, spec, use_masking=False)  # the no-mask ablation
    assert [c[2] for c in calls] == [False] * 3 and all(all_allowed for _, all_allowed in fits)


def test_a_save_killed_midway_leaves_no_checkpoint_under_its_name(tmp_path):
    from sfw_gym.rl.resume import save_checkpoint, state_path

    class Model:  # what a checkpoint takes of an SB3 model
        num_timesteps, _last_obs, _last_episode_starts = 64, None, None
        ep_info_buffer = ep_success_buffer = None

        def save(self, path):
            Path(path).write_bytes(b"PK half a zip")
            raise KeyboardInterrupt  # killed during the save

    class Venv:  # and of its VecMonitor (and the seeds its VecEnv holds for the next reset)
        episode_returns = episode_lengths = episode_count = 0
        venv = types.SimpleNamespace(_seeds=[None], _options=[{}])

        def env_method(self, name):
            return [b"env"]

    path = tmp_path / "checkpoints" / "ppo_64_steps.zip"
    with pytest.raises(KeyboardInterrupt):
        save_checkpoint(Model(), Venv(), Venv(), path)
    assert latest_checkpoint(tmp_path) is None
    # the state went first; the zip, which makes a checkpoint, never arrived, nor a temp file
    assert sorted((tmp_path / "checkpoints").iterdir()) == [state_path(path)]


def test_policy_kwargs_are_parsed_safely():
    assert parse_policy_kwargs("dict(a=[1, 2], b=dict(c=True))") == {"a": [1, 2], "b": {"c": True}}
    with pytest.raises(ConfigError, match="only dict"):
        parse_policy_kwargs("dict(activation_fn=__import__('os').system('true'))")


@pytest.mark.slow
def test_a_run_killed_five_times_ends_with_the_uninterrupted_runs_model(tmp_path):
    """SIGKILL at random points (each after a new checkpoint), resume each time: the final
    model and the held-out evaluations equal those of a run never interrupted."""
    run = dict(n_envs=2, env_kwargs=TINY, checkpoint_every=128, eval_every=256, eval_episodes=2)
    target = 2560
    out = tmp_path / "killed"
    main = tmp_path / "main.py"  # a file: SB3's workers start by forkserver and import it
    main.write_text(
        textwrap.dedent(f"""
            from sfw_gym.rl.training import train_ppo
            if __name__ == "__main__":
                train_ppo("SfW-ExploreSmall-v0", {target}, {str(out)!r}, resume=True,
                          progress_bar=False, **{run!r})
        """)
    )
    rng = np.random.default_rng(5)
    kills, resumed_at = 0, 0
    while True:
        proc = subprocess.Popen([sys.executable, str(main)], start_new_session=True)
        try:
            deadline = time.monotonic() + 240
            while proc.poll() is None and time.monotonic() < deadline:
                found = latest_checkpoint(out)
                if kills < 5 and found and found[1] > resumed_at:
                    time.sleep(rng.uniform(0.0, 1.0))  # somewhere in the next iteration
                    os.killpg(proc.pid, signal.SIGKILL)
                    kills += 1
                    break
                time.sleep(0.1)
        finally:
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
        if proc.returncode == 0:
            break
        assert proc.returncode == -signal.SIGKILL, "training failed on its own"
        resumed_at = latest_checkpoint(out)[1]
    assert kills == 5 and resumed_at < target
    train_ppo("SfW-ExploreSmall-v0", target, tmp_path / "whole", progress_bar=False, **run)
    for name in ("policy.pth", "policy.optimizer.pth"):
        killed, whole = (
            _zip_tensors(tmp_path / d / "SfW-ExploreSmall-v0.zip", name)
            for d in ("killed", "whole")
        )
        assert killed.keys() == whole.keys()
        assert all(torch_equal(killed[k], whole[k]) for k in killed), name
    killed, whole = (
        np.load(tmp_path / d / "eval" / "evaluations.npz") for d in ("killed", "whole")
    )
    assert (
        killed["timesteps"].tolist()
        == whole["timesteps"].tolist()
        == list(range(256, target + 1, 256))
    )
    np.testing.assert_array_equal(killed["results"], whole["results"])
    assert not list(out.rglob(".*.tmp*"))  # no temp file left behind by the kills


def _zip_tensors(path: Path, member: str) -> dict:
    import io
    import zipfile

    import torch

    with zipfile.ZipFile(path) as archive:
        state = torch.load(io.BytesIO(archive.read(member)), weights_only=False)
    flat: dict = {}

    def walk(prefix: str, value) -> None:
        if isinstance(value, dict):
            for k, v in value.items():
                walk(f"{prefix}.{k}", v)
        elif isinstance(value, list | tuple):
            for k, v in enumerate(value):
                walk(f"{prefix}.{k}", v)
        else:
            flat[prefix] = value

    walk("", state)
    return flat


def torch_equal(a, b) -> bool:
    import torch

    if isinstance(a, torch.Tensor):
        return isinstance(b, torch.Tensor) and torch.equal(a, b)
    return a == b


@pytest.mark.episode
def test_maskable_ppo_on_candidate_goals_starts_from_the_frontier_agents_choices(
    tmp_path, monkeypatch
):
    """ppo_mask: behaviour cloning before PPO (the actor already prefers the teacher's choices),
    checkpoints under its own name, and a resumed run continues."""
    import gymnasium as gym
    import numpy as np
    from sb3_contrib import MaskablePPO

    from sfw_gym.agents.frontier import explore_lite_choice
    from tests.envs.test_goals import SMALL

    yml = tmp_path / "ppo_mask.yml"
    yml.write_text(
        "SfW-ExploreGoals-v0:\n"
        "  policy: 'sfw_gym.rl.goal_policy.GoalsPolicy'\n"
        "  env_kwargs: {goals: {cost_per_m_bits: 20.0}, max_steps: 999}\n"
        "  n_steps: 32\n  batch_size: 32\n  n_epochs: 1\n  learning_rate: !!float 1e-5\n"
        "sfw_gym:\n  SfW-ExploreGoals-v0:\n    behaviour_cloning: {episodes: 3, epochs: 30}\n"
    )
    out = tmp_path / "run"
    kwargs = dict(n_envs=1, env_kwargs=SMALL, hyperparams_path=yml, algo="ppo_mask")
    kwargs |= dict(checkpoint_every=32, eval_every=10**9, progress_bar=False)
    from sfw_gym.rl import goal_policy

    logged = []  # the per-head gradient norms are wired in for a policy with separate heads

    class Recorder(goal_policy.HeadGradientNorms):
        def __init__(self):
            super().__init__()
            logged.append(self)

    monkeypatch.setattr(goal_policy, "HeadGradientNorms", Recorder)
    torch = pytest.importorskip("torch")
    torch.set_num_threads(2)
    summary = train_ppo("SfW-ExploreGoals-v0", 32, out, **kwargs)
    assert len(logged) == 1 and logged[0].model is not None
    assert torch.get_num_threads() == 1  # one thread unless told otherwise
    assert summary["algo"] == "ppo_mask" and latest_checkpoint(out, "ppo_mask")[1] == 32
    # the YAML's env_kwargs and the caller's (which win) reach the env; the agent reads them back
    assert summary["env_kwargs"] == {**SMALL, "goals": {"cost_per_m_bits": 20.0}}
    from sfw_gym.rl.agent import PPOAgent

    assert PPOAgent(out).config.cost_per_m_bits == 20.0
    model = MaskablePPO.load(out / "SfW-ExploreGoals-v0.zip")
    env = gym.make("SfW-ExploreGoals-v0", **SMALL)
    agree = []
    for seed in (20, 21):
        obs, _ = env.reset(seed=seed)
        for _ in range(15):
            menu, mask = env.unwrapped.menu, env.unwrapped.action_masks()
            action, _ = model.predict(obs, action_masks=mask, deterministic=True)
            teacher = explore_lite_choice(menu)
            if teacher is not None:
                agree.append(int(action) == teacher)
            obs, _, terminated, truncated, _ = env.step(int(action))
            if terminated or truncated:
                break
    assert np.mean(agree) >= 0.7
    resumed = train_ppo("SfW-ExploreGoals-v0", 64, out, resume=True, **kwargs)
    assert resumed["steps"] == 64 and latest_checkpoint(out, "ppo_mask")[1] == 64


def test_shipped_maskable_hyperparameters_load():
    from sfw_gym.core.data import default_hyperparams

    params = load_hyperparams("SfW-ExploreGoals-v0", default_hyperparams("ppo_mask"))
    assert params["policy"] == "sfw_gym.rl.goal_policy.GoalsPolicy"
    assert params["behaviour_cloning"]["episodes"] > 0  # from the sfw_gym block
    regions = load_hyperparams("SfW-ExploreRegions-v0", default_hyperparams("ppo_mask"))
    assert regions["fine_tuning"]["kl_coef"] > 0 and regions["env_kwargs"] == {"privileged": True}


@pytest.mark.parametrize("algo", ["ppo", "ppo_mask", "rllib_ppo"])
def test_rl_zoo_reads_only_keys_it_knows_in_every_shipped_block(algo):
    """rl-zoo hands every key of an env id's block that it does not pop to the model's
    constructor: sfw-gym's own keys live in the sfw_gym block, which it never reads."""
    import inspect

    import yaml
    from stable_baselines3 import PPO

    from sfw_gym.core.data import default_hyperparams
    from sfw_gym.rl.training import PROJECT_BLOCK, PROJECT_KEYS, zoo_hyperparams

    path = default_hyperparams(algo)
    table = yaml.safe_load(path.read_text(encoding="utf-8"))
    ppo_args = set(inspect.signature(PPO.__init__).parameters)
    popped_by_rl_zoo = {"n_timesteps", "n_envs", "env_wrapper", "env_kwargs"}
    for env_id in set(table) - {PROJECT_BLOCK}:
        block = zoo_hyperparams(env_id, path)
        assert set(block) <= ppo_args | popped_by_rl_zoo, (env_id, set(block) - ppo_args)
        assert not PROJECT_KEYS & set(block)
    for env_id, keys in (table.get(PROJECT_BLOCK) or {}).items():
        assert env_id in table and set(keys) <= PROJECT_KEYS


def test_sfw_gym_keys_outside_their_block_or_unknown_in_it_are_named(tmp_path):
    yml = tmp_path / "ppo_mask.yml"
    yml.write_text(
        f"{SMALL_ID}:\n  policy: MultiInputPolicy\n  behaviour_cloning: {{episodes: 1}}\n"
    )
    with pytest.raises(ConfigError, match=r"\['behaviour_cloning'\] of .* belong in the 'sfw_gym'"):
        load_hyperparams(SMALL_ID, yml)
    yml.write_text(
        f"{SMALL_ID}:\n  policy: MultiInputPolicy\nsfw_gym:\n  {SMALL_ID}:\n    cloning: 1\n"
    )
    with pytest.raises(
        ConfigError, match=r"unknown keys in sfw_gym\.SfW-ExploreSmall-v0: \['cloning'\]"
    ):
        load_hyperparams(SMALL_ID, yml)
    yml.write_text(f"{SMALL_ID}:\n  policy: MultiInputPolicy\nsfw_gym: [1]\n")
    with pytest.raises(ConfigError, match="sfw_gym must map env ids"):
        load_hyperparams(SMALL_ID, yml)
    yml.write_text(f"{SMALL_ID}:\n  policy: MultiInputPolicy\n  n_step: 8\n")
    with pytest.raises(ConfigError, match=r"unknown keys for .*\['n_step'\]"):
        load_hyperparams(SMALL_ID, yml)
    with pytest.raises(ConfigError, match=r"no hyperparameters for 'sfw_gym'"):
        load_hyperparams("sfw_gym", yml)  # the project block is no env's block
    project = f"sfw_gym:\n  {SMALL_ID}:\n    use_masking: false\n"
    yml.write_text(f"{SMALL_ID}:\n  policy: MultiInputPolicy\n{project}")
    assert load_hyperparams(SMALL_ID, yml) == {"policy": "MultiInputPolicy", "use_masking": False}


def test_the_training_curve_draws_other_policies_levels(tmp_path, monkeypatch):
    from matplotlib.axes import Axes

    from sfw_gym.rl.training import plot_training_curve

    (tmp_path / "train_0.monitor.csv").write_text('#{"t_start": 0}\nr,l,t\n1.0,10,1\n2.0,12,2\n')
    drawn = []
    monkeypatch.setattr(Axes, "axhline", lambda ax, y, **kw: drawn.append((y, kw["label"])))
    path = plot_training_curve(tmp_path, levels={"frontier": 12.3, "greedy": 7.9})
    assert path is not None and path.stat().st_size > 0
    assert drawn == [(12.3, "frontier"), (7.9, "greedy")]


@pytest.mark.episode
def test_a_resumed_run_keeps_its_evaluations_and_survives_a_cut_monitor_line(tmp_path):
    from sfw_gym.rl.training import _monitored_seconds

    run = {"n_envs": 1, "env_kwargs": TINY, "checkpoint_every": 64, "eval_every": 64}
    train_ppo("SfW-ExploreSmall-v0", 128, tmp_path, eval_episodes=1, progress_bar=False, **run)
    with (tmp_path / "train_0.monitor.csv").open("a") as fh:
        fh.write("0.71,30,")  # a line cut short by a kill
    stale = tmp_path / "checkpoints" / ".ppo_192_steps.abc.tmp.zip"  # a save cut short by a kill
    stale.write_bytes(b"PK half")
    assert _monitored_seconds(tmp_path) > 0
    train_ppo(
        "SfW-ExploreSmall-v0", 256, tmp_path, eval_episodes=1, resume=True, progress_bar=False,
        **run,
    )  # fmt: skip
    steps = np.load(tmp_path / "eval" / "evaluations.npz")["timesteps"].tolist()
    assert steps == [64, 128, 192, 256]  # the first segment's evaluations are still there
    assert not stale.exists()
    with pytest.raises(ConfigError, match="checkpoint_every must be an integer ≥ 1, got 0"):
        train_ppo("SfW-ExploreSmall-v0", 8, tmp_path / "x", **{**run, "checkpoint_every": 0})


@pytest.mark.episode
def test_a_resume_from_before_the_first_evaluation_evaluates_on_the_same_episodes(tmp_path):
    """The evaluation env has not been reset yet at the first checkpoint: its seed still waits
    for that reset, and a resume must keep it (not draw fresh entropy)."""
    run = {"n_envs": 1, "env_kwargs": TINY, "checkpoint_every": 64, "eval_every": 128}
    train_ppo("SfW-ExploreSmall-v0", 64, tmp_path / "cut", progress_bar=False, **run)
    train_ppo("SfW-ExploreSmall-v0", 256, tmp_path / "cut", resume=True, progress_bar=False, **run)
    train_ppo("SfW-ExploreSmall-v0", 256, tmp_path / "whole", progress_bar=False, **run)
    cut, whole = (np.load(tmp_path / d / "eval" / "evaluations.npz") for d in ("cut", "whole"))
    assert cut["timesteps"].tolist() == whole["timesteps"].tolist() == [128, 256]
    np.testing.assert_array_equal(cut["results"], whole["results"])


@pytest.mark.slow
def test_a_killed_training_leaves_no_env_worker_behind(tmp_path):
    out = tmp_path / "run"
    script = textwrap.dedent(f"""
        from sfw_gym.rl.training import train_ppo
        train_ppo("SfW-ExploreSmall-v0", 100_000, {str(out)!r}, n_envs=2, env_kwargs={TINY!r},
                  checkpoint_every=64, eval_every=10**9, progress_bar=False)
    """)
    proc = subprocess.Popen([sys.executable, "-c", script], start_new_session=True)
    try:
        deadline = time.monotonic() + 240
        while not latest_checkpoint(out) and time.monotonic() < deadline:
            assert proc.poll() is None, "training ended before it was killed"
            time.sleep(0.5)
    finally:
        proc.send_signal(signal.SIGKILL)  # the trainer only (SB3's workers exit on the closed pipe)
        proc.wait()
    deadline = time.monotonic() + 15
    while time.monotonic() < deadline:
        try:
            os.killpg(proc.pid, 0)
        except ProcessLookupError:
            return
        time.sleep(0.2)
    pytest.fail("a worker outlived its killed training")


def test_the_budget_is_the_yamls_n_timesteps_unless_given(tmp_path):
    from sfw_gym.rl.training import resolve_timesteps

    assert resolve_timesteps(None, {"n_timesteps": 1e5}, "X") == 100_000  # rl-zoo's float
    assert resolve_timesteps(None, {"n_timesteps": "2e3"}, "X") == 2_000  # YAML without !!float
    assert resolve_timesteps(64, {"n_timesteps": 1e5}, "X") == 64
    with pytest.raises(ConfigError, match="set no n_timesteps"):
        resolve_timesteps(None, {}, "X")
    with pytest.raises(ConfigError, match="whole number"):
        resolve_timesteps(None, {"n_timesteps": 10.5}, "X")
    with pytest.raises(ConfigError, match="whole number"):
        resolve_timesteps(None, {"n_timesteps": "many"}, "X")
    yml = tmp_path / "ppo.yml"
    yml.write_text(
        "SfW-ExploreSmall-v0:\n  policy: MultiInputPolicy\n  n_timesteps: 64\n  n_envs: 1\n"
        "  n_steps: 32\n  batch_size: 32\n  n_epochs: 1\n  env_kwargs: {max_steps: 40}\n"
    )
    summary = train_ppo(
        "SfW-ExploreSmall-v0", None, tmp_path / "run", hyperparams_path=yml, progress_bar=False,
        checkpoint_every=64, eval_every=64, eval_episodes=1,
    )  # fmt: skip
    assert summary["steps"] == 64


def test_a_run_is_saved_in_rl_zoos_layout(tmp_path):
    """OUT/<env-id>.zip, OUT/<env-id>/config.yml (the block as written, without the sfw_gym
    block) and args.yml (the env_kwargs rl_zoo3.enjoy uses), beside sfw-gym's config.yml."""
    import yaml

    from sfw_gym.rl.runs import find_model

    yml = tmp_path / "ppo.yml"
    block = (
        f"{SMALL_ID}:\n  policy: MultiInputPolicy\n  n_timesteps: 32\n  n_envs: 1\n"
        "  n_steps: 32\n  batch_size: 32\n  n_epochs: 1\n  env_kwargs: {max_steps: 40}\n"
        '  policy_kwargs: "dict(net_arch=[8])"\n'
    )
    yml.write_text(block + f"sfw_gym:\n  {SMALL_ID}:\n    use_masking: false\n")
    out = tmp_path / "ppo" / f"{SMALL_ID}_1"
    summary = train_ppo(
        SMALL_ID, None, out, hyperparams_path=yml, env_kwargs={"max_steps": 30}, seed=5,
        progress_bar=False, eval_every=10**6,
    )  # fmt: skip
    assert summary["model"] == str(out / f"{SMALL_ID}.zip") == str(find_model(out))
    assert not (out / "model.zip").exists()
    zoo = yaml.safe_load((out / SMALL_ID / "config.yml").read_text())
    assert zoo == yaml.safe_load(block)[SMALL_ID]  # policy_kwargs stays rl-zoo's string
    args = yaml.safe_load((out / SMALL_ID / "args.yml").read_text())
    assert args["algo"] == "ppo" and args["env"] == SMALL_ID and args["seed"] == 5
    assert args["env_kwargs"] == {"max_steps": 30}  # the caller's win over the block's
    assert args["n_timesteps"] == 32 and args["hyperparams"] is None
    record = yaml.safe_load((out / "config.yml").read_text())
    assert record["hyperparameters"]["use_masking"] is False  # the project block, recorded


def test_the_model_of_a_run_folder_is_found_by_its_env_id_or_the_old_name(tmp_path):
    from sfw_gym.rl.runs import env_name, find_model, model_path

    assert env_name("sfw_gym:SfW-Explore-v0") == "SfW-Explore-v0"
    assert env_name("ns/Env-v1") == "ns-Env-v1"
    assert model_path(tmp_path, "sfw_gym:SfW-Explore-v0") == tmp_path / "SfW-Explore-v0.zip"
    with pytest.raises(ConfigError, match="names no env"):
        env_name("sfw_gym:")
    zoo = tmp_path / "SfW-ExploreGoals-v0_3"  # rl-zoo's run folder: named by the env id
    zoo.mkdir()
    with pytest.raises(ConfigError, match=r"no model found \(looked for SfW-ExploreGoals-v0\.zip"):
        find_model(zoo)
    (zoo / "model.zip").write_bytes(b"old")  # a run saved before the rl-zoo names
    assert find_model(zoo) == zoo / "model.zip"
    (zoo / "SfW-ExploreGoals-v0.zip").write_bytes(b"new")
    assert find_model(zoo) == zoo / "SfW-ExploreGoals-v0.zip"
    run = tmp_path / "runs-goals"  # sfw-gym's --out, any name: its config.yml names the env
    run.mkdir()
    (run / "SfW-ExploreRegions-v0.zip").write_bytes(b"m")
    with pytest.raises(ConfigError, match=r"looked for model\.zip\)"):
        find_model(run)
    (run / "config.yml").write_text("env_id: SfW-ExploreRegions-v0\n")
    assert find_model(run) == run / "SfW-ExploreRegions-v0.zip"
    (run / "config.yml").unlink()  # or rl-zoo's <env-id>/config.yml beside the model
    (run / "SfW-ExploreRegions-v0").mkdir()
    (run / "SfW-ExploreRegions-v0" / "config.yml").write_text("{}")
    assert find_model(run) == run / "SfW-ExploreRegions-v0.zip"


@pytest.mark.episode  # starts SB3's worker processes
def test_n_envs_step_in_the_native_vector_env_unless_wrapped_or_told_otherwise(tmp_path):
    """``sfw-gym train``'s ``--vec-env``: the native env for bare envs (issue 33), SB3's
    SubprocVecEnv under an ``env_wrapper`` or with ``vec_env="subproc"``."""
    from stable_baselines3.common.vec_env import SubprocVecEnv

    from sfw_gym.envs.vector import SfWVectorEnv
    from sfw_gym.rl.training import _make_venv
    from sfw_gym.rl.vec_env import SB3VecEnv

    waypoints = [("sfw_gym.envs.waypoint.WaypointWrapper", {})]
    cases = [("native", [], SB3VecEnv), ("native", waypoints, SubprocVecEnv)]
    cases.append(("subproc", [], SubprocVecEnv))
    for vec_env, wrappers, kind in cases:
        venv = _make_venv(SMALL_ID, 2, 0, TINY, wrappers, tmp_path / "m.csv", vec_env)
        try:
            assert type(venv.venv) is kind, (vec_env, wrappers)
            if kind is SB3VecEnv:
                assert isinstance(venv.venv.venv, SfWVectorEnv) and venv.venv.venv._batched
        finally:
            venv.close()
    with pytest.raises(ConfigError, match="unknown vec_env 'dummy'"):
        train_ppo(SMALL_ID, 64, tmp_path / "run", vec_env="dummy", progress_bar=False)


@pytest.mark.slow
def test_the_curriculum_lengthens_the_episodes_that_start_after_its_stage(tmp_path):
    """Episodes of env_kwargs' 40 steps until timestep 128, then of the stage's 20; the episodes
    running at the switch keep their budget (monitor lengths, in order per sub-env)."""
    import pandas as pd
    import yaml

    block = {
        "policy": "MultiInputPolicy", "n_envs": 2, "n_steps": 32, "batch_size": 32,
        "n_epochs": 1, "env_kwargs": {"max_steps": 40},
        "policy_kwargs": "dict(net_arch=[8])",
    }  # fmt: skip
    project = {"SfW-ExploreSmall-v0": {"curriculum": [{"from_timestep": 128, "max_steps": 20}]}}
    hyper = tmp_path / "ppo.yml"
    hyper.write_text(yaml.safe_dump({"SfW-ExploreSmall-v0": block, "sfw_gym": project}))
    train_ppo(
        "SfW-ExploreSmall-v0", 320, tmp_path, hyperparams_path=hyper, eval_every=10**6,
        progress_bar=False,
    )  # fmt: skip
    lengths = pd.read_csv(tmp_path / "train_0.monitor.csv", skiprows=1)["l"].tolist()
    # each sub-env steps 64 times before the switch: its first episode (40) ends before it,
    # its second (begun at step 40) keeps its 40; every episode begun after it has 20
    assert lengths[:4] == [40, 40, 40, 40] and set(lengths) == {40, 20}
    assert lengths.count(40) == 4  # the stage is due at timestep 128 itself, not later
    first_short = lengths.index(20)
    assert all(length == 20 for length in lengths[first_short:])
    assert sum(lengths) <= 320


def test_a_malformed_curriculum_is_named():
    assert curriculum_stages(None) == []
    assert curriculum_stages([{"from_timestep": 9, "max_steps": 3}, {"from_timestep": 0,
                              "max_steps": 5}]) == [(0, 5), (9, 3)]  # fmt: skip
    for bad in ({"from_timestep": 1}, [{"from_timestep": -1, "max_steps": 3}], ["600"]):
        with pytest.raises(ConfigError, match="curriculum"):
            curriculum_stages(bad)
