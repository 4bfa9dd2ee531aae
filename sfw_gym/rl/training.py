"""PPO training (stable-baselines3; sb3-contrib's MaskablePPO as ``ppo_mask``, optionally
started by behaviour cloning) with checkpoints, resume, held-out evaluation and a curve.

Layout of an output folder (rl-baselines3-zoo's, :mod:`sfw_gym.rl.runs`, plus sfw-gym's own)::

    OUT/checkpoints/<algo>_<steps>_steps.zip   every ``checkpoint_every`` env steps, each with
    OUT/checkpoints/<algo>_<steps>_steps.state.pkl   what an exact resume needs (rl.resume)
    OUT/tb/                                 TensorBoard logs
    OUT/train_<start>.monitor.csv           episode return, length, floorplan (one per run segment)
    OUT/eval/evaluations.npz                held-out evaluation (EvalCallback)
    OUT/<env-id>.zip                        the final model (written atomically)
    OUT/<env-id>/config.yml, args.yml       rl-zoo's record: the hyperparameters, the arguments
    OUT/config.yml                          hyperparameters, env, seeds, command, wall time
    OUT/behaviour_cloning.yml               per cloning fit: decisions, loss, teacher agreement
    OUT/training_curve.png                  episode return and held-out return vs env steps
"""

from __future__ import annotations

import ast
import logging
import math
import re
import shutil
import sys
import time
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from sfw_gym.core.atomic import atomic_path, remove_stale_temps, write_text_atomic
from sfw_gym.core.data import DEFAULT_HYPERPARAMS
from sfw_gym.core.errors import ConfigError
from sfw_gym.rl.resume import (
    Snapshots,
    restore_state,
    resumable_checkpoints,
    save_checkpoint,
    state_path,
)
from sfw_gym.rl.runs import find_model, model_path, write_zoo_params

logger = logging.getLogger(__name__)

#: Evaluation episodes draw their floorplans from seeds this far from the training seeds.
HELD_OUT_SEED_OFFSET = 1_000_000
#: The algorithms, by rl-zoo's names.
ALGOS = ("ppo", "ppo_mask")
#: The top-level block of a hyperparameter file that holds, per env id, what ``sfw-gym train``
#: does beyond plain (Maskable)PPO: rl-zoo reads only the env id's own block, and hands every key
#: there that it does not know to the model's constructor.
PROJECT_BLOCK = "sfw_gym"
#: The keys of the project block: behaviour cloning before PPO, AnchoredMaskablePPO's
#: fine-tuning, the no-mask ablation, the training episodes' curriculum (:func:`curriculum_stages`).
PROJECT_KEYS = frozenset({"behaviour_cloning", "fine_tuning", "use_masking", "curriculum"})
#: The keys rl-zoo reads from an env id's block (the rest of :data:`_PPO_KEYS` go to PPO).
_ZOO_KEYS = frozenset({"policy", "n_timesteps", "n_envs", "env_wrapper", "env_kwargs"})
_PPO_KEYS = {
    "target_kl",
    "use_sde",
    "sde_sample_freq",
    "n_steps",
    "batch_size",
    "n_epochs",
    "gamma",
    "gae_lambda",
    "learning_rate",
    "clip_range",
    "ent_coef",
    "vf_coef",
    "max_grad_norm",
    "policy_kwargs",
}


def zoo_hyperparams(env_id: str, path: str | Path = DEFAULT_HYPERPARAMS) -> dict[str, Any]:
    """The block of ``env_id`` in an rl-zoo hyperparameter file, as written there (what
    ``rl_zoo3.train`` reads); the ``sfw_gym`` block's keys are not in it."""
    path = Path(path)
    try:
        table = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as exc:
        raise ConfigError(f"{path}: cannot read hyperparameters: {exc}") from exc
    blocks = sorted(k for k in table if k != PROJECT_BLOCK) if isinstance(table, dict) else []
    if env_id not in blocks:
        raise ConfigError(f"{path}: no hyperparameters for {env_id!r}; blocks: {blocks}")
    if not isinstance(table[env_id], dict):
        raise ConfigError(f"{path}: the block of {env_id!r} must be a mapping")
    return dict(table[env_id])


