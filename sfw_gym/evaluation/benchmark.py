"""The benchmark protocol (``envs/benchmark-v1.yml``): any agent class through fixed splits of
seeds and plans, the same metrics and bootstrap intervals, into a results file that records the
protocol, package and agent; and the paired comparison of two results files.

A results file (``OUT/results.json``) holds everything but timing fields under keys that do not
change between runs of the same agent, protocol and split, so that two runs give the same bytes
apart from ``timing``; ``OUT/results.md`` has no timing at all, nor has ``OUT/index.html``, the
same tables rendered for a browser.
"""

from __future__ import annotations

import hashlib
import json
import time
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from sfw_gym.core.atomic import write_text_atomic
from sfw_gym.core.data import data_path
from sfw_gym.core.errors import ConfigError
from sfw_gym.evaluation.checkpoint import require_same_run
from sfw_gym.evaluation.executor import Executor
from sfw_gym.evaluation.metric_table import METRICS
from sfw_gym.evaluation.report import PRIVILEGED_NOTE, paired_table, write_report
from sfw_gym.evaluation.stats import bootstrap_ci, paired_comparison

SPLITS = ("train", "validation", "test")
#: Record fields that are timings (left out of results.json's episodes).
TIMING_FIELDS = ("wall_s", "steps_per_s")


# ---------------------------------------------------------------------------------- protocol
def load_protocol(name: str | Path = "benchmark-v1") -> dict[str, Any]:
    """A protocol by name (shipped: ``benchmark-v1``) or path to a YAML file, checked."""
    path = Path(name)
    if not path.suffix:
        path = data_path("envs", f"{name}.yml")
    try:
        text = path.read_text(encoding="utf-8")
        protocol = yaml.safe_load(text)
    except (OSError, yaml.YAMLError) as exc:
        raise ConfigError(f"--protocol {name}: cannot read {path}: {exc}") from None
    where = f"protocol {path}"
    if not isinstance(protocol, dict):
        raise ConfigError(f"{where}: expected a mapping")
    for key in ("name", "version", "envs", "splits", "metrics", "intervals"):
        if key not in protocol:
            raise ConfigError(f"{where}: missing {key!r}")
    seeds = protocol["splits"].get("seeds", {})
    for split in SPLITS:
        lo_hi = seeds.get(split)
        if not (isinstance(lo_hi, list) and len(lo_hi) == 2 and 0 <= lo_hi[0] <= lo_hi[1]):
            raise ConfigError(f"{where}: splits.seeds.{split} must be [first, last], got {lo_hi}")
    for env in protocol["envs"]:
        if not isinstance(env, dict) or "id" not in env or "episodes" not in env:
            raise ConfigError(f"{where}: each env needs an id and episodes per split: {env}")
    unknown = set(protocol["metrics"]) - set(METRICS)
    if unknown:
        known = list(METRICS)
        raise ConfigError(f"{where}: unknown metrics {sorted(unknown)}; known: {known}")
    protocol["sha256"] = hashlib.sha256(text.encode()).hexdigest()
    return protocol


def split_seeds(protocol: dict[str, Any], split: str) -> tuple[int, int]:
    """The split's inclusive range of procedural reset seeds."""
    _check_split(split)
    first, last = protocol["splits"]["seeds"][split]
    return int(first), int(last)


def split_plan_files(protocol: dict[str, Any], folder: str | Path, split: str) -> list[Path]:
    """The plan files of ``folder`` (JSON plans and ROS map YAMLs:
    :func:`~sfw_gym.evaluation.runner.plan_files`) that fall in ``split`` (by name hash)."""
    from sfw_gym.evaluation.runner import plan_files

    _check_split(split)
    buckets = set(protocol["splits"]["plan_files"][split])
    files = [Path(f) for f in plan_files(folder, "--plans") if f]
    return [f for f in files if _bucket(f.name) in buckets]


def _bucket(name: str) -> int:
    return int(hashlib.sha256(name.encode()).hexdigest(), 16) % 10


def _check_split(split: str) -> None:
    if split not in SPLITS:
        raise ConfigError(f"--split must be one of {list(SPLITS)}, got {split!r}")


def agent_seed_for(env_seed: int, agent_seed: int) -> int:
    """The seed an agent is reset with: a mix of the episode's env seed and the agent seed."""
    return int(np.random.SeedSequence([env_seed, agent_seed]).generate_state(1)[0])


