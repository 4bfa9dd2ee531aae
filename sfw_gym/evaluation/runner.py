"""Run agents on the same floorplans and seeds and compare them: ``sfw-gym evaluate`` and
:func:`evaluate`, the orchestrator over the rollout (:mod:`~sfw_gym.evaluation.rollout`), the
run folder's checkpoint and manifest (:mod:`~sfw_gym.evaluation.checkpoint`), the executor
(:mod:`~sfw_gym.evaluation.executor`), the statistics and the tables.

``sfw-gym evaluate --agents frontier,cross-pass,random --episodes N --seed S`` runs episode ``i``
of every agent with ``env.reset(seed=S + i)``: the same procedural floorplan, routers and start
pose for every agent (with ``floorplans``, plan file ``i mod n_files`` of the folder). Each
finished episode is added to a JSONL checkpoint, so a run that is interrupted resumes where it
stopped. Outputs, every file written atomically (a temp file and ``os.replace``):

- ``episodes.jsonl``: one record per episode (metrics, curves, stop reason);
- ``episodes/<agent>_<i>.npz``: the final belief, the ground truth and the trajectory;
- ``results.csv`` and ``results.md``: per agent the mean ± 95 % CI (Student t) of every metric;
- ``paired.md``: with more than one agent, every other agent against the first, episode by
  episode (mean difference with a seeded 95 % bootstrap interval);
- ``coverage_vs_steps.png`` and ``iou_vs_path.png``: mean curves with 95 % CI bands;
- ``trajectories/<i>_<plan>.png``: per floorplan, every agent's path over the ground truth and
  its final belief;
- optionally ``gifs/<agent>_<i>.gif`` (``render_mode="rgb_array"`` frames);
- ``index.md`` and ``index.html``: the report page (the tables, the curves, the trajectory
  overlays and the GIFs), the HTML rendered from the Markdown for a browser, with relative links
  so the folder can be moved.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from sfw_gym.core.atomic import write_text_atomic
from sfw_gym.core.errors import ConfigError
from sfw_gym.evaluation.checkpoint import (
    CHECKPOINT,
    append_record,
    evaluation_manifest,
    load_checkpoint,
    open_checkpoint,
)
from sfw_gym.evaluation.executor import BACKENDS, Bar, Executor
from sfw_gym.evaluation.plots import plot_curves, plot_trajectories
from sfw_gym.evaluation.report import (
    paired_markdown,
    report_markdown,
    results_csv,
    results_markdown,
    write_report,
)
from sfw_gym.evaluation.rollout import EpisodeSpec, run_episode, zone_band_unknown
from sfw_gym.evaluation.stats import paired_differences, summarize
from sfw_gym.evaluation.vector import check_native_vector_env, run_vector

__all__ = [
    "BACKENDS",
    "CHECKPOINT",
    "EpisodeSpec",
    "check_routers",
    "evaluate",
    "load_checkpoint",
    "load_plans",
    "plan_files",
    "routers_json",
    "run_episode",
    "run_specs",
    "zone_band_unknown",
]


def run_specs(
    specs: Sequence[EpisodeSpec], out: Path, executor: Executor, vector_envs: int = 1
) -> list[dict[str, Any]]:
    """Run the episodes not yet in ``OUT/episodes.jsonl`` (the checkpoint) on ``executor`` (or,
    with ``vector_envs`` > 1, on a vector env of that many sub-envs in this process, through
    the executor's progress bar) and return every spec's record, in the order of ``specs``."""
    records = open_checkpoint(out)
    done = {r["key"] for r in records}
    todo = [s for s in specs if s.key not in done]
    ckpt = out / CHECKPOINT

    def keep(_: int, record: dict[str, Any]) -> None:
        records.append(record)
        append_record(ckpt, record)

    bar = Bar(
        "episodes",
        "ep",
        done=len(specs) - len(todo),
        postfix=lambda r: f"{r['agent']} #{r['episode']} cov {r['coverage']:.2f}",
    )
    if vector_envs > 1:
        executor.consume(run_vector(todo, vector_envs), len(todo), keep, bar)
    else:
        executor.run(run_episode, todo, keep, bar)
    by_key = {r["key"]: r for r in records}
    return [by_key[s.key] for s in specs]


def plan_files(floorplans: str | Path | None, option: str = "--floorplans") -> list[str | None]:
    """The plan files episodes cycle through: a folder's plan files (JSON plans and ROS map
    YAMLs: :func:`~sfw_gym.world.floorplan.floorplan_files`), one file, or ``[None]`` (the
    env's procedural plans); a folder with none is an error that names it."""
    from sfw_gym.world.floorplan import PLAN_SUFFIXES, floorplan_files

    if floorplans is None:
        return [None]
    files = floorplan_files(floorplans)
    if not files:
        raise ConfigError(
            f"{option} {floorplans}: no floorplan files there ({', '.join(PLAN_SUFFIXES)})"
        )
    return [str(p) for p in files]


def load_plans(plans: Sequence[str | None]) -> list[str | None]:
    """The distinct plan files among ``plans`` (None: the env's procedural plans), each loaded
    once so that a malformed one fails before any episode."""
    from sfw_gym.world import load_floorplan

    files = list(dict.fromkeys(plans))
    for plan in files:
        if plan:
            load_floorplan(plan)
    return files


def routers_json(routers: Any) -> list[list[float]] | int | None:
    """``routers`` as JSON keeps it: a count, a list of ``[x, y]``, or None."""
    if routers is None or isinstance(routers, int):
        return routers
    return [[float(x), float(y)] for x, y in routers]


def check_routers(
    env_id: str,
    env_kwargs: dict[str, Any] | None,
    routers: list[list[float]] | int,
    plans: Sequence[str | None],
    seed: int,
) -> None:
    """Reset the env once on each of ``plans`` with ``routers``: ``--routers``' one-line error
    (a router in a plan's wall, more than the env's ``n_routers``) before any episode runs."""
    import gymnasium as gym

    env = gym.make(env_id, **(env_kwargs or {}))
    try:
        for plan in plans:
            options = {"routers": routers} | ({"floorplan": plan} if plan else {})
            try:
                env.reset(seed=seed, options=options)
            except ConfigError as exc:
                raise ConfigError(f"--routers: {exc}") from None
    finally:
        env.close()


def evaluate(
    agents: Sequence[str],
    episodes: int,
    seed: int = 0,
    *,
    out: str | Path = "evaluation",
    env_id: str = "SfW-Explore-v0",
    floorplans: str | Path | None = None,
    env_kwargs: dict[str, Any] | None = None,
    agent_params: dict[str, dict[str, Any]] | None = None,
    routers: Any = None,
    workers: int = 2,
    gif_episodes: int = 0,
    curve_every: int = 10,
    progress: bool = True,
    backend: str = "local",
    address: str | None = None,
    vector_envs: int = 1,
) -> dict[str, Any]:
    """Run (or resume) an evaluation and write its tables, curves, trajectory figures and report
    page (``index.md``, and ``index.html`` for a browser).

    Args:
        agents: Agent names (see :data:`sfw_gym.agents.AGENTS`).
        episodes: Episodes per agent; episode ``i`` uses ``env.reset(seed=seed + i)``.
        seed: Seed of episode 0.
        out: Output folder (created; holds the checkpoint that a rerun resumes from).
        env_id: Gymnasium id.
        floorplans: A folder of plan files, JSON or ROS map YAML (episode ``i`` uses file
            ``i mod n``), or one file; None: the env's procedural plans.
        env_kwargs: Extra ``gym.make`` kwargs (JSON-serialisable).
        agent_params: Per agent name, constructor parameters.
        routers: Every episode's routers, positions ``[[x, y], ...]`` (metres) or a count;
            None: each plan's own routers where it stores them, else the env's k-means
            placement (:func:`~sfw_gym.envs.episode.build_scene`).
        workers: Worker processes (1: run in this process).
        gif_episodes: Write GIFs of the first this many episodes of every agent.
        curve_every: Curve sampling interval, steps.
        progress: Show a tqdm progress bar.
        backend: ``"local"`` (worker processes) or ``"ray"`` (episodes as Ray tasks, at most
            ``workers`` at a time; a task whose worker dies runs again); the same records.
        address: Ray's address (``"auto"``: a running cluster); None starts a local Ray.
        vector_envs: More than 1: run the episodes on the native vector env of this many
            sub-envs instead, stepped together in this process, one agent per sub-env acting
            on its robot view (:mod:`~sfw_gym.evaluation.vector`), with the same records;
            ``workers`` and ``backend`` are then not used, and no GIFs.

    Returns:
        ``{"rows": summary rows, "records": episode records, "files": written paths}``; with
        more than one agent, ``paired.md`` holds every other agent's differences from the first
        on the same plans and seeds (:func:`~sfw_gym.evaluation.stats.paired_differences`).
    """
    import gymnasium as gym

    from sfw_gym.agents import agent_class, known_agent, make_agent, unknown_agents_error

    agents = list(dict.fromkeys(agents))
    if not agents:
        raise ConfigError("--agents: give at least one agent")
    unknown = [a for a in agents if not known_agent(a) and ":" not in a]
    if unknown:
        raise ConfigError(f"--agents: {unknown_agents_error(unknown)}")
    for name in agents:
        agent_class(name)  # an entry point of one's own must import, in this process too
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ConfigError(f"--episodes must be an int >= 1, got {episodes!r}")
    executor = Executor(workers=workers, backend=backend, address=address, progress=progress)
    if isinstance(vector_envs, bool) or not isinstance(vector_envs, int) or vector_envs < 1:
        raise ConfigError(f"--vector-envs must be an int >= 1, got {vector_envs!r}")
    if vector_envs > 1 and (backend != "local" or gif_episodes):
        raise ConfigError("--vector-envs runs the episodes here: not with --backend ray or --gif")
    for name, params in (agent_params or {}).items():  # fail early on bad parameters
        if not isinstance(params, dict):
            raise ConfigError(f"--agent-params: {name!r}: expected a JSON object, got {params!r}")
        try:
            make_agent(name, **params)
        except ConfigError as exc:
            raise ConfigError(f"--agent-params: {exc}") from None
    try:  # and on bad env kwargs (an unknown env id raises gymnasium's NameNotFound)
        gym.make(env_id, **(env_kwargs or {})).close()
    except (TypeError, ConfigError) as exc:
        raise ConfigError(f"--env-kwargs: {exc}") from None
    if vector_envs > 1:
        check_native_vector_env(env_id)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    plans = plan_files(floorplans)
    routers = routers_json(routers)
    distinct_plans = load_plans(plans[:episodes])
    if routers is not None:  # fail early on routers the env refuses (in a wall, too many)
        check_routers(env_id, env_kwargs, routers, distinct_plans, seed)
    specs = [  # episode-major: every agent's episode 0 first
        EpisodeSpec(
            agent=name,
            episode=i,
            seed=seed + i,
            env_id=env_id,
            floorplan=plans[i % len(plans)],
            routers=routers,
            env_kwargs=dict(env_kwargs or {}),
            agent_params=dict((agent_params or {}).get(name, {})),
            curve_every=curve_every,
            gif_path=str(out / "gifs" / f"{name}_{i:04d}.gif") if i < gif_episodes else None,
            npz_path=str(out / "episodes" / f"{name}_{i:04d}.npz"),
        )
        for i in range(episodes)
        for name in agents
    ]
    records = load_checkpoint(out / CHECKPOINT)
    manifest = evaluation_manifest(
        out, records, agents, episodes, seed, env_id, floorplans, env_kwargs, agent_params, routers,
    )  # fmt: skip
    write_text_atomic(out / "config.json", json.dumps(manifest, indent=2) + "\n")
    mine = run_specs(specs, out, executor, vector_envs)
    rows = summarize(mine, agents)
    files = [
        write_text_atomic(out / "results.csv", results_csv(rows)),
        write_text_atomic(out / "results.md", results_markdown(rows)),
    ]
    paired = ""
    if len(agents) > 1:  # every other agent against the first, episode by episode
        paired = paired_markdown(paired_differences(mine, agents, reference=agents[0]))
        files.append(write_text_atomic(out / "paired.md", paired))
    else:  # not a stale table of an earlier run in the same folder
        (out / "paired.md").unlink(missing_ok=True)
    files += plot_curves(mine, agents, out)
    files += plot_trajectories(mine, agents, out)
    files += [Path(s.gif_path) for s in specs if s.gif_path and Path(s.gif_path).is_file()]
    seeds = f"seed {seed}" if episodes == 1 else f"seeds {seed}–{seed + episodes - 1}"
    head = [
        f"# sfw_gym evaluation: {', '.join(agents)} on `{env_id}`",
        "",
        f"{episodes} episode(s) per agent; episode i of every agent on the same floorplan, "
        f"routers and start pose ({seeds}).",
        "",
    ]
    body = report_markdown(out, rows, files, paired=paired)
    files += write_report(out / "index.md", "\n".join(head + body) + "\n")
    return {"rows": rows, "records": mine, "files": files}
