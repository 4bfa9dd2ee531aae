"""RLlib (Ray) training: the envs registered for Ray's runners, an RLModule for the Dict
observation, PPO from the same rl-zoo YAML as stable-baselines3, checkpoints and resume.

Layout of an output folder::

    OUT/checkpoints/iter_<n>/     RLlib checkpoint after iteration n (moved into place whole)
    OUT/progress.csv              iteration, env steps, mean episode return, wall time
    OUT/config.yml                hyperparameters, env, seed, runners, command
    OUT/model/                    the final checkpoint (``Algorithm.from_checkpoint`` loads it)

Ray's runners are fresh processes that have not imported ``sfw_gym``: a plain id raises
``NameNotFound`` there. :func:`register_rllib_envs` registers every id (and its rl-zoo wrappers)
with ``ray.tune.register_env``, which Ray ships to every runner.
"""

from __future__ import annotations

import csv
import functools
import math
import re
import shutil
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from sfw_gym.core.atomic import atomic_dir, atomic_path, remove_stale_temps, write_text_atomic
from sfw_gym.core.data import default_hyperparams
from sfw_gym.core.errors import ConfigError
from sfw_gym.rl.training import (
    import_dotted,
    load_hyperparams,
    resolve_timesteps,
    wrapper_specs,
)

#: The hyperparameters of the RLlib backend (rl-zoo format).
RLLIB_HYPERPARAMS = default_hyperparams("rllib_ppo")
#: The RLModule when the hyperparameters name no ``policy``.
DEFAULT_MODULE = "sfw_gym.rl.rllib_module.DictObsModule"
_CHECKPOINT = re.compile(r"iter_(\d+)")
_PROGRESS_FIELDS = ("iteration", "env_steps", "episode_return_mean", "wall_time_s")


def require_rllib() -> Any:
    """``ray.rllib``, or a one-line error saying how to install it."""
    try:
        import ray.rllib  # noqa: F401
        from ray.rllib.algorithms.ppo import PPOConfig
    except ImportError:
        raise ConfigError("--backend rllib needs Ray: pip install 'sfw-gym[ray]'") from None
    return PPOConfig


def make_env(env_id: str, wrappers: list[tuple[str, dict]], env_config: Any = None) -> Any:
    """The env for ``env_id`` with rl-zoo's wrappers applied (``env_config``: its kwargs). With
    ``num_envs`` in ``env_config`` (RLlib's runners under ``gym_env_vectorize_mode=
    "vector_entry_point"``, which `ppo_config` sets for an id without wrappers): the native
    vector env of that many sub-envs (`sfw_gym.envs.vector`)."""
    import gymnasium as gym

    import sfw_gym  # noqa: F401  (registration in this runner)

    kwargs = dict(env_config or {})
    num_envs = kwargs.pop("num_envs", None)
    if num_envs is not None:
        if wrappers:
            raise ConfigError(f"{env_id}: wrapped envs step one by one, not as a native batch")
        return gym.make_vec(
            env_id, num_envs=num_envs, vectorization_mode="vector_entry_point", **kwargs
        )
    env = gym.make(env_id, **kwargs)
    for name, kwargs in wrappers:
        env = import_dotted(name)(env, **kwargs)
    return env


def register_rllib_envs(wrappers: dict[str, list[tuple[str, dict]]] | None = None) -> None:
    """Register every sfw_gym id with Ray Tune, so RLlib's runners can build it by its id.

    ``wrappers``: per id, rl-zoo ``env_wrapper`` specs to apply (:func:`wrapper_specs`).
    """
    from ray.tune.registry import register_env

    from sfw_gym.envs import ENV_IDS

    for env_id in ENV_IDS:
        register_env(env_id, functools.partial(make_env, env_id, (wrappers or {}).get(env_id, [])))