# ---------------------------------------------------------------------------------- running
def run_benchmark(
    agent: str,
    *,
    protocol: str | Path = "benchmark-v1",
    split: str = "test",
    out: str | Path = "benchmark",
    agent_params: dict[str, Any] | None = None,
    agent_seed: int = 0,
    plans: str | Path | None = None,
    episodes: int | None = None,
    routers: Any = None,
    workers: int = 1,
    backend: str = "local",
    address: str | None = None,
    progress: bool = True,
) -> dict[str, Any]:
    """Run ``agent`` (a shipped name or ``package.module:Class``) through the protocol's
    ``split``; writes ``OUT/results.json``, ``OUT/results.md`` and ``OUT/index.html`` (the same
    tables for a browser) and returns the results.
    ``episodes`` caps the episodes per env (a quick look; recorded in the results);
    ``routers`` places every episode's routers (positions ``[[x, y], ...]`` or a count; None:
    a plan's own, else the env's k-means placement: :func:`~sfw_gym.envs.episode.build_scene`);
    ``workers``, ``backend`` and ``address`` as :func:`~sfw_gym.evaluation.evaluate`'s."""
    from sfw_gym import __version__
    from sfw_gym.agents import is_privileged
    from sfw_gym.evaluation.rollout import EpisodeSpec
    from sfw_gym.evaluation.runner import check_routers, load_plans, routers_json, run_specs

    proto = load_protocol(protocol)
    first, last = split_seeds(proto, split)
    routers = routers_json(routers)
    out = Path(out)
    specs: list[EpisodeSpec] = []
    for env in proto["envs"]:
        n = int(env["episodes"][split])
        if episodes is not None:
            n = min(n, episodes)
        files: list[str | None] = [None] * n
        if plans is not None:
            files += [str(p) for p in split_plan_files(proto, plans, split)]
        if len(files) > last - first + 1:
            raise ConfigError(f"protocol: {len(files)} episodes exceed the {split} split's seeds")
        distinct_plans = load_plans(files)
        if routers is not None:
            check_routers(env["id"], env.get("kwargs"), routers, distinct_plans, first)
        for i, plan in enumerate(files):
            specs.append(
                EpisodeSpec(
                    agent=agent,
                    episode=len(specs),
                    seed=first + i,
                    agent_seed=agent_seed_for(first + i, agent_seed),
                    env_id=env["id"],
                    floorplan=plan,
                    routers=routers,
                    env_kwargs=dict(env.get("kwargs") or {}),
                    agent_params=dict(agent_params or {}),
                    npz_path=None,
                )
            )
    executor = Executor(workers=workers, backend=backend, address=address, progress=progress)
    run = {
        "protocol_sha256": proto["sha256"],
        "agent": agent,
        "agent_params": json.loads(json.dumps(agent_params or {})),
        "split": split,
        "plans": None if plans is None else str(plans),
    } | ({} if routers is None else {"routers": routers})
    require_same_run(out, run, "benchmark")
    start = time.perf_counter()
    records = run_specs(specs, out, executor)
    results = {
        "protocol": proto["name"],
        "protocol_version": proto["version"],
        "protocol_sha256": proto["sha256"],
        "package_version": __version__,
        "agent": agent,
        "agent_params": dict(agent_params or {}),
        "privileged": is_privileged(agent),
        "agent_seed": agent_seed,
        "split": split,
        "episodes_cap": episodes,
        "plans": None if plans is None else Path(plans).name,
        "episodes": [_episode_row(r, proto) for r in records],
        "timing": {"wall_s": time.perf_counter() - start, "workers": workers},
    } | ({} if routers is None else {"routers": routers})
    results["summary"] = summarize_results(results, proto)
    write_text_atomic(out / "results.json", json.dumps(results, indent=1, sort_keys=True) + "\n")
    write_report(out / "results.md", results_markdown(results))  # and index.html
    return results


def _episode_row(record: dict[str, Any], protocol: dict[str, Any]) -> dict[str, Any]:
    row = {k: record[k] for k in ("env_id", "seed", "floorplan", "steps")}
    for metric in protocol["metrics"]:
        value = record.get(metric)
        if metric == "steps_to_coverage_90" and (value is None or value < 0):
            value = record["max_steps"] + 1  # never got there: censored at the budget
        row[metric] = value
    return row


def _key(row: dict[str, Any]) -> tuple[str, int, str]:
    return row["env_id"], row["seed"], row["floorplan"]


def intervals(protocol: dict[str, Any]) -> dict[str, Any]:
    """The protocol's bootstrap settings, as :func:`~sfw_gym.evaluation.stats.bootstrap_ci`'s
    keywords."""
    iv = protocol["intervals"]
    return {
        "confidence": float(iv["confidence"]),
        "resamples": int(iv["resamples"]),
        "random_state": int(iv["random_state"]),
    }


