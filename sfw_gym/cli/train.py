"""``sfw-gym train``: train a PPO policy (stable-baselines3, or RLlib with ``--backend rllib``),
saying first which policy, what one timestep counts and roughly how long it takes."""

from __future__ import annotations

import argparse
from typing import Any, NamedTuple

from sfw_gym.cli.options import (
    DEFAULT_ENV,
    LOCAL_RAY,
    add_backend,
    add_env,
    add_no_progress,
    add_out_folder,
    add_seed,
    non_negative_int,
    positive_int,
)
from sfw_gym.core.errors import ConfigError

EXAMPLE = "sfw-gym train ppo_mask --env SfW-ExploreRegions-v0 --out runs/regions --resume"
HELP = "train an agent (PPO: stable-baselines3, or RLlib with --backend rllib)"
#: How the default learned agent (``regions-ppo``) is trained: the help's and the notice's hint.
DEFAULT_AGENT_COMMAND = "sfw-gym train ppo_mask --env SfW-ExploreRegions-v0"
#: ``--num-threads``' default: one PyTorch thread suits these small networks (more contend with
#: the env workers for the cores; :func:`sfw_gym.rl.training.train_ppo`).
TORCH_THREADS = 1


class Policy(NamedTuple):
    """What ``sfw-gym train`` learns on one kind of env, and how fast the shipped run went
    (docs/results/training.md: 2-core CPU, one torch thread, the shipped hyperparameters)."""

    what: str  # the policy, and the agent that acts with it
    timestep: str  # what one of --timesteps is
    per_second: float | None  # timesteps a second (None: not measured)
    fixed_s: float = 0.0  # time before PPO (behaviour cloning)
    example: int = 0  # a run's timesteps, for the help's time estimate


#: Decisions a second of one wheels-ppo training run, measured with three side by side on 2
#: cores (the shipped runs, docs/results/training.md); one alone is faster.
WHEELS_DECISIONS_PER_S = 377.0
#: By env id (and ``env`` for any other env, with no wrapper in its hyperparameters).
POLICIES = {
    # 30,000 decisions in 1,228 s, 555 s of cloning before them (the shipped
    # SfW-ExploreRegions-v0_1's config.yml: wall_time_s, total_wall_time_s)
    "SfW-ExploreRegions-v0": Policy(
        "the region policy of regions-ppo, the default learned agent",
        "one region decision (up to 20 env steps)",
        30_000 / 1228,
        555.0,
        30_000,
    ),
    # 200,192 decisions in 1,373 s, cloning included (SfW-ExploreGoals-v0_1's run)
    "SfW-ExploreGoals-v0": Policy(
        "the candidate-goal policy of goals-ppo",
        "one goal decision (up to 80 env steps)",
        200_192 / 1373,
        0.0,
        200_000,
    ),
    # ppo.yml's SfW-Explore-v0 block: a wheel command every 4 env steps (ActionRepeat);
    # WHEELS_DECISIONS_PER_S from the shipped runs (SfW-Explore-v0_2)
    "wheels": Policy(
        "the wheels policy of wheels-ppo, from scratch",
        "one decision (a wheel command held for 4 env steps)",
        WHEELS_DECISIONS_PER_S,
        0.0,
        500_000,
    ),
    # an older block wrapped SfW-Explore-v0 in WaypointWrapper: ~48 waypoints/s (v0_1's run)
    "waypoint": Policy(
        "the block-waypoint policy of waypoint-ppo",
        "one waypoint (about 35 env steps, at most 60)",
        48.0,
        0.0,
        200_000,
    ),
    "env": Policy("a policy over the env's own actions", "one env step", None),
}


def duration(seconds: float) -> str:
    """A rough time: minutes, or hours beyond 90 minutes."""
    if seconds < 60:
        return "under a minute"
    return f"{seconds / 60:.0f} min" if seconds < 90 * 60 else f"{seconds / 3600:.1f} h"


