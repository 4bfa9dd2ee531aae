"""The WiFi-localisation study (``sfw-gym localize``): the paper's Tables I–III on generated
plans, global localisation, kidnapping and speed, with its figures.

Per held-out plan (seeds 2,000,000+): one frontier episode on ``SfW-ExploreDrift-v0`` (16
background APs, drifting odometry) of ``survey_steps`` + ``test_steps`` steps. The first
``survey_steps`` steps' true positions and fingerprints are the survey (binned to 0.25 m); the
rest is the test drive: MCL from one reading (Alg. 1, no prior), then odometry increments and
fingerprints. ``runs`` MCL runs (particle seeds) per plan and setting. Error: the distance of the
weighted mean to the true position over the test steps after the first ``SETTLE_STEPS``; per run
its mean and its max.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path
from typing import Any

import numpy as np

from sfw_gym.core.atomic import atomic_path, write_text_atomic
from sfw_gym.evaluation.drives import record_frontier_drive
from sfw_gym.evaluation.executor import Bar, Executor
from sfw_gym.evaluation.stats import mean_ci95
from sfw_gym.localization import GaussianGridmaps, MclConfig, SignalModel, Survey, WifiMCL
from sfw_gym.slam import relative_pose

SURVEY_CELL_M = 0.25
RESOLUTIONS_M = (0.1, 0.25, 0.5, 1.0, 2.0, 3.0, 5.0)
DTYPES = ("float64", "float16", "uint8")
SETTLE_STEPS = 10
FIRST_SEED = 2_000_000


def record_drive(seed: int, survey_steps: int, test_steps: int) -> dict[str, Any]:
    """A frontier drive on ``SfW-ExploreDrift-v0`` and where its survey ends."""
    drive = record_frontier_drive("SfW-ExploreDrift-v0", seed, survey_steps + test_steps)
    return {**drive, "survey_steps": survey_steps}


def localise(
    maps: GaussianGridmaps,
    drive: dict[str, Any],
    seed: int,
    particles: int,
    direct: SignalModel | None = None,
) -> np.ndarray:
    """Global localisation then tracking along the test drive: the error (m) per step."""
    truth, odo, fp = drive["truth"], drive["odometry"], drive["fingerprints"]
    first = drive["survey_steps"]
    mcl = WifiMCL(maps, MclConfig(particles=particles), np.random.default_rng(seed), direct=direct)
    mcl.global_init(fp[first])
    errors = []
    for k in range(first + 1, len(truth)):
        mcl.predict(relative_pose(odo[k - 1], odo[k]))
        mcl.update(fp[k])
        errors.append(float(np.hypot(*(mcl.estimate()[0][:2] - truth[k, :2]))))
    return np.array(errors)


def kidnapped(maps: GaussianGridmaps, drive: dict[str, Any], seed: int, particles: int):
    """Track from the true start for half the test drive, then jump (odometry sees nothing) to
    the farthest pose of the second half: the jump (m) and the steps until the error is below
    2 m again (-1: never)."""
    truth, odo, fp = drive["truth"], drive["odometry"], drive["fingerprints"]
    first = drive["survey_steps"]
    half = first + (len(truth) - first) // 2
    away = half + int(np.argmax(np.hypot(*(truth[half:, :2] - truth[half - 1, :2]).T)))
    jump = float(np.hypot(*(truth[away, :2] - truth[half - 1, :2])))
    mcl = WifiMCL(maps, MclConfig(particles=particles), np.random.default_rng(seed))
    mcl.init_at(truth[first])
    for k in range(first + 1, half):
        mcl.predict(relative_pose(odo[k - 1], odo[k]))
        mcl.update(fp[k])
    mcl.predict((0.0, 0.0, 0.0))
    mcl.update(fp[away])
    for n, k in enumerate(range(away + 1, len(truth)), 1):
        mcl.predict(relative_pose(odo[k - 1], odo[k]))
        mcl.update(fp[k])
        if np.hypot(*(mcl.estimate()[0][:2] - truth[k, :2])) < 2.0:
            return jump, n
    return jump, -1


def study_plan(job: dict[str, Any]) -> dict[str, Any]:
    """Every setting on one plan (a worker's job)."""
    drive = record_drive(job["seed"], job["survey_steps"], job["test_steps"])
    n = job["survey_steps"]
    truth, prints = drive["truth"][:n, :2], drive["fingerprints"][:n]
    survey = Survey.from_dbm(truth, prints).binned(SURVEY_CELL_M)
    out: dict[str, Any] = {"seed": job["seed"], "survey_samples": len(survey.positions)}
    models = {}
    for name, per_ap in (("GP", False), ("mGP", True)):
        start = time.perf_counter()
        models[name] = SignalModel(survey, per_ap=per_ap)
        out[f"fit_s_{name}"] = time.perf_counter() - start
    rows: list[dict[str, Any]] = []
    particles, bounds, seeds = job["particles"], drive["bounds"], range(job["runs"])

    def add(errors: np.ndarray, **setting: Any) -> None:
        e = errors[SETTLE_STEPS:]
        first = np.flatnonzero(errors < 2.0)
        rows.append(
            {
                **setting,
                "mean_m": float(e.mean()),
                "max_m": float(e.max()),
                "first_below_2m": int(first[0]) + 1 if len(first) else -1,
            }
        )

    curves = {}
    for name, model in models.items():
        maps = GaussianGridmaps.from_model(model, bounds, 0.25)
        runs = [localise(maps, drive, s, particles) for s in seeds]
        curves[name] = np.mean(runs, axis=0).tolist()
        for errors in runs:
            add(errors, table="I", model=name, source="gridmaps")
        if job["direct"]:
            for s in seeds:
                add(
                    localise(maps, drive, s, particles, model),
                    table="I",
                    model=name,
                    source="direct",
                )
    out["curves"] = curves
    mgp = models["mGP"]
    for mean_dtype in DTYPES:
        for var_dtype in DTYPES:
            maps = GaussianGridmaps.from_model(mgp, bounds, 0.25, (mean_dtype, var_dtype))
            for s in seeds:
                add(localise(maps, drive, s, particles), table="II", mean=mean_dtype, var=var_dtype)
    for res in RESOLUTIONS_M:
        maps = GaussianGridmaps.from_model(mgp, bounds, res)
        kib = maps.memory_bytes / 1024 / mgp.n_access_points
        for s in seeds:
            add(localise(maps, drive, s, particles), table="III", resolution=res, kib_per_ap=kib)
    maps = GaussianGridmaps.from_model(mgp, bounds, 0.25)
    for s in seeds:
        jump, steps = kidnapped(maps, drive, s, particles)
        rows.append({"table": "kidnap", "jump_m": jump, "recovered_after": steps})
    out["update_ms_1000"] = {  # one update of 1,000 particles, side by side
        label: _update_ms(maps, drive, direct)
        for label, direct in (("gridmaps", None), ("direct", mgp))
    }
    out["rows"] = rows
    if job.get("figure"):
        out["figure_maps"] = {
            name: {str(r): _figure_maps(model, bounds, r) for r in (0.25, 1.0, 5.0)}
            for name, model in models.items()
        }
        out["survey_xy"] = survey.positions.tolist()
    return out


def _update_ms(maps: GaussianGridmaps, drive: dict[str, Any], direct: SignalModel | None) -> float:
    mcl = WifiMCL(maps, MclConfig(particles=1000), np.random.default_rng(0), direct=direct)
    first = drive["survey_steps"]
    mcl.init_at(drive["truth"][first])
    start = time.perf_counter()
    for k in range(first, first + 20):
        mcl.update(drive["fingerprints"][k])
    return 1e3 * (time.perf_counter() - start) / 20


def _figure_maps(model: SignalModel, bounds, resolution: float) -> dict[str, Any]:
    maps = GaussianGridmaps.from_model(model, bounds, resolution)
    return {"mean": maps.mean[0].tolist(), "variance": maps.variance[0].tolist()}


def run_localization_study(
    out_dir: str | os.PathLike[str],
    *,
    plans: int = 10,
    runs: int = 3,
    survey_steps: int = 2000,
    test_steps: int = 400,
    particles: int = 500,
    direct: bool = True,
    workers: int = 2,
    backend: str = "local",
    address: str | None = None,
    progress: bool = True,
) -> dict[str, Any]:
    """Run the study; writes ``results.json``, ``tables.md``, ``gridmaps.png`` and
    ``error_over_time.png`` into ``out_dir``; returns the results. A plan is a job of the
    :class:`~sfw_gym.evaluation.executor.Executor` (``workers``, ``backend``, ``address``,
    ``progress``: a bar over the plans)."""
    executor = Executor(workers=workers, backend=backend, address=address, progress=progress)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    jobs = [
        {
            "seed": FIRST_SEED + i,
            "runs": runs,
            "survey_steps": survey_steps,
            "test_steps": test_steps,
            "particles": particles,
            "direct": direct,
            "figure": i == 0,
        }
        for i in range(plans)
    ]
    start = time.perf_counter()
    results = executor.map(study_plan, jobs, Bar("localisation study", "plan"))
    wall = time.perf_counter() - start
    summary = summarise(results, plans, runs, particles, test_steps, wall)
    figure = results[0]
    _draw_gridmaps(
        figure.pop("figure_maps"), np.array(figure.pop("survey_xy")), out / "gridmaps.png"
    )
    _draw_errors(results, out / "error_over_time.png")
    write_text_atomic(
        out / "results.json", json.dumps({"summary": summary, "plans": results}, indent=1)
    )
    write_text_atomic(out / "tables.md", summary["markdown"])
    return summary


def _ci(values: list[float]) -> str:
    mean, half, _ = mean_ci95(values)
    return f"{mean:.2f} ± {half:.2f}"


def summarise(results, plans, runs, particles, test_steps, wall) -> dict[str, Any]:
    """The tables, as Markdown and as numbers."""
    rows = [r for plan in results for r in plan["rows"]]

    def pick(**match: Any) -> list[dict[str, Any]]:
        return [r for r in rows if all(r.get(k) == v for k, v in match.items())]

    lines = [
        f"{plans} held-out plans × {runs} MCL runs = {plans * runs} runs per setting, "
        f"{particles} particles, {test_steps} test steps; error in m: mean ± 95 % CI over runs, "
        f"max: mean over runs of each run's maximum / the largest. {wall:.0f} s.",
        "",
        "Table I analogue (gridmaps at 0.25 m, float64):",
        "",
        "| model | source | mean error [m] | max error [m] |",
        "|---|---|---:|---:|",
    ]
    table1 = {}
    for model in ("GP", "mGP"):
        for source in ("direct", "gridmaps"):
            rs = pick(table="I", model=model, source=source)
            if rs:
                table1[f"{model} {source}"] = float(np.mean([r["mean_m"] for r in rs]))
                lines.append(
                    f"| {model} | {source} | {_ci([r['mean_m'] for r in rs])} | "
                    f"{np.mean([r['max_m'] for r in rs]):.2f} / {max(r['max_m'] for r in rs):.2f} |"
                )
    lines += [
        "",
        "Table II analogue (mGP, 0.25 m): mean error [m], mean dtype × variance dtype:",
        "",
    ]
    lines += ["| mean \\ variance | " + " | ".join(DTYPES) + " |", "|---|" + "---:|" * len(DTYPES)]
    for m in DTYPES:
        cells = [_ci([r["mean_m"] for r in pick(table="II", mean=m, var=v)]) for v in DTYPES]
        lines.append(f"| {m} | " + " | ".join(cells) + " |")
    lines += ["", "Table III analogue (mGP, float64):", ""]
    lines += ["| resolution [m] | KiB per AP (mean + variance) | mean error [m] | max error [m] |"]
    lines += ["|---:|---:|---:|---:|"]
    for res in RESOLUTIONS_M:
        rs = pick(table="III", resolution=res)
        lines.append(
            f"| {res} | {np.mean([r['kib_per_ap'] for r in rs]):.1f} | "
            f"{_ci([r['mean_m'] for r in rs])} | {np.mean([r['max_m'] for r in rs]):.2f} |"
        )
    first = [r["first_below_2m"] for r in pick(table="I", model="mGP", source="gridmaps")]
    kid = pick(table="kidnap")
    recovered = [r["recovered_after"] for r in kid if r["recovered_after"] > 0]
    speed = [plan["update_ms_1000"] for plan in results]
    grid_ms = float(np.mean([s["gridmaps"] for s in speed]))
    direct_ms = float(np.mean([s["direct"] for s in speed]))
    fits = {m: float(np.mean([plan[f"fit_s_{m}"] for plan in results])) for m in ("GP", "mGP")}
    lines += [
        "",
        f"Global localisation (mGP gridmaps, from one reading): error < 2 m by step 1 in "
        f"{sum(0 < f <= 1 for f in first)}/{len(first)} runs, by step 10 in "
        f"{sum(0 < f <= 10 for f in first)}/{len(first)}, by step 50 in "
        f"{sum(0 < f <= 50 for f in first)}/{len(first)}.",
        f"Kidnapping (jumps of {np.mean([r['jump_m'] for r in kid]):.1f} m on average, odometry "
        f"blind to them): error < 2 m again in {len(recovered)}/{len(kid)} runs, after a median of "
        f"{np.median(recovered) if recovered else float('nan'):.0f} steps "
        f"(max {max(recovered) if recovered else -1}).",
        f"Speed, one MCL update of 1,000 particles, 16 APs: gridmaps {grid_ms:.2f} ms, direct mGP "
        f"prediction {direct_ms:.1f} ms ({direct_ms / grid_ms:.0f}× slower), same run.",
        f"GP fits on the binned survey ({np.mean([p['survey_samples'] for p in results]):.0f} "
        f"samples): GP {fits['GP']:.1f} s, mGP {fits['mGP']:.1f} s per plan.",
    ]
    return {
        "table_I_mean_error_m": table1,
        "global_within_10_steps": sum(0 < f <= 10 for f in first) / max(len(first), 1),
        "kidnap_recovered": len(recovered) / max(len(kid), 1),
        "update_ms_1000": {"gridmaps": grid_ms, "direct": direct_ms},
        "markdown": "\n".join(lines) + "\n",
    }


def _draw_gridmaps(maps: dict[str, Any], survey_xy: np.ndarray, path: Path) -> None:
    """The paper's Fig. 1: one AP's mean and variance gridmaps, GP and mGP, three resolutions."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    resolutions = list(next(iter(maps.values())))
    fig, axes = plt.subplots(4, len(resolutions), figsize=(3 * len(resolutions), 10))
    for r, (name, by_res) in enumerate(maps.items()):
        for c, res in enumerate(resolutions):
            for k, what in enumerate(("mean", "variance")):
                ax = axes[2 * r + k, c]
                ax.imshow(np.array(by_res[res][what]), cmap="viridis")
                ax.set_title(f"{name} {what}, {res} m", fontsize=8)
                ax.set_xticks([])
                ax.set_yticks([])
    fig.suptitle(f"AP 0 of plan {FIRST_SEED}; survey of {len(survey_xy)} binned samples")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=90)
    plt.close(fig)


def _draw_errors(results: list[dict[str, Any]], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    for name in ("GP", "mGP"):
        curves = np.array([plan["curves"][name] for plan in results])
        ax.plot(np.arange(1, curves.shape[1] + 1), curves.mean(0), label=f"{name} gridmaps")
    ax.axhline(2.0, color="k", lw=0.8, ls=":")
    ax.set_xlabel("steps since global localisation")
    ax.set_ylabel("error [m] (mean over plans and runs)")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110)
    plt.close(fig)