def _all_zero(values: list[Any]) -> bool:
    """No value, or all zero (as ATE where the odometry does not drift): not reported."""
    v = np.array([x for x in values if x is not None], np.float64)
    return not len(v) or bool(np.allclose(v, 0.0))


def summarize_results(results: dict[str, Any], protocol: dict[str, Any]) -> dict[str, Any]:
    """Per env and metric: mean, interval and n over the episodes (metrics all zero, as ATE
    where the odometry does not drift, are left out)."""
    summary: dict[str, Any] = {}
    for env_id in dict.fromkeys(r["env_id"] for r in results["episodes"]):
        rows = [r for r in results["episodes"] if r["env_id"] == env_id]
        summary[env_id] = {}
        for metric in protocol["metrics"]:
            if _all_zero([r[metric] for r in rows]):
                continue
            values = np.array([r[metric] for r in rows if r[metric] is not None], np.float64)
            low, high = bootstrap_ci(values, **intervals(protocol))
            summary[env_id][metric] = {
                "mean": float(values.mean()),
                "ci_low": low,
                "ci_high": high,
                "n": len(values),
            }
    return summary


def format_interval(stats: dict[str, Any], metric: str) -> str:
    """``mean [low, high]`` of a summary entry, in the metric's format."""
    m = METRICS[metric]
    return f"{m.format(stats['mean'])} [{m.format(stats['ci_low'])}, {m.format(stats['ci_high'])}]"


def results_markdown(results: dict[str, Any]) -> str:
    """The results as a Markdown table per env (no timing)."""
    lines = [
        f"# {results['agent']} on {results['protocol']} / {results['split']}",
        "",
        f"sfw_gym {results['package_version']}, agent seed {results['agent_seed']}, "
        f"protocol sha256 {results['protocol_sha256'][:12]}; mean [95 % bootstrap interval].",
    ]
    if results.get("privileged"):
        lines += ["", PRIVILEGED_NOTE]
    for env_id, metrics in results["summary"].items():
        n = max((s["n"] for s in metrics.values()), default=0)
        lines += ["", f"## {env_id} ({n} episodes)", "", "| metric | value |", "|---|---:|"]
        for metric, stats in metrics.items():
            lines.append(f"| {METRICS[metric].label} | {format_interval(stats, metric)} |")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------------- comparing
def load_results(path: str | Path) -> dict[str, Any]:
    """A ``results.json`` written by :func:`run_benchmark`."""
    try:
        results = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as exc:
        raise ConfigError(f"{path}: not a benchmark results file: {exc}") from None
    if not isinstance(results, dict) or "protocol" not in results or "episodes" not in results:
        raise ConfigError(f"{path}: not a benchmark results file (no protocol or episodes)")
    return results


def compare(a: dict[str, Any], b: dict[str, Any], protocol: str | Path | None = None) -> str:
    """The paired table ``b − a`` per env and metric over the episodes both ran (the same env,
    seed and plan), with the protocol's bootstrap interval. Refuses different protocols."""
    for key in ("protocol", "protocol_version", "protocol_sha256", "split"):
        if a.get(key) != b.get(key):
            raise ConfigError(
                f"cannot compare results of different {key.replace('_', ' ')}s: "
                f"{a.get(key)!r} vs {b.get(key)!r}"
            )
    proto = load_protocol(protocol or a["protocol"])
    if proto["sha256"] != a["protocol_sha256"]:
        raise ConfigError(f"the results were made under another text of {a['protocol']}")
    rows_a = {_key(r): r for r in a["episodes"]}
    pairs = [(rows_a[_key(r)], r) for r in b["episodes"] if _key(r) in rows_a]
    if not pairs:
        raise ConfigError("the two results share no episode (env, seed, plan)")
    groups = []
    for env_id in dict.fromkeys(_key(x)[0] for x, _ in pairs):
        env_pairs = [(x, y) for x, y in pairs if x["env_id"] == env_id]
        metrics = [
            m for m in proto["metrics"] if not _all_zero([v[m] for pair in env_pairs for v in pair])
        ]
        groups.append((env_id, paired_comparison(env_pairs, metrics, **intervals(proto))))
    head = (
        f"{b['agent']} − {a['agent']} on {a['protocol']} / {a['split']}, paired by episode; "
        "mean difference [95 % bootstrap interval]."
    )
    return head + "\n\n" + paired_table(groups, group="env", a=a["agent"], b=b["agent"])