def project_hyperparams(env_id: str, path: str | Path = DEFAULT_HYPERPARAMS) -> dict[str, Any]:
    """``env_id``'s entry in the ``sfw_gym`` block of a hyperparameter file (``{}`` if none):
    the keys that ``sfw-gym train`` reads and rl-zoo never sees."""
    path = Path(path)
    try:
        table = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as exc:
        raise ConfigError(f"{path}: cannot read hyperparameters: {exc}") from exc
    project = table.get(PROJECT_BLOCK) if isinstance(table, dict) else None
    if project is None:
        return {}
    if not isinstance(project, dict) or not isinstance(project.get(env_id) or {}, dict):
        raise ConfigError(
            f"{path}: {PROJECT_BLOCK} must map env ids to mappings of "
            f"{sorted(PROJECT_KEYS)}, got {project!r}"
        )
    keys = dict(project.get(env_id) or {})
    unknown = set(keys) - PROJECT_KEYS
    if unknown:
        raise ConfigError(
            f"{path}: unknown keys in {PROJECT_BLOCK}.{env_id}: {sorted(unknown)}; "
            f"known: {sorted(PROJECT_KEYS)}"
        )
    return keys


def load_hyperparams(env_id: str, path: str | Path = DEFAULT_HYPERPARAMS) -> dict[str, Any]:
    """What ``sfw-gym train`` trains ``env_id`` with: the env id's rl-zoo block
    (``policy_kwargs`` parsed safely) and its entry in the ``sfw_gym`` block
    (:data:`PROJECT_KEYS`)."""
    path = Path(path)
    params = zoo_hyperparams(env_id, path)
    misplaced = sorted(PROJECT_KEYS & set(params))
    if misplaced:
        raise ConfigError(
            f"{path}: {misplaced} of {env_id!r} belong in the {PROJECT_BLOCK!r} block "
            f"({PROJECT_BLOCK}: {{{env_id}: {{...}}}}): rl-zoo would hand them to the model"
        )
    if isinstance(params.get("policy_kwargs"), str):
        params["policy_kwargs"] = parse_policy_kwargs(params["policy_kwargs"])
    wrapper_specs(params.get("env_wrapper"))  # fail early on a malformed entry
    if not isinstance(params.get("env_kwargs") or {}, dict):
        raise ConfigError(f"{path}: env_kwargs must be a mapping, got {params['env_kwargs']!r}")
    unknown = set(params) - _PPO_KEYS - _ZOO_KEYS
    if unknown:
        raise ConfigError(
            f"{path}: unknown keys for {env_id!r}: {sorted(unknown)} (sfw-gym's own go in the "
            f"{PROJECT_BLOCK!r} block)"
        )
    return {**params, **project_hyperparams(env_id, path)}


def resolve_timesteps(timesteps: int | None, params: dict[str, Any], env_id: str) -> int:
    """``timesteps``, or when None the YAML block's ``n_timesteps`` (rl-zoo's budget)."""
    if timesteps is not None:
        return timesteps
    budget = params.get("n_timesteps")
    if budget is None:
        raise ConfigError(
            f"no timesteps given and the hyperparameters of {env_id!r} set no n_timesteps"
        )
    try:
        steps = float(budget)  # rl-zoo writes 1e5 (!!float), YAML may leave "1e5" a string
    except (TypeError, ValueError):
        steps = math.nan
    if not (steps.is_integer() and steps >= 1):
        raise ConfigError(f"n_timesteps of {env_id!r} must be a whole number ≥ 1, got {budget!r}")
    return int(steps)