def ppo_config(
    env_id: str,
    params: dict[str, Any],
    *,
    num_env_runners: int = 0,
    seed: int = 0,
    env_kwargs: dict[str, Any] | None = None,
) -> Any:
    """RLlib's PPOConfig from an rl-zoo block (:func:`load_hyperparams`): one iteration collects
    ``n_steps × n_envs`` env steps, as one SB3 rollout does; the other keys map one to one;
    ``policy`` names the RLModule class by dotted path (an SB3 policy name such as
    ``MultiInputPolicy``, or none: :data:`DEFAULT_MODULE`). Each runner's envs are the native
    vector env (``gym.make_vec``'s ``vector_entry_point``), unless the block wraps them
    (``env_wrapper``): then Gymnasium's ``SyncVectorEnv``."""
    PPOConfig = require_rllib()
    from ray.rllib.core.rl_module.rl_module import RLModuleSpec

    n_envs = int(params.get("n_envs", 1))
    batch = int(params.get("n_steps", 2048)) * n_envs
    hidden = _first_layer_width(params.get("policy_kwargs") or {})
    policy = params.get("policy") or DEFAULT_MODULE
    module = import_dotted(policy if "." in policy else DEFAULT_MODULE)  # SB3 names: ours
    kwargs = {**(params.get("env_kwargs") or {}), **(env_kwargs or {})}
    config = (
        PPOConfig()
        .environment(env=env_id, env_config=kwargs)
        .env_runners(
            num_env_runners=num_env_runners,
            num_envs_per_env_runner=max(1, n_envs // max(1, num_env_runners)),
            rollout_fragment_length="auto",
            gym_env_vectorize_mode="sync" if params.get("env_wrapper") else "vector_entry_point",
        )
        .training(
            train_batch_size_per_learner=batch,
            minibatch_size=min(int(params.get("batch_size", 64)), batch),
            num_epochs=int(params.get("n_epochs", 10)),
            gamma=float(params.get("gamma", 0.99)),
            lambda_=float(params.get("gae_lambda", 0.95)),
            lr=float(params.get("learning_rate", 3e-4)),
            clip_param=float(params.get("clip_range", 0.2)),
            entropy_coeff=float(params.get("ent_coef", 0.0)),
            vf_loss_coeff=float(params.get("vf_coef", 0.5)),
            grad_clip=float(params.get("max_grad_norm", 0.5)),
        )
        .rl_module(
            rl_module_spec=RLModuleSpec(module_class=module, model_config={"hidden": hidden})
        )
        .debugging(seed=seed)
    )
    return config


def _first_layer_width(policy_kwargs: dict[str, Any]) -> int:
    """The width of SB3's first policy layer (``net_arch``), 64 when not given."""
    arch = policy_kwargs.get("net_arch")
    if isinstance(arch, dict):
        arch = arch.get("pi")
    return int(arch[0]) if isinstance(arch, list) and arch else 64


def latest_rllib_checkpoint(out_dir: Path) -> tuple[Path, int] | None:
    """The checkpoint with the most iterations in ``OUT/checkpoints``, if any."""
    found = [
        (int(m.group(1)), p)
        for p in (out_dir / "checkpoints").glob("iter_*")
        if p.is_dir() and (m := _CHECKPOINT.fullmatch(p.name))
    ]
    if not found:
        return None
    iteration, path = max(found)
    return path, iteration


def _save(algo: Any, target: Path) -> None:
    """``algo``'s checkpoint at ``target``, written beside it and moved into place whole."""
    if target.exists():
        return
    with atomic_dir(target) as tmp:
        algo.save_to_path(str(tmp.resolve()))


def train_rllib(
    env_id: str,
    timesteps: int | None,
    out_dir: str | Path,
    *,
    num_env_runners: int = 0,
    seed: int = 0,
    hyperparams_path: str | Path = RLLIB_HYPERPARAMS,
    env_kwargs: dict[str, Any] | None = None,
    checkpoint_every: int = 50_000,
    resume: bool = False,
    progress_bar: bool = True,
    address: str | None = None,
) -> dict[str, Any]:
    """Train PPO with RLlib on ``env_id`` until ``timesteps`` env steps (whole iterations; None:
    the hyperparameters' ``n_timesteps``).

    ``num_env_runners``: Ray processes that collect episodes (0: the driver collects them).
    A checkpoint in ``OUT/checkpoints`` at the first iteration boundary after every
    ``checkpoint_every`` env steps, and at the end; ``resume=True`` loads the latest and
    continues (the module, optimiser, connector and metrics state and the iteration count; the
    env episodes in flight start anew). ``address``: a running Ray
    cluster (``"auto"``), else a local Ray with one CPU per runner plus the driver.
    """
    from tqdm.auto import tqdm

    require_rllib()
    import ray

    params = load_hyperparams(env_id, hyperparams_path)
    timesteps = resolve_timesteps(timesteps, params, env_id)
    for name, value in (
        ("timesteps", timesteps),
        ("checkpoint_every", checkpoint_every),
    ):
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise ConfigError(f"{name} must be an integer ≥ 1, got {value!r}")
    runners_ok = isinstance(num_env_runners, int) and not isinstance(num_env_runners, bool)
    if not runners_ok or num_env_runners < 0:
        raise ConfigError(f"num_env_runners must be an integer ≥ 0, got {num_env_runners!r}")
    wrappers = wrapper_specs(params.get("env_wrapper"))
    for name, _ in wrappers:
        import_dotted(name)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if resume:
        remove_stale_temps(out)
    previous = latest_rllib_checkpoint(out) if resume else None
    started = not ray.is_initialized()
    if started:
        ray.init(
            address=address,
            num_cpus=num_env_runners + 1 if address is None else None,
            include_dashboard=False,
            log_to_driver=False,
        )
    register_rllib_envs({env_id: wrappers})
    config = ppo_config(
        env_id, params, num_env_runners=num_env_runners, seed=seed, env_kwargs=env_kwargs
    )
    algo = None
    t0 = time.perf_counter()
    try:
        algo = config.build_algo()
        iteration, steps = 0, 0
        if previous is not None:
            algo.restore_from_path(str(previous[0].resolve()))
            iteration, steps = _progress_at(out / "progress.csv", previous[1])
        next_checkpoint = (steps // checkpoint_every + 1) * checkpoint_every
        _write_config(out, env_id, params, num_env_runners, seed, timesteps)
        bar = tqdm(
            total=timesteps, initial=min(steps, timesteps), unit="step", disable=not progress_bar
        )
        try:
            while steps < timesteps:
                t_iter = time.perf_counter()
                result = algo.train()
                iteration += 1
                new_steps = int(result["env_runners"]["num_env_steps_sampled_lifetime"])
                bar.update(min(new_steps, timesteps) - min(steps, timesteps))
                steps = new_steps
                mean_return = result["env_runners"].get("episode_return_mean", math.nan)
                _append_progress(
                    out / "progress.csv",
                    iteration,
                    steps,
                    mean_return,
                    time.perf_counter() - t_iter,
                )
                bar.set_postfix_str(f"return {mean_return:.2f}")
                if steps >= next_checkpoint:
                    _save(algo, out / "checkpoints" / f"iter_{iteration:06d}")
                    next_checkpoint = (steps // checkpoint_every + 1) * checkpoint_every
        finally:
            bar.close()
        final = out / "checkpoints" / f"iter_{iteration:06d}"
        _save(algo, final)
        shutil.rmtree(out / "model", ignore_errors=True)
        with atomic_dir(out / "model") as tmp:
            shutil.copytree(final, tmp, dirs_exist_ok=True)
    finally:
        if algo is not None:
            algo.stop()
        if started:
            ray.shutdown()
    return {
        "steps": steps,
        "iterations": iteration,
        "wall_time_s": time.perf_counter() - t0,
        "model": str(out / "model"),
    }


def _append_progress(
    path: Path, iteration: int, steps: int, mean_return: float, seconds: float
) -> None:
    new = not path.is_file()
    with path.open("a", newline="", encoding="utf-8") as f:
        writer = csv.writer(f)
        if new:
            writer.writerow(_PROGRESS_FIELDS)
        writer.writerow([iteration, steps, f"{mean_return:.6g}", f"{seconds:.3f}"])


def read_progress(path: str | Path) -> list[dict[str, float]]:
    """``progress.csv`` as rows of numbers (a line cut by a kill is skipped)."""
    rows = []
    with Path(path).open(newline="", encoding="utf-8") as f:
        for row in csv.DictReader(f):
            try:
                rows.append({k: float(row[k]) for k in _PROGRESS_FIELDS})
            except (TypeError, ValueError):
                continue
    return rows


def _progress_at(path: Path, iteration: int) -> tuple[int, int]:
    """(iteration, env steps) at a checkpoint; later rows (past the checkpoint) are dropped."""
    rows = [r for r in read_progress(path) if r["iteration"] <= iteration] if path.is_file() else []
    with atomic_path(path) as tmp:
        with Path(tmp).open("w", newline="", encoding="utf-8") as f:
            writer = csv.writer(f)
            writer.writerow(_PROGRESS_FIELDS)
            for r in rows:
                writer.writerow(
                    [
                        int(r["iteration"]),
                        int(r["env_steps"]),
                        r["episode_return_mean"],
                        r["wall_time_s"],
                    ]
                )
    return iteration, int(rows[-1]["env_steps"]) if rows else 0


def _write_config(
    out: Path, env_id: str, params: dict[str, Any], runners: int, seed: int, timesteps: int
) -> None:
    record = {
        "backend": "rllib",
        "env_id": env_id,
        "timesteps": timesteps,
        "seed": seed,
        "num_env_runners": runners,
        "hyperparams": params,
        "command": " ".join(sys.argv),
    }
    write_text_atomic(out / "config.yml", yaml.safe_dump(record, sort_keys=False))


def greedy_returns(
    checkpoint: str | Path | Any,
    env_id: str,
    seeds: list[int],
    env_kwargs: dict[str, Any] | None = None,
) -> list[float]:
    """Returns of the policy acting greedily (the Gaussian's mean, the highest valid logit) on
    one episode per seed. ``checkpoint``: a folder of :func:`train_rllib` or an RLModule."""
    import torch
    from gymnasium import spaces
    from ray.rllib.core.columns import Columns

    module: Any = checkpoint
    if isinstance(checkpoint, str | Path):
        from ray.rllib.core.rl_module.rl_module import RLModule

        path = Path(checkpoint) / "learner_group" / "learner" / "rl_module" / "default_policy"
        module = RLModule.from_checkpoint(str(path.resolve()))
    returns = []
    for seed in seeds:
        env = make_env(env_id, [], env_kwargs)
        obs, _ = env.reset(seed=seed)
        total, done = 0.0, False
        while not done:
            batch = {k: torch.as_tensor(np.asarray(v)[None]) for k, v in obs.items()}
            with torch.no_grad():
                out = module.forward_inference({Columns.OBS: batch})[Columns.ACTION_DIST_INPUTS][0]
            if isinstance(env.action_space, spaces.Discrete):
                action: Any = int(out.argmax())
            else:
                dim = int(np.prod(env.action_space.shape))
                action = np.clip(out[:dim].numpy(), env.action_space.low, env.action_space.high)
            obs, reward, terminated, truncated, _ = env.step(action)
            total += float(reward)
            done = terminated or truncated
        env.close()
        returns.append(total)
    return returns
