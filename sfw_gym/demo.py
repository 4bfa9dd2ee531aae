"""``sfw-gym demo``: frontier, cross-pass and the shipped learned explorer (PPO over candidate
goals) on a few fresh plans → a report.

Everything comes with the package: procedural floorplans, the default radio, the shipped policies.
The report folder holds ``index.md`` (what ran, the results table, the figures) and
``index.html``, the same page rendered for a browser (open it by double-clicking; its images are
relative links, so the folder can be moved), beside the evaluation's tables and curves,
trajectory overlays per floorplan and one GIF per agent.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from sfw_gym.core.data import scenario

DEMO_AGENTS = ("frontier", "cross-pass", "regions-ppo")
DEMO_ENV = "SfW-Explore-v0"  # the shipped policy's env
#: Floorplan seeds far from those the shipped policy was trained on (its training resets used
#: seeds 0-3 and their RNG streams; its held-out evaluation 1,000,000+): envs/scenarios.yml.
DEMO_SEED = int(scenario("demo")["seed"])
DEMO_EPISODES = int(scenario("demo")["episodes"])


def run_demo(
    out: str | Path = "sfw-report",
    episodes: int = DEMO_EPISODES,
    seed: int = DEMO_SEED,
    *,
    workers: int = 2,
    progress: bool = True,
    model: str | Path | None = None,
) -> Path:
    """Run the demo (resumable, like any evaluation) and write ``OUT/index.md`` and
    ``OUT/index.html`` (the same page for a browser); return the Markdown page's path.

    ``model``: a ``sfw-gym train ppo_mask`` folder (or a ``.zip`` in it) instead of the shipped
    policy.
    """
    # here, not at the top: the command line reads this module's defaults to build its parser
    from sfw_gym.evaluation import evaluate
    from sfw_gym.evaluation.report import write_report

    out = Path(out)
    start = time.perf_counter()
    result = evaluate(
        list(DEMO_AGENTS),
        episodes,
        seed,
        out=out,
        env_id=DEMO_ENV,
        workers=workers,
        gif_episodes=1,
        progress=progress,
        agent_params={"regions-ppo": {"path": str(model)}} if model is not None else None,
    )
    index = out / "index.md"
    wall_s = time.perf_counter() - start
    policy = str(model) if model is not None else "agents/ppo_mask/SfW-ExploreRegions-v0_1"
    write_report(index, _index_markdown(out, result, seed, wall_s, policy))
    return index


def _index_markdown(
    out: Path, result: dict[str, Any], seed: int, wall_s: float, policy: str
) -> str:
    from sfw_gym.evaluation.metric_table import METRICS
    from sfw_gym.evaluation.report import report_markdown

    records = result["records"]
    episodes = sorted({r["episode"] for r in records})
    plans = {r["episode"]: (r["floorplan"], r["area_m2"]) for r in records}
    lines = [
        "# sfw_gym demo: WiFi-only exploration",
        "",
        f"`{DEMO_ENV}` (default radio, two routers, 3,000-step budget): frontier exploration, "
        "frontier with cross-connecting passes and the learned explorer (`regions-ppo`: "
        "MaskablePPO choosing a region of the navigation menu's candidates every 20 steps, "
        f"`{policy}`) on the same "
        "procedural floorplans, start poses and "
        f"seeds ({seed}–{seed + len(episodes) - 1}; never used in training). "
        f"Report written in {wall_s:.0f} s.",
        "",
        "| episode | floorplan | free area |",
        "|---|---|---|",
        *[f"| {i} | {plans[i][0]} | {plans[i][1]:.0f} m² |" for i in episodes],
        "",
    ]
    note = (
        f"*{METRICS['info_gain_per_m'].label}*: the map's entropy decrease per metre driven, what "
        "the reward pays for per unit of effort."
    )
    lines += report_markdown(out, result["rows"], result["files"], note=note)
    return "\n".join(lines) + "\n"