def parse_policy_kwargs(text: str) -> dict[str, Any]:
    """Evaluate rl-zoo's ``policy_kwargs`` string allowing only dict(...) calls and literals."""

    def value(node: ast.AST) -> Any:
        if (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Name)
            and node.func.id == "dict"
        ):
            if node.args:
                raise ConfigError(f"policy_kwargs: dict() takes keywords only: {text!r}")
            return {kw.arg: value(kw.value) for kw in node.keywords}
        if isinstance(node, ast.List | ast.Tuple):
            return [value(e) for e in node.elts]
        if isinstance(node, ast.Dict) and all(k is not None for k in node.keys):
            return {value(k): value(v) for k, v in zip(node.keys, node.values, strict=True)}  # type: ignore[arg-type]
        if isinstance(node, ast.Constant):
            return node.value
        if (  # a signed number: log_std_init=-0.5
            isinstance(node, ast.UnaryOp)
            and isinstance(node.op, ast.USub | ast.UAdd)
            and isinstance(node.operand, ast.Constant)
            and isinstance(node.operand.value, int | float)
            and not isinstance(node.operand.value, bool)
        ):
            return -node.operand.value if isinstance(node.op, ast.USub) else node.operand.value
        raise ConfigError(f"policy_kwargs: only dict(...) and literals are allowed: {text!r}")

    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as exc:
        raise ConfigError(f"policy_kwargs: not a Python expression: {text!r}") from exc
    out = value(tree.body)
    if not isinstance(out, dict):
        raise ConfigError(f"policy_kwargs must be a dict, got {text!r}")
    return out


def wrapper_specs(value: Any) -> list[tuple[str, dict[str, Any]]]:
    """rl-zoo's ``env_wrapper`` entry as ``[(dotted class path, kwargs), ...]``.

    Accepted forms: ``"pkg.mod.Class"``, ``{"pkg.mod.Class": {kwargs}}``, or a list of those
    (applied in order, innermost first).
    """
    if value is None:
        return []
    specs: list[tuple[str, dict[str, Any]]] = []
    for entry in value if isinstance(value, list) else [value]:
        if isinstance(entry, str):
            specs.append((entry, {}))
        elif isinstance(entry, dict) and len(entry) == 1:
            ((name, kwargs),) = entry.items()
            if not isinstance(name, str) or not isinstance(kwargs or {}, dict):
                raise ConfigError(f"env_wrapper: bad entry {entry!r}")
            specs.append((name, dict(kwargs or {})))
        else:
            raise ConfigError(
                f"env_wrapper: expected 'pkg.mod.Class' or {{'pkg.mod.Class': {{kwargs}}}}, "
                f"got {entry!r}"
            )
    return specs


def import_dotted(name: str) -> Any:
    """The object at dotted path ``pkg.mod.Name`` (as rl-zoo imports ``policy`` and
    ``env_wrapper`` entries)."""
    import importlib

    module, _, attr = name.rpartition(".")
    try:
        return getattr(importlib.import_module(module), attr)
    except (ImportError, AttributeError, ValueError) as exc:
        raise ConfigError(f"cannot import {name!r}: {exc}") from None


def curriculum_stages(value: Any) -> list[tuple[int, int]]:
    """The project block's ``curriculum``: a list of ``{from_timestep: T, max_steps: N}``, the
    training episodes' step budget from timestep T on (before the first: ``env_kwargs``'), as
    sorted ``(T, N)`` pairs."""
    if value is None:
        return []
    stages = []
    for entry in value if isinstance(value, list) else [value]:
        if not (isinstance(entry, dict) and set(entry) == {"from_timestep", "max_steps"}):
            raise ConfigError(
                f"curriculum: each stage is {{from_timestep: T, max_steps: N}}, got {entry!r}"
            )
        start, steps = entry["from_timestep"], entry["max_steps"]
        if not all(isinstance(v, int) and not isinstance(v, bool) for v in (start, steps)) or (
            start < 0 or steps < 1
        ):
            raise ConfigError(f"curriculum: T must be ≥ 0 and N ≥ 1 (integers), got {entry!r}")
        stages.append((start, steps))
    return sorted(stages)