def policy_of(env_id: str, params: dict[str, Any]) -> Policy:
    """What training on ``env_id`` with the hyperparameter block ``params`` learns."""
    if "WaypointWrapper" in str(params.get("env_wrapper")):
        return POLICIES["waypoint"]
    if "ActionRepeat" in str(params.get("env_wrapper")):
        return POLICIES["wheels"]
    return POLICIES.get(env_id.rpartition(":")[2], POLICIES["env"])


def describe() -> str:
    """``train --help``'s description: per env, what is trained and what a timestep is."""
    lines = [
        "Train a PPO policy. What it learns, and what one timestep (--timesteps) counts, depend "
        "on --env;",
        "times with the shipped hyperparameters on 2 CPU cores (docs/results/training.md):",
    ]
    for env_id, key, algo in (
        ("SfW-ExploreRegions-v0", "SfW-ExploreRegions-v0", "ppo_mask"),
        ("SfW-ExploreGoals-v0", "SfW-ExploreGoals-v0", "ppo_mask"),
        (f"{DEFAULT_ENV} (the default --env)", "wheels", "ppo"),
    ):
        policy = POLICIES[key]
        took = duration(policy.fixed_s + policy.example / (policy.per_second or 1.0))
        lines += [
            f"  {env_id}, {algo}: {policy.what};",
            f"    a timestep is {policy.timestep}; {policy.example:,} take about {took}",
        ]
    lines += [
        f"  any other env: {POLICIES['env'].what}; a timestep is {POLICIES['env'].timestep}",
        f"The default learned agent, regions-ppo, is trained by: {DEFAULT_AGENT_COMMAND}",
    ]
    return "\n".join(lines)


def notice(env_id: str, params: dict[str, Any], timesteps: int | None, rllib: bool = False) -> str:
    """The line printed as training starts: which policy, what a timestep is, how long (the
    times were measured with stable-baselines3, not RLlib)."""
    policy = policy_of(env_id, params)
    line = f"sfw-gym train: on {env_id}, training {policy.what}; one timestep is {policy.timestep}"
    if timesteps and policy.per_second and not rllib:
        took = duration(policy.fixed_s + timesteps / policy.per_second)
        line += f", so {timesteps:,} timesteps take roughly {took} on 2 CPU cores"
    elif timesteps:
        measured = "stable-baselines3 only" if rllib else "other envs only"
        line += f"; {timesteps:,} timesteps (times were measured for {measured})"
    if policy is not POLICIES["SfW-ExploreRegions-v0"]:
        line += f". The default learned agent, regions-ppo, is trained by: {DEFAULT_AGENT_COMMAND}"
    return line


DESCRIPTION = describe()


def add_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "algo",
        choices=["ppo", "ppo_mask"],
        help="ppo, or ppo_mask (MaskablePPO, for SfW-ExploreGoals-v0 and SfW-ExploreRegions-v0)",
    )
    add_env(parser)
    parser.add_argument(
        "--timesteps",
        type=positive_int,
        default=None,
        help="total timesteps, what one counts depends on --env (above) "
        "(default: the YAML block's n_timesteps, as rl-zoo)",
    )
    parser.add_argument(
        "--n-envs", type=positive_int, default=None, help="parallel envs (default: YAML)"
    )
    parser.add_argument(
        "--vec-env",
        choices=_vec_envs(),
        default="native",
        help="native: the n envs step together in this process (SubprocVecEnv under an "
        "env_wrapper); subproc: SB3's SubprocVecEnv, one worker process per env",
    )
    add_seed(parser, "seed of the run")
    add_out_folder(
        parser, None, "output folder (default: runs/ALGO/ENV; rllib: runs/rllib_ppo/ENV)"
    )
    parser.add_argument(
        "--hyperparams",
        default=None,
        help="rl-zoo YAML (default: the shipped <algo>.yml; rllib: rllib_ppo.yml)",
    )
    parser.add_argument("--checkpoint-every", type=positive_int, default=50_000, help="timesteps")
    parser.add_argument("--eval-every", type=positive_int, default=25_000, help="timesteps")
    parser.add_argument("--eval-episodes", type=positive_int, default=5, help="held-out episodes")
    parser.add_argument(
        "--num-threads",
        type=non_negative_int,
        default=TORCH_THREADS,
        help="PyTorch CPU threads (1 suits the small networks; 0: PyTorch's own choice)",
    )
    add_backend(
        parser,
        ["sb3", "rllib"],
        "sb3 (stable-baselines3) or rllib (Ray RLlib; pip install 'sfw-gym[ray]')",
    )
    parser.add_argument(
        "--num-env-runners",
        type=non_negative_int,
        default=None,
        help="with --backend rllib: Ray processes collecting episodes (default: 0, the driver)",
    )
    parser.add_argument(
        "--address",
        default=None,
        help=f"with --backend rllib: a Ray cluster's address ('auto') (default: {LOCAL_RAY})",
    )
    parser.add_argument(
        "--device",
        default="auto",
        help="PyTorch device of the policy: auto (a GPU where there is one), cpu, cuda, ...",
    )
    parser.add_argument("--resume", action="store_true", help="continue from the last checkpoint")
    add_no_progress(parser)


