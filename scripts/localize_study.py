"""WiFi Monte-Carlo localisation on Gaussian gridmaps (issue 16): the paper's Tables I–III on
generated plans, global localisation, kidnapping, speed.

    python scripts/localize_study.py [--plans 10] [--runs 3] [--workers 2] [--out runs/localize]

Per held-out plan (seeds 2,000,000+): one frontier episode on ``SfW-ExploreDrift-v0`` (16
background APs, drifting odometry) of 2,000 + ``--test-steps`` steps. The first 2,000 steps'
true positions and fingerprints are the survey (binned to 0.25 m); the rest is the test drive:
MCL from one reading (Alg. 1, no prior), then odometry increments and fingerprints. ``--runs``
MCL runs (particle seeds) per plan and setting. Error: distance of the weighted mean to the
true position, over the test steps after the first 10 (mean, and the max over the run).
Writes ``OUT/tables.md`` and ``OUT/records.json``.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

SURVEY_STEPS = 2000
RESOLUTIONS_M = (0.1, 0.25, 0.5, 1.0, 2.0, 3.0, 5.0)
DTYPES = ("float64", "float16", "uint8")
SETTLE_STEPS = 10


def record(seed: int, steps: int) -> dict[str, Any]:
    import gymnasium as gym

    import sfw_gym  # noqa: F401  (registration)
    from sfw_gym.agents import FrontierAgent

    env = gym.make("SfW-ExploreDrift-v0", max_steps=steps)
    obs, info = env.reset(seed=seed)
    agent = FrontierAgent()
    agent.reset(env, seed=seed)
    infos, done = [info], False
    while not done:
        obs, _, terminated, truncated, info = env.step(agent.act(obs))
        infos.append(info)
        done = terminated or truncated
    u = env.unwrapped
    return {
        "truth": np.array([i["true_pose"] for i in infos]),
        "odometry": np.array([i["odometry_pose"] for i in infos]),
        "fingerprints": np.array([i["fingerprint"] for i in infos]),
        "bounds": u.scene.floorplan.bounds,
    }


def mcl_run(maps, run: dict[str, Any], seed: int, particles: int, direct=None) -> dict[str, Any]:
    """One localisation run on the test drive (``direct``: predict with this GP model)."""
    from sfw_gym.localization import MclConfig, WifiMCL
    from sfw_gym.slam import relative_pose

    truth, odo, fp = run["truth"], run["odometry"], run["fingerprints"]
    mcl = WifiMCL(maps, MclConfig(particles=particles), np.random.default_rng(seed), direct=direct)
    start = SURVEY_STEPS
    mcl.global_init(fp[start])
    errors, update_s = [], 0.0
    for k in range(start + 1, len(truth)):
        mcl.predict(relative_pose(odo[k - 1], odo[k]))
        t0 = time.perf_counter()
        mcl.update(fp[k])
        update_s += time.perf_counter() - t0
        errors.append(float(np.hypot(*(mcl.estimate()[0][:2] - truth[k, :2]))))
    e = np.array(errors)
    return {
        "mean_m": float(e[SETTLE_STEPS:].mean()),
        "max_m": float(e[SETTLE_STEPS:].max()),
        "first_below_2m": int(np.argmax(e < 2.0)) + 1 if (e < 2.0).any() else -1,
        "update_ms": 1e3 * update_s / len(e),
    }


def kidnap_run(maps, run: dict[str, Any], seed: int, particles: int) -> dict[str, Any]:
    """Track from the true start, then jump (odometry sees nothing) to the test pose farthest
    away among the second half; steps until the error is below 2 m again."""
    from sfw_gym.localization import MclConfig, WifiMCL
    from sfw_gym.slam import relative_pose

    truth, odo, fp = run["truth"], run["odometry"], run["fingerprints"]
    start = SURVEY_STEPS
    half = (len(truth) - start) // 2
    before = range(start + 1, start + half)
    away = (
        start
        + half
        + int(np.argmax(np.hypot(*(truth[start + half :, :2] - truth[start + half - 1, :2]).T)))
    )
    after = range(away + 1, len(truth))
    mcl = WifiMCL(maps, MclConfig(particles=particles), np.random.default_rng(seed))
    mcl.init_at(truth[start])
    for k in before:
        mcl.predict(relative_pose(odo[k - 1], odo[k]))
        mcl.update(fp[k])
    mcl.predict((0.0, 0.0, 0.0))
    mcl.update(fp[away])
    for n, k in enumerate(after, 1):
        mcl.predict(relative_pose(odo[k - 1], odo[k]))
        mcl.update(fp[k])
        if np.hypot(*(mcl.estimate()[0][:2] - truth[k, :2])) < 2.0:
            return {
                "jump_m": float(np.hypot(*(truth[away, :2] - truth[start + half - 1, :2]))),
                "recovered_after": n,
            }
    return {
        "jump_m": float(np.hypot(*(truth[away, :2] - truth[start + half - 1, :2]))),
        "recovered_after": -1,
    }


def plan_study(job: dict[str, Any]) -> dict[str, Any]:
    from sfw_gym.localization import GaussianGridmaps, SignalModel, Survey

    run = record(job["seed"], SURVEY_STEPS + job["test_steps"])
    survey = Survey.from_dbm(
        run["truth"][:SURVEY_STEPS, :2], run["fingerprints"][:SURVEY_STEPS]
    ).binned(0.25)
    out: dict[str, Any] = {"seed": job["seed"], "survey_samples": len(survey.positions)}
    models = {}
    for name, per_ap in (("GP", False), ("mGP", True)):
        t0 = time.perf_counter()
        models[name] = SignalModel(survey, per_ap=per_ap)
        out[f"fit_s_{name}"] = time.perf_counter() - t0
    rows = []
    seeds = range(job["runs"])
    p = job["particles"]
    bounds = run["bounds"]
    for name, model in models.items():
        maps = GaussianGridmaps.from_model(model, bounds, 0.25)
        for s in seeds:
            rows.append(
                {"table": "I", "model": name, "source": "gridmaps", **mcl_run(maps, run, s, p)}
            )
            if job["direct"]:
                rows.append(
                    {
                        "table": "I",
                        "model": name,
                        "source": "direct",
                        **mcl_run(maps, run, s, p, model),
                    }
                )
    mgp = models["mGP"]
    for mean_dtype in DTYPES:
        for var_dtype in DTYPES:
            maps = GaussianGridmaps.from_model(mgp, bounds, 0.25, (mean_dtype, var_dtype))
            for s in seeds:
                rows.append(
                    {
                        "table": "II",
                        "mean": mean_dtype,
                        "var": var_dtype,
                        **mcl_run(maps, run, s, p),
                    }
                )
    for r in RESOLUTIONS_M:
        maps = GaussianGridmaps.from_model(mgp, bounds, r)
        for s in seeds:
            rows.append(
                {
                    "table": "III",
                    "resolution": r,
                    "memory_kib": maps.memory_bytes / 1024,
                    **mcl_run(maps, run, s, p),
                }
            )
    maps = GaussianGridmaps.from_model(mgp, bounds, 0.25)
    for s in seeds:
        rows.append({"table": "kidnap", **kidnap_run(maps, run, s, p)})
    # speed: one update, 1,000 particles, gridmaps vs direct prediction, side by side
    from sfw_gym.localization import MclConfig, WifiMCL

    timing = {}
    for label, direct in (("gridmaps", None), ("direct", mgp)):
        mcl = WifiMCL(maps, MclConfig(particles=1000), np.random.default_rng(0), direct=direct)
        mcl.init_at(run["truth"][SURVEY_STEPS])
        t0 = time.perf_counter()
        for k in range(SURVEY_STEPS, SURVEY_STEPS + 20):
            mcl.update(run["fingerprints"][k])
        timing[label] = 1e3 * (time.perf_counter() - t0) / 20
    out["update_ms_1000"] = timing
    out["rows"] = rows
    return out


def stats(values: list[float]) -> str:
    from sfw_gym.evaluation.stats import mean_ci95

    mean, half, _ = mean_ci95(values)
    return f"{mean:.2f} ± {half:.2f}"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--plans", type=int, default=10)
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--test-steps", type=int, default=500)
    p.add_argument("--particles", type=int, default=500)
    p.add_argument("--no-direct", action="store_true", help="skip direct GP prediction (slow)")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--out", default="runs/localize")
    args = p.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    jobs = [
        {
            "seed": s,
            "runs": args.runs,
            "test_steps": args.test_steps,
            "particles": args.particles,
            "direct": not args.no_direct,
        }
        for s in range(2_000_000, 2_000_000 + args.plans)
    ]
    start = time.perf_counter()
    with ProcessPoolExecutor(args.workers, mp_context=mp.get_context("spawn")) as pool:
        plans = list(pool.map(plan_study, jobs))
    rows = [r for plan in plans for r in plan["rows"]]
    n_runs = args.plans * args.runs

    def pick(**match: Any) -> list[dict[str, Any]]:
        return [r for r in rows if all(r.get(k) == v for k, v in match.items())]

    lines = [
        f"{args.plans} held-out plans × {args.runs} MCL runs = {n_runs} runs per setting, "
        f"{args.particles} particles, {args.test_steps} test steps; mean error (m, mean ± 95 % CI "
        f"over runs) and the max over each run (mean of the maxima, and the largest). "
        f"{time.perf_counter() - start:.0f} s on {args.workers} workers.",
        "",
        "Table I analogue (gridmaps at 0.25 m, float64):",
        "",
        "| model | source | mean error [m] | max error [m] (mean / largest) |",
        "|---|---|---:|---:|",
    ]
    for model in ("GP", "mGP"):
        for source in ("direct", "gridmaps"):
            rs = pick(table="I", model=model, source=source)
            if rs:
                lines.append(
                    f"| {model} | {source} | {stats([r['mean_m'] for r in rs])} | "
                    f"{np.mean([r['max_m'] for r in rs]):.2f} / {max(r['max_m'] for r in rs):.2f} |"
                )
    lines += ["", "Table II analogue (mGP, 0.25 m): mean error [m] by mean × variance dtype:", ""]
    lines += ["| mean \\ variance | " + " | ".join(DTYPES) + " |", "|---|" + "---:|" * len(DTYPES)]
    for m in DTYPES:
        cells = [stats([r["mean_m"] for r in pick(table="II", mean=m, var=v)]) for v in DTYPES]
        lines.append(f"| {m} | " + " | ".join(cells) + " |")
    lines += ["", "Table III analogue (mGP, float64):", ""]
    lines += [
        "| resolution [m] | memory per AP pair of maps [KiB] | mean error [m] | max [m] |",
        "|---:|---:|---:|---:|",
    ]
    for res in RESOLUTIONS_M:
        rs = pick(table="III", resolution=res)
        lines.append(
            f"| {res} | {np.mean([r['memory_kib'] for r in rs]) / 16:.1f} | "
            f"{stats([r['mean_m'] for r in rs])} | {np.mean([r['max_m'] for r in rs]):.2f} |"
        )
    first = [r["first_below_2m"] for r in pick(table="I", model="mGP", source="gridmaps")]
    reached = [f for f in first if f > 0]
    kid = pick(table="kidnap")
    rec = [r["recovered_after"] for r in kid if r["recovered_after"] > 0]
    speed = [plan["update_ms_1000"] for plan in plans]
    fits = {m: np.mean([plan[f"fit_s_{m}"] for plan in plans]) for m in ("GP", "mGP")}
    lines += [
        "",
        f"Global localisation (mGP gridmaps): error < 2 m within 1 step in "
        f"{sum(f == 1 for f in first)}/{len(first)} runs, within 10 steps in "
        f"{sum(0 < f <= 10 for f in first)}/{len(first)}, ever in {len(reached)}/{len(first)}.",
        f"Kidnapping (jumps of {np.mean([r['jump_m'] for r in kid]):.1f} m on average): recovered "
        f"(error < 2 m) in {len(rec)}/{len(kid)} runs, after a median of "
        f"{np.median(rec) if rec else float('nan'):.0f} steps (max {max(rec) if rec else -1}).",
        f"Speed, one update of 1,000 particles, 16 APs: gridmaps "
        f"{np.mean([s['gridmaps'] for s in speed]):.2f} ms, direct mGP prediction "
        f"{np.mean([s['direct'] for s in speed]):.1f} ms "
        f"({np.mean([s['direct'] / s['gridmaps'] for s in speed]):.0f}× slower), same run.",
        f"GP fits on the binned survey ({np.mean([plan['survey_samples'] for plan in plans]):.0f} "
        f"samples): GP {fits['GP']:.1f} s, mGP {fits['mGP']:.1f} s per plan.",
    ]
    text = "\n".join(lines) + "\n"
    (out / "tables.md").write_text(text)
    (out / "records.json").write_text(
        json.dumps([{k: v for k, v in plan.items()} for plan in plans], indent=1)
    )
    print(text)


if __name__ == "__main__":
    main()