def episode_budget_curriculum(stages: list[tuple[int, int]], venv: Any) -> Any:
    """An SB3 callback that sets the training envs' step budget (``set_max_steps``) to the
    :func:`curriculum_stages` stage due at each rollout's start, for the episodes that begin
    from then on (a resumed run's too)."""
    from stable_baselines3.common.callbacks import BaseCallback

    class EpisodeBudgetCurriculum(BaseCallback):
        def _init_callback(self) -> None:
            self.current: int | None = None

        def _on_rollout_start(self) -> None:
            due = [steps for start, steps in stages if start <= self.model.num_timesteps]
            if due and due[-1] != self.current:
                self.current = due[-1]
                venv.env_method("set_max_steps", self.current)
                logger.info("curriculum: episodes of %d steps from now on", self.current)

        def _on_step(self) -> bool:
            return True

    return EpisodeBudgetCurriculum()


def latest_checkpoint(out_dir: Path, algo: str = "ppo") -> tuple[Path, int] | None:
    """The checkpoint with the most env steps in ``OUT/checkpoints``, if any."""
    found = []
    for path in (out_dir / "checkpoints").glob(f"{algo}_*_steps.zip"):
        match = re.fullmatch(rf"{algo}_(\d+)_steps\.zip", path.name)
        if match:
            found.append((int(match.group(1)), path))
    if not found:
        return None
    steps, path = max(found)
    return path, steps


def _make_env_fn(env_id: str, env_kwargs: dict[str, Any], wrappers: list[tuple[str, dict]]):
    def make() -> Any:
        import gymnasium as gym

        env = gym.make(env_id, **env_kwargs)
        for name, kwargs in wrappers:
            env = import_dotted(name)(env, **kwargs)
        return Snapshots(env)

    return make


#: The one env wrapper the native vector env applies itself (SB3VecEnv's ``action_repeat``).
ACTION_REPEAT = "sfw_gym.envs.action_repeat.ActionRepeat"


def native_action_repeat(wrappers: list[tuple[str, dict]]) -> int | None:
    """The action repeat with which the native vector env steps envs wrapped so (1 unwrapped),
    or None when the wrappers need envs of their own (SubprocVecEnv)."""
    if not wrappers:
        return 1
    if len(wrappers) == 1 and wrappers[0][0] == ACTION_REPEAT:
        from sfw_gym.envs.action_repeat import DEFAULT_REPEAT

        return int(wrappers[0][1].get("repeat", DEFAULT_REPEAT))
    return None


#: ``vec_env`` choices of `train_ppo`: the native vector env in this process (each sub-env a
#: bare env; with an ``env_wrapper``, SubprocVecEnv instead), or SB3's worker processes.
VEC_ENVS = ("native", "subproc")


def _make_venv(
    env_id: str,
    n_envs: int,
    seed: int | None,
    env_kwargs: dict[str, Any],
    wrappers: list[tuple[str, dict]],
    monitor: Path,
    vec_env: str = "native",
):
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv, VecMonitor

    # Workers start by forkserver and have not imported sfw_gym: name the module in the id.
    qualified = env_id if ":" in env_id else f"sfw_gym:{env_id}"
    venv: Any
    repeat = native_action_repeat(wrappers)
    if n_envs > 1 and vec_env == "native" and repeat is not None:
        import gymnasium as gym

        from sfw_gym.rl.vec_env import SB3VecEnv

        venv = SB3VecEnv(
            gym.make_vec(
                qualified, num_envs=n_envs, vectorization_mode="vector_entry_point", **env_kwargs
            ),
            action_repeat=repeat,
        )
    else:
        fns = [_make_env_fn(qualified, env_kwargs, wrappers) for _ in range(n_envs)]
        venv = SubprocVecEnv(fns) if n_envs > 1 else DummyVecEnv(fns)
    if seed is not None:  # None: the envs' states are restored instead
        venv.seed(seed)
    # The floorplan column lets a later comparison prove its plans were never trained on.
    return VecMonitor(venv, filename=str(monitor), info_keywords=("floorplan",))