def _vec_envs() -> tuple[str, ...]:
    from sfw_gym.rl.training import VEC_ENVS

    return VEC_ENVS


def _print_notice(
    env_id: str, hyperparams: Any, timesteps: int | None, rllib: bool = False
) -> None:
    """:func:`notice`, where the hyperparameters read (else training reports the error)."""
    from sfw_gym.rl.training import resolve_timesteps, zoo_hyperparams

    try:
        params = zoo_hyperparams(env_id, hyperparams)
        steps: int | None = resolve_timesteps(timesteps, params, env_id)
    except ConfigError:
        return
    print(notice(env_id, params, steps, rllib), flush=True)


def run(args: argparse.Namespace) -> int:
    import gymnasium as gym

    from sfw_gym.core.data import default_hyperparams
    from sfw_gym.rl.training import train_ppo

    if ":" not in args.env:  # ("module:Env-v0" registers on import, in the workers)
        gym.spec(args.env)  # an unknown id: an --env error, not a missing YAML block
    if args.backend == "rllib":
        return _train_on_rllib(args)
    if args.num_env_runners is not None or args.address is not None:
        raise ConfigError("--num-env-runners and --address need --backend rllib")
    hyperparams = args.hyperparams or default_hyperparams(args.algo)
    _print_notice(args.env, hyperparams, args.timesteps)
    summary = train_ppo(
        args.env,
        args.timesteps,
        args.out or f"runs/{args.algo}/{args.env}",
        n_envs=args.n_envs,
        seed=args.seed,
        hyperparams_path=hyperparams,
        algo=args.algo,
        checkpoint_every=args.checkpoint_every,
        eval_every=args.eval_every,
        eval_episodes=args.eval_episodes,
        resume=args.resume,
        progress_bar=not args.no_progress,
        num_threads=args.num_threads or None,
        vec_env=args.vec_env,
        device=args.device,
    )
    print(
        f"trained {args.env} to "
        f"{summary['steps']:,} steps in {summary['wall_time_s']:.0f} s; model: {summary['model']}"
    )
    return 0


def _train_on_rllib(args: argparse.Namespace) -> int:
    from sfw_gym.rl.rllib import RLLIB_HYPERPARAMS, train_rllib

    if args.algo != "ppo":
        raise ConfigError(f"--backend rllib trains ppo only, got {args.algo!r}")
    if args.n_envs is not None:
        raise ConfigError("--n-envs is the stable-baselines3 backend's; RLlib: --num-env-runners")
    hyperparams = args.hyperparams or RLLIB_HYPERPARAMS
    _print_notice(args.env, hyperparams, args.timesteps, rllib=True)
    summary = train_rllib(
        args.env,
        args.timesteps,
        args.out or f"runs/rllib_ppo/{args.env}",
        num_env_runners=args.num_env_runners or 0,
        seed=args.seed,
        hyperparams_path=hyperparams,
        checkpoint_every=args.checkpoint_every,
        resume=args.resume,
        progress_bar=not args.no_progress,
        address=args.address,
    )
    print(
        f"trained {args.env} with RLlib to {summary['steps']:,} steps "
        f"({summary['iterations']} iterations) in {summary['wall_time_s']:.0f} s; "
        f"model: {summary['model']}"
    )
    return 0
