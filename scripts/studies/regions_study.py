"""The learned region explorer against frontier, the tuned heuristics and the oracles (issues
30 and 40: the benchmark's ceiling).

Runs ``sfw-gym evaluate`` (resuming what is done) with every agent of the comparison on the same
plans and seeds, then prints each agent's bits per metre and coverage as ratios to default
frontier's (ratio of the means, 95 % interval by a paired bootstrap over episodes: the package's
paired comparison, ``compare_paired(..., ratio=True)``), the decisions per episode, the wall
time per step relative to frontier's and per episode. Oracles (privileged) are marked †.
``--budgets`` adds coverage and bits per metre at those step counts (read off each episode's
curve; an episode that ended earlier keeps its final values): run with ``--max-steps`` the
largest.

    python scripts/studies/regions_study.py --episodes 50 --seed 2000000 --out runs/study_test
    python scripts/studies/regions_study.py --episodes 11 \
        --floorplans ../shared/floorplans/houseexpo --out runs/study_hx
    python scripts/studies/regions_study.py --agents frontier,region-teacher --episodes 20 \
        --seed 3000000 --out runs/teacher20      # the teacher before any cloning
    python scripts/studies/regions_study.py --agents frontier,oracle-coverage --episodes 20 \
        --max-steps 10000 --budgets 1000,3000,10000 --out runs/ceiling_budgets
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from sfw_gym.agents import is_privileged
from sfw_gym.evaluation.report import PRIVILEGED_NOTE, agent_label
from sfw_gym.evaluation.runner import evaluate
from sfw_gym.evaluation.stats import compare_paired

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from _docs import RESULTS, command_line, write_block

#: The tuned heuristics of DESIGN.md's sweep: name → (table label, entry point, parameters).
TUNED = {
    "greedy-tuned": (
        "greedy (distance_offset_m=0.3)",
        "sfw_gym.agents.greedy:GreedyInfoGainAgent",
        {"distance_offset_m": 0.3},
    ),
    "frontier-tuned": (
        "frontier (potential_scale=1)",
        "sfw_gym.agents.frontier:FrontierAgent",
        {"potential_scale": 1.0},
    ),
}
DEFAULT_AGENTS = (
    "frontier,regions-ppo,region-teacher,greedy-tuned,frontier-tuned,cross-pass,goals-ppo"
)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument(
        "--agents", default=DEFAULT_AGENTS, help="comma-separated; the first is the reference"
    )
    p.add_argument("--episodes", type=int, default=50)
    p.add_argument("--seed", type=int, default=2_000_000, help="benchmark-v1's test seeds")
    p.add_argument("--floorplans", default=None)
    p.add_argument("--model", default=None, help="the ppo agent's model (default: shipped)")
    p.add_argument("--agent-params", default="{}", help="more per-agent parameters (JSON)")
    p.add_argument("--out", default="runs/regions_study")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--max-steps", type=int, default=None, help="the episodes' step budget")
    p.add_argument("--budgets", default="", help="comma-separated steps: coverage at each")
    p.add_argument(
        "--write-docs",
        default=None,
        metavar="PAGE:BLOCK",
        help="also write the tables into block BLOCK of docs/results/PAGE",
    )
    args = p.parse_args()

    agents, params, label = resolve_agents(args.agents.split(","), json.loads(args.agent_params))
    if args.model and "regions-ppo" in agents:
        params.setdefault("regions-ppo", {})["path"] = args.model
    result = evaluate(
        agents,
        args.episodes,
        args.seed,
        out=args.out,
        floorplans=args.floorplans,
        env_kwargs={"max_steps": args.max_steps} if args.max_steps else None,
        agent_params=params,
        workers=args.workers,
        progress=False,
    )
    records: dict[str, dict[int, dict]] = {}
    for r in result["records"]:
        records.setdefault(r["agent"], {})[r["episode"]] = r
    ref_name = agents[0]
    episodes = sorted(set.intersection(*(set(v) for v in records.values())))

    def column(agent: str, key: str) -> np.ndarray:
        values = [records[agent][i].get(key) for i in episodes]
        return np.array([np.nan if v is None else float(v) for v in values])

    def per_step_ms(agent: str) -> float:
        rows = [records[agent][i] for i in episodes]
        return 1e3 * sum(r["wall_s"] for r in rows) / sum(r["steps"] for r in rows)

    ref_bits, ref_cov = column(ref_name, "info_gain_per_m"), column(ref_name, "coverage")
    lines = [
        f"{len(episodes)} paired episodes, ratios to {label[ref_name]} (95 % paired bootstrap)",
        "",
        "| agent | bits/m ratio | coverage ratio | bits/m | coverage | free IoU | wall precision "
        "| wall recall | collisions | decisions / episode (steps each) | ms / step (× ref) "
        "| s / episode |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    ref_ms = per_step_ms(ref_name)
    for agent in agents:
        bits, cov = column(agent, "info_gain_per_m"), column(agent, "coverage")
        rb = compare_paired(ref_bits, bits, ratio=True)
        rc = compare_paired(ref_cov, cov, ratio=True)
        decisions = np.mean([records[agent][i]["decisions"] for i in episodes])
        steps = np.mean([records[agent][i]["steps"] for i in episodes])
        ms = per_step_ms(agent)
        seconds = np.mean([records[agent][i]["wall_s"] for i in episodes])
        lines.append(
            f"| {label[agent]} | {rb.text('{:.3f}')} | "
            f"{rc.text('{:.3f}')} | {bits.mean():.1f} | {cov.mean():.3f} | "
            f"{np.nanmean(column(agent, 'free_iou')):.3f} | "
            f"{np.nanmean(column(agent, 'wall_precision')):.3f} | "
            f"{np.nanmean(column(agent, 'interior_wall_recall')):.3f} | "
            f"{column(agent, 'collisions').mean():.0f} | "
            f"{decisions:.0f} ({steps / max(decisions, 1):.1f}) | {ms:.2f} ({ms / ref_ms:.2f}×) "
            f"| {seconds:.1f} |"
        )
    budgets = [int(b) for b in args.budgets.split(",") if b]
    if budgets:
        lines += [
            "",
            f"At each step budget: coverage and bits per metre, mean and ratio to "
            f"{label[ref_name]} (95 % paired bootstrap)",
            "",
            "| agent | "
            + " | ".join(f"coverage at {b:,} | bits/m at {b:,}" for b in budgets)
            + " |",
            "|---|" + "---|---|" * len(budgets),
        ]
        at = {
            (a, b, k): np.array([curve_at(records[a][i]["curve"], b)[k] for i in episodes])
            for a in agents
            for b in budgets
            for k in (0, 1)
        }
        for agent in agents:
            ratio = {
                (b, k): compare_paired(at[ref_name, b, k], at[agent, b, k], ratio=True)
                for b in budgets
                for k in (0, 1)
            }
            cells = [
                f"{at[agent, b, k].mean():.3f} ({ratio[b, k].text('{:.3f}')})"
                for b in budgets
                for k in (0, 1)
            ]
            lines.append(f"| {label[agent]} | " + " | ".join(cells) + " |")
    if any(is_privileged(a) for a in agents):
        lines += ["", PRIVILEGED_NOTE]
    text = "\n".join(lines)
    Path(args.out, "ratios.md").write_text(text + "\n", encoding="utf-8")
    print(text)
    if args.write_docs:
        page, block = args.write_docs.split(":")
        write_block(RESULTS / page, block, [f"`{command_line()}`:", "", *lines])


def resolve_agents(
    names: list[str], params: dict[str, dict]
) -> tuple[list[str], dict[str, dict], dict[str, str]]:
    """The agents to evaluate, their parameters and their table labels: a tuned heuristic by
    its entry point, an oracle marked †, a variant with parameters labelled with them."""
    agents, params, label = [], dict(params), {}
    for name in names:
        if name in TUNED:
            label_text, entry, kwargs = TUNED[name]
            agents.append(entry)
            params[entry] = kwargs
            label[entry] = label_text
        else:
            agents.append(name)
            label[name] = agent_label(name, is_privileged(name))
            if params.get(name):  # a variant: name its settings
                settings = ", ".join(f"{k}={v}" for k, v in params[name].items())
                label[name] = f"{label[name]} ({settings})"
    return agents, params, label


def curve_at(curve: list[list[float]], step: int) -> tuple[float, float]:
    """Coverage and bits per metre at ``step`` from an episode's curve (``[step, coverage, IoU,
    path m, entropy bits]`` rows): the last sample at or before it (an episode that ended earlier
    keeps its final values); bits per metre is NaN on a curve without entropy (before issue 46)."""
    rows = [row for row in curve if row[0] <= step]
    last = rows[-1]
    if len(last) < 5 or last[3] <= 0:
        return float(last[1]), float("nan")
    return float(last[1]), float((curve[0][4] - last[4]) / last[3])


if __name__ == "__main__":
    main()