def train_ppo(
    env_id: str,
    timesteps: int | None,
    out_dir: str | Path,
    *,
    n_envs: int | None = None,
    seed: int = 0,
    hyperparams_path: str | Path = DEFAULT_HYPERPARAMS,
    env_kwargs: dict[str, Any] | None = None,
    checkpoint_every: int = 50_000,
    eval_every: int = 25_000,
    eval_episodes: int = 5,
    resume: bool = False,
    progress_bar: bool = True,
    device: str = "auto",
    algo: str = "ppo",
    num_threads: int | None = 1,
    vec_env: str = "native",
) -> dict[str, Any]:
    """Train (or resume training) PPO on ``env_id`` up to ``timesteps`` env steps in total
    (None: the hyperparameters' ``n_timesteps``, as rl-zoo).

    ``algo="ppo_mask"``: sb3-contrib's MaskablePPO (the env has ``action_masks()``); a
    ``behaviour_cloning`` block in the hyperparameters (``episodes``, ``epochs``) first fits
    the fresh policy's actor to the frontier agent's choices on that many training episodes;
    ``use_masking: false`` (an ablation) ignores the masks in cloning, rollouts and updates.

    With ``resume=True`` the latest checkpoint in ``OUT/checkpoints`` is loaded and training
    continues from it exactly (envs mid-episode, random generators, step counter, optimiser and
    schedules: the final model equals an uninterrupted run's; :mod:`sfw_gym.rl.resume`);
    without a checkpoint it starts afresh. Checkpoints are taken between PPO iterations, at the
    first after every ``checkpoint_every`` env steps. Returns a summary (steps, wall time, paths).

    ``num_threads``: PyTorch's CPU threads in this process (rl-zoo's ``--num-threads``; None:
    PyTorch's default). One suits these small networks: more contend with the env workers for
    the cores (a policy 5× slower measured on a busy 2-core machine), and keeps a run's result
    the same on any machine. With the native env there are no workers: more threads speed PPO
    up (``n_envs`` 16 and 2 threads: 2.5× the throughput of 4 SubprocVecEnv workers and one
    thread on 2 cores, docs/results/speed.md), at the price of results that may differ in the last
    bits between thread counts.

    ``vec_env``: ``"native"`` steps the ``n_envs`` envs together in this process
    (`sfw_gym.envs.vector`, through `sfw_gym.rl.vec_env.SB3VecEnv`; an ``env_wrapper`` in the
    YAML makes it SubprocVecEnv, as the wrapped envs do not step together); ``"subproc"``:
    SB3's SubprocVecEnv. Both give the same episodes for the same seed.
    """
    from stable_baselines3.common.callbacks import CallbackList

    import sfw_gym  # noqa: F401  (registration in this process)

    if num_threads is not None:
        import torch

        torch.set_num_threads(num_threads)
    if algo not in ALGOS:
        raise ConfigError(f"unknown algo {algo!r}; known: {list(ALGOS)}")
    if vec_env not in VEC_ENVS:
        raise ConfigError(f"unknown vec_env {vec_env!r}; known: {list(VEC_ENVS)}")
    Algo: Any
    EvalCallback: Any
    params = load_hyperparams(env_id, hyperparams_path)
    timesteps = resolve_timesteps(timesteps, params, env_id)
    for name, value in (
        ("timesteps", timesteps),
        ("checkpoint_every", checkpoint_every),
        ("eval_every", eval_every),
        ("eval_episodes", eval_episodes),
    ):
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise ConfigError(f"{name} must be an integer ≥ 1, got {value!r}")
    fine_tuning = dict(params.get("fine_tuning") or {})
    stages = curriculum_stages(params.get("curriculum"))
    if algo == "ppo":
        if fine_tuning:
            raise ConfigError("fine_tuning needs algo ppo_mask (a cloned candidate policy)")
        from stable_baselines3 import PPO as Algo
        from stable_baselines3.common.callbacks import EvalCallback
    else:
        from sb3_contrib import MaskablePPO as Algo
        from sb3_contrib.common.maskable.callbacks import MaskableEvalCallback as EvalCallback

        if fine_tuning:  # keep what cloning learned (rl.finetune)
            from sfw_gym.rl.finetune import AnchoredMaskablePPO as Algo
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    n_envs = int(n_envs or params.get("n_envs", 1))
    policy = params.get("policy", "MultiInputPolicy")
    if "." in policy:  # a policy class of one's own, by dotted path
        policy = import_dotted(policy)
    ppo_kwargs = {k: v for k, v in params.items() if k in _PPO_KEYS}
    masking = {"use_masking": bool(params.get("use_masking", True))} if algo == "ppo_mask" else {}
    # rl-zoo's env_kwargs block, then the caller's (which win)
    env_kwargs = {**(params.get("env_kwargs") or {}), **(env_kwargs or {})}
    wrappers = wrapper_specs(params.get("env_wrapper"))
    for name, _ in wrappers:
        import_dotted(name)

    if resume:
        remove_stale_temps(out)  # of a run killed mid-write
    previous = latest_checkpoint(out, algo) if resume else None
    if previous is not None:
        logger.info("%s: resuming from %s (%d steps)", out, previous[0].name, previous[1])
    start_steps = previous[1] if previous else 0
    exact = previous is not None and state_path(previous[0]).is_file()
    if previous is not None and start_steps >= timesteps:  # already there (killed after its last
        with atomic_path(model_path(out, env_id)) as tmp:  # checkpoint)
            shutil.copyfile(previous[0], tmp)
        steps, wall = start_steps, 0.0
    else:
        venv = _make_venv(
            env_id,
            n_envs,
            None if exact else seed + start_steps,
            env_kwargs,
            wrappers,
            out / f"train_{start_steps}.monitor.csv",
            vec_env,
        )
        eval_env = _make_venv(
            env_id,
            1,
            None if exact else seed + HELD_OUT_SEED_OFFSET,
            env_kwargs,
            wrappers,
            out / f"eval_{start_steps}.monitor.csv",
        )
        try:
            if previous:
                model = Algo.load(
                    previous[0], env=venv, device=device, tensorboard_log=str(out / "tb")
                )
                if exact:
                    restore_state(model, venv, eval_env, previous[0])
            else:
                model = Algo(
                    policy,
                    venv,
                    seed=seed,
                    device=device,
                    verbose=0,
                    tensorboard_log=str(out / "tb"),
                    **ppo_kwargs,
                    **fine_tuning,
                )
                if params.get("behaviour_cloning"):
                    cloning = _clone_teacher(
                        model, env_id, env_kwargs, seed, params["behaviour_cloning"], **masking
                    )
                    write_text_atomic(out / "behaviour_cloning.yml", yaml.safe_dump(cloning))
                if fine_tuning:
                    model.set_anchor()  # the cloned policy: the KL term's reference
            grad_norms = []  # logged per head where the policy has separate heads
            if hasattr(model.policy, "parameter_groups"):
                from sfw_gym.rl import goal_policy

                grad_norms.append(goal_policy.HeadGradientNorms())
            evaluations = EvalCallback(
                eval_env,
                n_eval_episodes=eval_episodes,
                eval_freq=max(eval_every // n_envs, 1),
                log_path=str(out / "eval"),
                best_model_save_path=None,
                deterministic=False,
                verbose=0,
                **masking,
            )
            if previous:  # a resumed run appends to the evaluations so far, not over them
                _continue_evaluations(evaluations, out / "eval" / "evaluations.npz", start_steps)
                evaluations.n_calls = start_steps // n_envs  # and keeps their schedule
            callbacks = CallbackList(
                [
                    *([episode_budget_curriculum(stages, venv)] if stages else []),
                    *grad_norms,
                    resumable_checkpoints(
                        checkpoint_every, out / "checkpoints", algo, venv, eval_env
                    ),
                    evaluations,
                ]
            )
            start = time.perf_counter()
            model.learn(
                total_timesteps=timesteps - start_steps,
                callback=callbacks,
                reset_num_timesteps=previous is None,
                progress_bar=progress_bar,
                tb_log_name=algo,
                **masking,
            )
            wall = time.perf_counter() - start
            _save_atomic(model, model_path(out, env_id))
            # A final checkpoint, so that a later resume starts from the end of this run.
            final = out / "checkpoints" / f"{algo}_{model.num_timesteps}_steps.zip"
            save_checkpoint(model, venv, eval_env, final)
        finally:
            venv.close()
            eval_env.close()
        steps = int(model.num_timesteps)
    summary = {
        "algo": algo,
        "env_id": env_id,
        "steps": steps,
        "resumed_from": str(previous[0]) if previous else None,
        "wall_time_s": round(wall, 1),  # this call's
        "total_wall_time_s": round(_monitored_seconds(out), 1),  # every segment's, from the logs
        "n_envs": n_envs,
        "seed": seed,
        "hyperparameters": params,
        "env_kwargs": env_kwargs,
        "command": " ".join(sys.argv),
        "model": str(model_path(out, env_id)),
    }
    # rl-zoo's record, for rl_zoo3.enjoy: the env id's block as written, and the arguments
    write_zoo_params(
        out,
        env_id,
        zoo_hyperparams(env_id, hyperparams_path),
        {
            "algo": algo,
            "env": env_id,
            "conf_file": str(hyperparams_path),
            "env_kwargs": env_kwargs or None,
            "hyperparams": {"n_envs": n_envs} if n_envs != params.get("n_envs", 1) else None,
            "n_timesteps": timesteps,
            "seed": seed,
            "device": device,
            "num_threads": num_threads,
        },
    )
    write_text_atomic(out / "config.yml", yaml.safe_dump(summary, sort_keys=False))
    plot_training_curve(out)
    return summary


def _clone_teacher(
    model: Any,
    env_id: str,
    env_kwargs: dict[str, Any],
    seed: int,
    spec: dict[str, Any],
    use_masking: bool = True,
) -> list[dict[str, Any]]:
    """Behaviour cloning of a teacher's menu choices before PPO (training seeds; ``teacher``:
    explore_lite, the frontier agent's choice, by default): ``episodes`` driven by the teacher,
    then ``dagger_rounds`` rounds of ``dagger_episodes`` driven by the cloned policy and
    labelled by the teacher (DAgger), refitting on all.
    Without ``use_masking`` every action counts as allowed (the learner's and the loss's).
    Returns per fit: decisions, final loss and the actor's agreement with the teacher.

    ``from_model``: instead, copy the actor of an earlier run's clone (the anchor of a
    fine-tuned model in ``from_model``, a folder or ``.zip``), so that fine-tuning variants
    start from the same clone."""
    from sfw_gym.rl.goal_policy import (
        Demonstrations,
        behaviour_clone,
        teacher_agreement,
        teacher_decisions,
    )

    keys = {"episodes", "epochs", "dagger_rounds", "dagger_episodes", "teacher", "from_model"}
    unknown = set(spec) - keys
    if unknown:
        raise ConfigError(f"behaviour_cloning: unknown keys {sorted(unknown)}")
    if "from_model" in spec:
        _copy_clone(model, Path(spec["from_model"]))
        return [{"from_model": str(spec["from_model"])}]
    epochs, first = int(spec.get("epochs", 30)), int(spec.get("episodes", 8))
    per_round = int(spec.get("dagger_episodes", 4))

    def decisions(seeds: range, learner: Any = None) -> Demonstrations:
        obs, acts, masks = teacher_decisions(
            env_id, env_kwargs, seeds, learner, use_masking, spec.get("teacher", "explore_lite")
        )
        return Demonstrations(obs, acts, masks if use_masking else np.ones_like(masks))

    fits: list[dict[str, Any]] = []

    def fit() -> None:
        losses = behaviour_clone(model.policy, demos, epochs=epochs)
        agreement = teacher_agreement(model.policy, demos)
        fits.append(
            {
                "decisions": len(demos.actions),
                "final_loss": float(losses[-1]) if losses else None,
                "teacher_agreement": round(float(agreement), 4),
            }
        )

    demos = decisions(range(seed, seed + first))
    fit()
    for i in range(int(spec.get("dagger_rounds", 0))):
        start = seed + first + i * per_round
        demos = demos.joined(decisions(range(start, start + per_round), model.policy))
        fit()
    return fits


def _copy_clone(model: Any, path: Path) -> None:
    """Copy the actor of the cloned policy saved at ``path`` (a fine-tuned model's anchor; else
    its policy) into ``model``'s actor."""
    import torch

    from sfw_gym.rl.finetune import AnchoredMaskablePPO

    source = AnchoredMaskablePPO.load(find_model(path) if path.is_dir() else path)
    clone: Any = source.anchor if source.anchor is not None else source.policy
    mine, theirs = model.policy.parameter_groups()["actor"], clone.parameter_groups()["actor"]
    if [p.shape for p in mine] != [p.shape for p in theirs]:
        raise ConfigError(f"behaviour_cloning.from_model: {path}'s actor differs from this one")
    with torch.no_grad():
        for dst, src in zip(mine, theirs, strict=True):
            dst.copy_(src)


def _continue_evaluations(callback: Any, path: Path, up_to_steps: int) -> None:
    """Load the held-out evaluations recorded up to ``up_to_steps`` (the resumed checkpoint)
    into SB3's ``EvalCallback``, which would otherwise start its file afresh."""
    if not path.is_file():
        return
    try:
        with np.load(path) as data:
            keep = data["timesteps"] <= up_to_steps
            callback.evaluations_timesteps = data["timesteps"][keep].tolist()
            callback.evaluations_results = data["results"][keep].tolist()
            callback.evaluations_length = data["ep_lengths"][keep].tolist()
    except (OSError, KeyError, ValueError, zipfile.BadZipFile) as exc:
        raise ConfigError(f"{path}: cannot resume its evaluations ({exc})") from None


def _monitored_seconds(out: Path) -> float:
    """Training wall time over every run segment: the last complete episode end time of each
    monitor (a line cut short by a kill is skipped)."""
    total = 0.0
    for csv in out.glob("train_*.monitor.csv"):
        for line in reversed(csv.read_text(encoding="utf-8", errors="replace").splitlines()[2:]):
            cells = line.split(",")
            try:
                total += float(cells[2])
                break
            except (IndexError, ValueError):
                continue
    return total


def _save_atomic(model: Any, path: Path) -> None:
    with atomic_path(path) as tmp:
        model.save(tmp)


def plot_training_curve(out_dir: str | Path, levels: dict[str, float] | None = None) -> Path | None:
    """Episode return (training, smoothed) and held-out evaluation return vs agent steps → PNG;
    ``levels``: other policies' mean held-out return, drawn as horizontal lines."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    steps: list[float] = []
    returns: list[float] = []

    def start_of(path: Path) -> int:
        return int(path.name.split("_")[1].split(".")[0])

    for csv in sorted(out.glob("train_*.monitor.csv"), key=start_of):
        offset_steps = start_of(csv)
        lines = csv.read_text().splitlines()[2:]  # a JSON header line, then the column names
        if not lines:
            continue
        data = np.loadtxt(lines, delimiter=",", ndmin=2, usecols=(0, 1))
        # columns r, l, t: cumulative episode lengths give the env step at each episode's end
        steps.extend(offset_steps + np.cumsum(data[:, 1]) * 1.0)
        returns.extend(data[:, 0])
    evals = out / "eval" / "evaluations.npz"
    if not steps and not evals.exists():
        return None
    fig, ax = plt.subplots(figsize=(7, 4))
    if steps:
        order = np.argsort(steps)
        s, r = np.asarray(steps)[order], np.asarray(returns)[order]
        ax.plot(s, r, ".", alpha=0.25, label="training episodes")
        k = max(1, len(r) // 20)
        smooth = np.convolve(r, np.ones(k) / k, mode="valid")  # trailing mean, no edge dip
        ax.plot(s[k - 1 :], smooth, label=f"training (mean of last {k})")
    if evals.exists():
        ev = np.load(evals)
        ax.errorbar(
            ev["timesteps"],
            ev["results"].mean(1),
            yerr=ev["results"].std(1),
            fmt="o-",
            label="held-out seeds",
        )
    for (name, level), style in zip((levels or {}).items(), ("--", ":", "-."), strict=False):
        ax.axhline(level, color="k", linestyle=style, linewidth=1, label=name)
    ax.set_xlabel("agent steps (waypoints with WaypointWrapper; goal decisions with ppo_mask)")
    ax.set_ylabel("episode return")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    path = out / "training_curve.png"
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110)
    plt.close(fig)
    return path
