"""The ``sfw-gym`` command."""

from __future__ import annotations

import argparse
import logging
import math
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from sfw_gym.core.errors import ConfigError, SfwGymError

if TYPE_CHECKING:
    from sfw_gym.slam import RadioSlamConfig


def checked(convert: Callable, ok: Callable, what: str) -> Callable:
    """An argparse ``type=``: ``convert(text)``, which must satisfy ``ok``; anything else is
    argparse's usage error, exit 2, its last line naming the option ("argument --steps: ...")."""

    def parse(text: str):
        try:
            value = convert(text)
            good = ok(value)
        except ValueError:
            good = False
        if not good:
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}")
        return value

    return parse


positive_int = checked(int, lambda v: v >= 1, "an integer >= 1")
non_negative_int = checked(int, lambda v: v >= 0, "an integer >= 0")
seed_int = checked(int, lambda v: 0 <= v < 2**32, "a seed in [0, 2**32)")
positive_float = checked(float, lambda v: math.isfinite(v) and v > 0, "a finite number > 0")
non_negative_float = checked(float, lambda v: math.isfinite(v) and v >= 0, "a finite number >= 0")
folder = checked(str, lambda v: not Path(v).exists() or Path(v).is_dir(), "a folder, not a file")


def parse_routers(text: str) -> np.ndarray | int:
    """``"x1,y1;x2,y2"`` → (R, 2) array of positions; ``"3"`` → a router count (≥ 1)."""
    text = text.strip()
    if text.isdigit() and int(text) >= 1:
        return int(text)
    try:
        pts = [[float(v) for v in pair.split(",")] for pair in text.split(";") if pair.strip()]
        arr = np.array(pts, dtype=np.float64)
    except ValueError:
        arr = np.empty((0,))
    if arr.ndim != 2 or arr.shape[1] != 2 or len(arr) == 0 or not np.isfinite(arr).all():
        raise ConfigError(f"--routers: expected a count >= 1 or 'x1,y1;x2,y2;…', got {text!r}")
    return arr


def _cmd_world(args: argparse.Namespace) -> int:
    from sfw_gym.world import (
        RadioConfig,
        RadioModel,
        load_floorplan,
        place_routers,
    )
    from sfw_gym.world.picture import draw_world

    start = time.perf_counter()
    rng = np.random.default_rng(args.seed)
    if args.floorplan:
        plan = load_floorplan(args.floorplan)
    else:
        from sfw_gym.world.generator import generate_floorplan

        plan = generate_floorplan(args.seed)
    routers = parse_routers(args.routers)
    if isinstance(routers, int):
        routers = place_routers(plan, routers, rng)
    radio = RadioModel(plan, routers, RadioConfig.preset(args.preset, band=args.band), rng)
    out = draw_world(plan, radio, args.out, resolution_m=args.resolution)
    took = time.perf_counter() - start
    print(
        f"{plan.name}: {plan.area_m2:.1f} m², {len(plan.edges)} wall faces, routers at "
        f"{np.round(radio.routers, 2).tolist()}"
    )
    print(f"wrote {out} in {took:.1f} s")
    return 0


def _cmd_map(args: argparse.Namespace) -> int:
    from dataclasses import replace

    from sfw_gym.mapping.offline import OFFLINE_CONFIG, map_log, write_map

    routers = parse_routers(args.routers)
    if isinstance(routers, int):
        raise ConfigError(
            f"--routers: the map command needs router positions 'x1,y1;x2,y2' in the CSV's "
            f"units, not a count ({routers})"
        )
    result = map_log(
        args.log,
        routers,
        scale_m_per_unit=1.0 / args.px_per_m if args.px_per_m else (args.scale or 1.0),
        resolution_m=args.resolution,
        margin_m=args.margin,
        rssi_column=args.rssi_column,
        config=replace(OFFLINE_CONFIG, router_policy=args.policy or OFFLINE_CONFIG.router_policy),
        method=args.method,
        passes=args.passes,
    )
    paths = write_map(result, args.out, y_down=args.y_down)
    log = result.log
    rows, cols = result.grid.shape
    print(
        f"{log.path}: {log.n_samples} samples, {log.n_skipped} rows skipped (no position); "
        f"routers <- columns {', '.join(result.columns)}"
    )
    print(
        f"mapper: {result.median_us_per_sample:.1f} µs per sample (median; mean "
        f"{result.us_per_sample:.1f}), {cols} x {rows} cells of {result.grid.resolution_m:g} m"
    )
    print(f"wrote {paths['png']}, {paths['npy']}, {paths['json']}")
    if args.score:
        from sfw_gym.evaluation.logs import read_log_meta, score_map

        meta = read_log_meta(args.log)
        scores = score_map(result.occupancy_u8, result.grid, meta["truth_u8"], meta["truth_grid"])
        print("against the recorded truth: " + ", ".join(f"{k} {v:.3f}" for k, v in scores.items()))
    return 0


def _cmd_record(args: argparse.Namespace) -> int:
    from sfw_gym.evaluation.logs import read_log_meta, record_log
    from sfw_gym.world import generate_floorplan, load_floorplan

    plan = load_floorplan(args.floorplan) if args.floorplan else generate_floorplan(args.seed)
    routers = parse_routers(args.routers)
    paths = record_log(
        plan, args.out, routers=routers, seed=args.seed, trajectory=args.trajectory,
        step_m=args.step,
    )  # fmt: skip
    meta = read_log_meta(paths["csv"])
    where = ";".join(f"{x:g},{y:g}" for x, y in meta["routers_px"])
    print(
        f"{plan.name}: {meta['samples']} samples ({args.trajectory}), "
        f"{len(meta['routers_px'])} router(s) at pixels {where}"
    )
    print(f"wrote {paths['csv']}, {paths['truth']}, {paths['json']}")
    print(
        f"map and score it: sfw-gym map {paths['csv']} --routers '{where}' "
        f"--px-per-m {1 / meta['pixel_m']:g} --y-down --score"
    )
    return 0


def _cmd_slam(args: argparse.Namespace) -> int:
    from sfw_gym.slam import RadioSlamConfig
    from sfw_gym.slam.offline import slam_log, trajectory_errors

    settings = {"keyframe_every": args.keyframes}
    if args.record is not None:  # odometry weighted by the recording robot's noise model
        recorded = _record_slam_log(args.log, args.env, args.record, args.steps)
        settings |= {k: getattr(recorded, k) for k in ("odometry_sigma_m", "odometry_sigma_rad")}
        print(
            f"recorded {args.steps} frontier steps on {args.env} (seed {args.record}) to {args.log}"
        )
    if args.odometry_sigma is not None:
        settings["odometry_sigma_m"] = args.odometry_sigma
    if args.heading_sigma is not None:
        settings["odometry_sigma_rad"] = args.heading_sigma
    out = args.out or str(Path(args.log).with_suffix("")) + "_slam"
    start = time.perf_counter()
    log, result, paths = slam_log(args.log, out, RadioSlamConfig(**settings))
    print(
        f"{log.path}: {len(log.odometry)} poses, {len(log.access_points)} access points, "
        f"{len(result.closures)} radio loop closures; {time.perf_counter() - start:.1f} s"
    )
    errors = trajectory_errors(log, result)
    if errors:
        print(
            f"ATE (against the log's truth): odometry {errors[0]:.2f} m, "
            f"Radio SLAM {errors[1]:.2f} m"
        )
    print(f"wrote {paths['trajectory']}, {paths['fingerprint_map']}, {paths['figure']}")
    return 0


def _record_slam_log(path: str, env_id: str, seed: int, steps: int) -> RadioSlamConfig:
    """A frontier run on ``env_id`` written as a Radio SLAM log with its truth; returns the
    env's Radio SLAM settings (its odometry weights follow the robot's noise)."""
    import gymnasium as gym

    from sfw_gym.envs.explore import unwrap_sfw
    from sfw_gym.evaluation.drives import record_frontier_drive
    from sfw_gym.slam.offline import write_slam_log

    if not unwrap_sfw(gym.make(env_id)).config.explore.n_background_aps:
        raise ConfigError(f"--env {env_id}: has no background access points to fingerprint")
    drive = record_frontier_drive(env_id, seed, steps)
    write_slam_log(
        path,
        drive["period_s"] * np.arange(len(drive["truth"])),
        drive["odometry"],
        drive["fingerprints"],
        drive["truth"],
    )
    return drive["slam_config"]


def _cmd_localize(args: argparse.Namespace) -> int:
    from sfw_gym.evaluation.localization import run_localization_study

    summary = run_localization_study(
        args.out,
        plans=args.plans,
        runs=args.runs,
        survey_steps=args.survey_steps,
        test_steps=args.test_steps,
        particles=args.particles,
        direct=not args.no_direct,
        workers=args.workers,
        backend=args.backend,
        address=args.address,
        progress=not args.no_progress,
    )
    print(summary["markdown"])
    print(f"wrote {args.out}/results.json, tables.md, gridmaps.png, error_over_time.png")
    return 0


def _cmd_fingerprints(args: argparse.Namespace) -> int:
    from sfw_gym.datasets import read_csv, read_ujiindoorloc, read_wifine

    if args.action == "convert":
        if args.format == "ujiindoorloc":
            data = read_ujiindoorloc(args.source, args.split)
        elif args.format == "wifine":
            data = read_wifine(args.source)
        else:
            data = read_csv(args.source, not_heard=args.not_heard)
        data.to_csv(args.output)
        print(f"wrote {args.output}: {len(data)} scans, {data.n_access_points} access points")
        return 0
    from sfw_gym.evaluation.fingerprints import TrackSettings, evaluate, write_evaluation
    from sfw_gym.world.floorplan import load_floorplan

    train = read_csv(args.train, not_heard=args.not_heard)
    test = read_csv(args.test, not_heard=args.not_heard)
    track = None
    if args.track:
        plans = {floor: load_floorplan(path) for floor, path in args.floorplan}
        track = TrackSettings(
            translation_std=args.odometry_translation_std,
            heading_std_rad=args.odometry_heading_std_rad,
            seed=args.seed,
            particles=args.particles,
            floorplans=plans,
            wall_weight=args.wall_weight,
        )
    elif args.floorplan:
        raise ConfigError("--floorplan: only used with --track")
    metrics, columns = evaluate(train, test, args.method, track)
    paths = write_evaluation(args.out, metrics, columns)
    print(_fingerprint_summary(metrics))
    print(f"wrote {paths['metrics']} and {paths['predictions']}")
    return 0


def _fingerprint_summary(metrics: dict) -> str:
    line = (
        f"{metrics['method']}: {metrics['n_test']} scans, mean error {metrics['mean_error_m']:.2f}"
        f" (median {metrics['median_error_m']:.2f}, p95 {metrics['p95_error_m']:.2f})"
    )
    if "per_scan_mean_error_m" in metrics:
        line += f", per scan {metrics['per_scan_mean_error_m']:.2f}"
    for key in ("floor_hit_rate", "building_hit_rate"):
        if key in metrics:
            line += f", {key.split('_')[0]} {100 * metrics[key]:.1f} %"
    return line + f"; fit {metrics['fit_s']:.1f} s, {metrics['query_ms_per_scan']:.2f} ms a scan"


def parse_floorplan_option(text: str) -> tuple[int | None, str]:
    """``--floorplan``: ``PATH`` (every floor) or ``FLOOR=PATH``."""
    floor, sep, path = text.partition("=")
    if sep and floor.strip().lstrip("-").isdigit():
        return int(floor), path
    return None, text


def _cmd_bench(args: argparse.Namespace) -> int:
    from sfw_gym.bench import main_bench

    agents = [a for a in args.agents.split(",") if a] if args.agents else None
    return main_bench(
        args.env, args.steps, args.resets, args.memory_steps, agents, args.agent_episodes
    )


def _cmd_train(args: argparse.Namespace) -> int:
    import gymnasium as gym

    from sfw_gym.core.data import default_hyperparams
    from sfw_gym.rl.training import train_ppo

    if ":" not in args.env:  # ("module:Env-v0" registers on import, in the workers)
        gym.spec(args.env)  # an unknown id: an --env error, not a missing YAML block
    if args.backend == "rllib":
        return _train_on_rllib(args)
    if args.num_env_runners is not None or args.address is not None:
        raise ConfigError("--num-env-runners and --address need --backend rllib")
    summary = train_ppo(
        args.env,
        args.timesteps,
        args.out or f"runs/{args.algo}/{args.env}",
        n_envs=args.n_envs,
        seed=args.seed,
        hyperparams_path=args.hyperparams or default_hyperparams(args.algo),
        algo=args.algo,
        checkpoint_every=args.checkpoint_every,
        eval_every=args.eval_every,
        eval_episodes=args.eval_episodes,
        resume=args.resume,
        progress_bar=not args.no_progress,
        num_threads=args.num_threads or None,
        vec_env=args.vec_env,
    )
    print(
        f"trained {args.env} to "
        f"{summary['steps']:,} steps in {summary['wall_time_s']:.0f} s; model: {summary['model']}"
    )
    return 0


def _vec_envs() -> tuple[str, ...]:
    from sfw_gym.rl.training import VEC_ENVS

    return VEC_ENVS


def _train_on_rllib(args: argparse.Namespace) -> int:
    from sfw_gym.rl.rllib import RLLIB_HYPERPARAMS, train_rllib

    if args.algo != "ppo":
        raise ConfigError(f"--backend rllib trains ppo only, got {args.algo!r}")
    if args.n_envs is not None:
        raise ConfigError("--n-envs is the stable-baselines3 backend's; RLlib: --num-env-runners")
    summary = train_rllib(
        args.env,
        args.timesteps,
        args.out or f"runs/rllib_ppo/{args.env}",
        num_env_runners=args.num_env_runners or 0,
        seed=args.seed,
        hyperparams_path=args.hyperparams or RLLIB_HYPERPARAMS,
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


def _json(option: str, text: str | None) -> dict:
    """A command-line JSON object (empty when not given), or a one-line error naming ``option``."""
    import json

    try:
        value = json.loads(text) if text else {}
    except json.JSONDecodeError as exc:
        raise ConfigError(f"{option}: not valid JSON ({exc})") from None
    if not isinstance(value, dict):
        raise ConfigError(f"{option}: expected a JSON object, got {text!r}")
    return value


def _cmd_benchmark(args: argparse.Namespace) -> int:
    from sfw_gym.evaluation import benchmark

    if args.action == "compare":
        a, b = (benchmark.load_results(p) for p in args.results)
        print(benchmark.compare(a, b), end="")
        return 0
    # an agent of one's own, importable from the current folder (as `python -m` would)
    sys.path.insert(0, str(Path.cwd()))
    out = args.out or f"benchmark/{args.agent.replace(':', '.')}/{args.split}"
    benchmark.run_benchmark(
        args.agent,
        protocol=args.protocol,
        split=args.split,
        out=out,
        agent_params=_json("--agent-params", args.agent_params),
        agent_seed=args.seed,
        plans=args.plans,
        episodes=args.episodes,
        workers=args.workers,
        backend=args.backend,
        address=args.address,
        progress=not args.no_progress,
    )
    print((Path(out) / "results.md").read_text(encoding="utf-8"), end="")
    print(f"wrote {out}/results.json and results.md")
    return 0


def _cmd_evaluate(args: argparse.Namespace) -> int:
    from sfw_gym.evaluation import evaluate

    result = evaluate(
        [a.strip() for a in args.agents.split(",") if a.strip()],
        args.episodes,
        args.seed,
        out=args.out,
        env_id=args.env,
        floorplans=args.floorplans,
        env_kwargs=_json("--env-kwargs", args.env_kwargs),
        agent_params=_json("--agent-params", args.agent_params),
        workers=args.workers,
        gif_episodes=args.gif_episodes if args.gif else 0,
        progress=not args.no_progress,
        backend=args.backend,
        address=args.address,
        vector_envs=args.vector_envs,
    )
    print((Path(args.out) / "results.md").read_text(encoding="utf-8"), end="")
    paired = Path(args.out) / "paired.md"
    if paired.is_file():
        print(
            "\npaired on the same plans and seeds:",
            paired.read_text(encoding="utf-8"),
            sep="\n",
            end="",
        )
    print(f"wrote {len(result['files'])} files under {args.out}")
    return 0


def _cmd_demo(args: argparse.Namespace) -> int:
    from sfw_gym.demo import run_demo

    start = time.perf_counter()
    index = run_demo(
        args.out,
        args.episodes,
        args.seed,
        workers=args.workers,
        progress=not args.no_progress,
        model=args.model,
    )
    print(index.parent.joinpath("results.md").read_text(encoding="utf-8"), end="")
    print(f"report: {index} ({time.perf_counter() - start:.0f} s)")
    return 0


#: One example per subcommand, shown at the end of its ``--help``.
EXAMPLES = {
    "demo": "sfw-gym demo --out sfw-report",
    "world": "sfw-gym world --seed 3 --out world.png",
    "map": 'sfw-gym map LOG.csv --routers "60,60;220,220" --scale 0.05 --out map.png',
    "record": "sfw-gym record walk.csv --seed 3 --routers 2",
    "slam": "sfw-gym slam drift.csv --record 7",
    "localize": "sfw-gym localize --plans 10 --out localize",
    "fingerprints": "sfw-gym fingerprints evaluate --train train.csv --test test.csv --out fp",
    "speed": "sfw-gym speed --steps 5000 --resets 50",
    "train": "sfw-gym train ppo_mask --env SfW-ExploreRegions-v0 --out runs/regions --resume",
    "evaluate": "sfw-gym evaluate --agents frontier,ppo,greedy --episodes 10 --seed 2000000",
    "benchmark": "sfw-gym benchmark run --agent frontier --split test",
}


class HelpWithDefaults(argparse.RawDescriptionHelpFormatter):
    """Help that shows each option's default (unless its text already says it, or it has none)
    and keeps the example's line as written."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        if (
            not action.option_strings
            or "default" in text.lower()
            or any(action.default is v for v in (None, False, argparse.SUPPRESS))
            or action.default == ""
        ):
            return text
        return f"{text} (default: %(default)s)"


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of every subcommand."""
    parser = argparse.ArgumentParser(
        prog="sfw-gym", description="Active WiFi exploration: worlds, mapping, agents."
    )
    parser.add_argument(
        "--debug", action="store_true", help="show the traceback of an error (else one line)"
    )
    noise = parser.add_mutually_exclusive_group()
    noise.add_argument(
        "-v", "--verbose", action="count", default=0, help="the library's log: -v info, -vv debug"
    )
    noise.add_argument(
        "-q", "--quiet", action="store_true", help="errors only (no warnings from the library)"
    )
    sub = parser.add_subparsers(dest="command", required=True)

    from sfw_gym.demo import DEMO_EPISODES, DEMO_SEED
    from sfw_gym.world.radio import BANDS, PRESETS

    demo = sub.add_parser(
        "demo",
        help="frontier, cross-pass and the shipped learned explorer on fresh plans → sfw-report/",
    )
    demo.add_argument(
        "--out", type=folder, default="sfw-report", help="report folder (default sfw-report)"
    )
    demo.add_argument(
        "--episodes", type=positive_int, default=DEMO_EPISODES, help="floorplans (default 3)"
    )
    demo.add_argument(
        "--seed", type=seed_int, default=DEMO_SEED, help="seed of the first floorplan"
    )
    demo.add_argument(
        "--workers", type=positive_int, default=2, help="worker processes (default 2)"
    )
    demo.add_argument(
        "--model",
        default=None,
        help="a `sfw-gym train ppo_mask` folder or .zip (default: the shipped one)",
    )
    demo.add_argument("--no-progress", action="store_true", help="no progress bar")
    demo.set_defaults(func=_cmd_demo)

    world = sub.add_parser("world", help="draw a floorplan, its routers, RSSI and true k-regions")
    source = world.add_mutually_exclusive_group()
    source.add_argument(
        "--seed", type=seed_int, default=0, help="procedural floorplan seed (default 0)"
    )
    source.add_argument(
        "--floorplan", help="a floorplan file: HouseExpo or sfw_gym JSON, or a ROS map YAML"
    )
    world.add_argument("--routers", default="2", help="a count, or positions 'x1,y1;x2,y2'")
    world.add_argument("--preset", choices=PRESETS, default="default", help="radio preset")
    world.add_argument("--band", choices=list(BANDS), default="2.4", help="GHz (default 2.4)")
    world.add_argument(
        "--resolution", type=positive_float, default=0.1, help="heat-map cell size, metres"
    )
    world.add_argument("--out", default="world.png", help="output PNG (default world.png)")
    world.set_defaults(func=_cmd_world)

    mp = sub.add_parser("map", help="map a recorded RSSI log (CSV) offline: PNG + .npy")
    mp.add_argument("log", help="CSV: x, y, then RSSI columns (the SfW experiments' layout)")
    mp.add_argument(
        "--routers", required=True, help="router positions 'x1,y1;x2,y2' in the CSV's units"
    )
    units = mp.add_mutually_exclusive_group()
    units.add_argument(
        "--scale",
        type=positive_float,
        default=None,
        help="metres per CSV unit (default 1; pixels e.g. 0.05)",
    )
    units.add_argument(
        "--px-per-m",
        type=positive_float,
        default=None,
        help="CSV units (canvas pixels) per metre: the SfW logs' about 87 (0.0115 m per pixel)",
    )
    mp.add_argument(
        "--resolution",
        type=positive_float,
        default=0.05,
        help="map cell size, metres (default 0.05)",
    )
    mp.add_argument(
        "--margin",
        type=non_negative_float,
        default=1.0,
        help="border around the data, metres (default 1)",
    )
    mp.add_argument(
        "--rssi-column",
        default=None,
        metavar="max|2.4|5|NAME[,NAME...]",
        help="each router's RSSI: its strongest band (max: the default, as the SfW authors "
        "mapped), one band, or one column name per router",
    )
    mp.add_argument(
        "--policy",
        choices=["strongest", "all"],
        default=None,
        help="update along every heard router's ray (all: the default, measured best on "
        "two-router logs) or the strongest's only (the paper)",
    )
    mp.add_argument(
        "--method",
        choices=["inverse-k", "sfw-reference"],
        default="inverse-k",
        help="sparse inverse k-visibility (ours, default) or the SfW authors' method",
    )
    mp.add_argument(
        "--passes",
        type=int,
        choices=[1, 2],
        default=2,
        help="2 (default): run the log forward, then reversed; 1: forward only",
    )
    mp.add_argument(
        "--score",
        action="store_true",
        help="score the map against the truth recorded beside the log (sfw-gym record)",
    )
    mp.add_argument(
        "--y-down", action="store_true", help="the CSV's y grows downward (image pixels)"
    )
    mp.add_argument("--out", default="map.png", help="output PNG; .npy and .json beside it")
    mp.set_defaults(func=_cmd_map)

    rec = sub.add_parser(
        "record",
        help="record an RSSI log (CSV, the SfW layout) from the simulator, the truth beside it",
    )
    rec.add_argument("out", help="the CSV to write; .truth.npy and .truth.json go beside it")
    rec.add_argument("--floorplan", help="a floorplan file (default: a generated one)")
    rec.add_argument("--seed", type=seed_int, default=0, help="plan, routers, walk and radio")
    rec.add_argument("--routers", default="2", help="a count, or positions 'x1,y1;x2,y2' (m)")
    rec.add_argument(
        "--trajectory",
        choices=["walk", "survey"],
        default="walk",
        help="a person's walk from place to place, or a survey (walls, then 0.5 m passes)",
    )
    rec.add_argument(
        "--step", type=positive_float, default=0.05, help="metres between samples (default 0.05)"
    )
    rec.set_defaults(func=_cmd_record)
    slam = sub.add_parser(
        "slam", help="Radio SLAM on a recorded log (CSV): corrected trajectory, fingerprint map"
    )
    slam.add_argument(
        "log", help="CSV: time, odom_x, odom_y, odom_theta, one column per AP [, true_x, true_y]"
    )
    slam.add_argument(
        "--record",
        type=seed_int,
        default=None,
        metavar="SEED",
        help="first record LOG: a frontier run on --env from this seed",
    )
    slam.add_argument(
        "--env", default="SfW-ExploreDrift-v0", help="env id for --record (needs background APs)"
    )
    slam.add_argument(
        "--steps", type=positive_int, default=1500, help="steps for --record (default 1500)"
    )
    slam.add_argument(
        "--keyframes", type=positive_int, default=5, help="every k-th pose a graph node (default 5)"
    )
    slam.add_argument(
        "--odometry-sigma",
        type=positive_float,
        default=None,
        help="odometry's translation error per pose, metres (default 0.02; --record: the env's)",
    )
    slam.add_argument(
        "--heading-sigma",
        type=positive_float,
        default=None,
        help="odometry's heading error per pose, radians (default 0.02; --record: the env's)",
    )
    slam.add_argument("--out", type=folder, default=None, help="output folder (default LOG_slam/)")
    slam.set_defaults(func=_cmd_slam)

    _add_fingerprints_parser(sub)

    loc = sub.add_parser(
        "localize",
        help="WiFi Monte-Carlo localisation on Gaussian gridmaps: the paper's tables → OUT/",
    )
    loc.add_argument("--plans", type=positive_int, default=10, help="held-out plans (default 10)")
    loc.add_argument(
        "--runs", type=positive_int, default=3, help="MCL runs per plan and setting (default 3)"
    )
    loc.add_argument(
        "--survey-steps", type=positive_int, default=2000, help="steps of each survey drive"
    )
    loc.add_argument(
        "--test-steps", type=positive_int, default=400, help="steps of each test drive"
    )
    loc.add_argument("--particles", type=positive_int, default=500, help="particles (default 500)")
    loc.add_argument(
        "--no-direct", action="store_true", help="skip MCL on direct GP prediction (the slow part)"
    )
    _add_episode_runner_options(loc)
    loc.add_argument(
        "--out",
        "--json",  # its name before issue 32, kept as an alias
        dest="out",
        type=folder,
        default="localize",
        help="output folder (default localize/; --json is the old name)",
    )
    loc.set_defaults(func=_cmd_localize)

    bench = sub.add_parser(
        "speed",
        aliases=["bench"],
        help="the env's throughput: steps/s and reset ms beside CartPole-v1 (alias: bench)",
    )
    bench.add_argument("--env", default="SfW-Explore-v0", help="env id (default SfW-Explore-v0)")
    bench.add_argument("--steps", type=positive_int, default=5000, help="random steps to time")
    bench.add_argument("--resets", type=positive_int, default=50, help="resets to time")
    bench.add_argument(
        "--memory-steps",
        type=non_negative_int,
        default=0,
        help="also report RSS before/after this many steps (e.g. 100000)",
    )
    bench.add_argument(
        "--agents",
        default="",
        help="also time these agents' episodes beside random actions (e.g. frontier,ppo), "
        "candidate_goals, and episode time by length",
    )
    bench.add_argument(
        "--agent-episodes", type=positive_int, default=3, help="seeds per env for --agents"
    )
    bench.set_defaults(func=_cmd_bench)

    train = sub.add_parser(
        "train", help="train an agent (PPO: stable-baselines3, or RLlib with --backend rllib)"
    )
    train.add_argument(
        "algo",
        choices=["ppo", "ppo_mask"],
        help="ppo, or ppo_mask (MaskablePPO, for SfW-ExploreGoals-v0 and SfW-ExploreRegions-v0)",
    )
    train.add_argument("--env", default="SfW-Explore-v0", help="env id (default SfW-Explore-v0)")
    train.add_argument(
        "--timesteps",
        type=positive_int,
        default=None,
        help="total env steps (default: the YAML block's n_timesteps, as rl-zoo)",
    )
    train.add_argument(
        "--n-envs", type=positive_int, default=None, help="parallel envs (default: YAML)"
    )
    train.add_argument(
        "--vec-env",
        choices=_vec_envs(),
        default="native",
        help="native: the n envs step together in this process (default; SubprocVecEnv under "
        "an env_wrapper); subproc: SB3's SubprocVecEnv, one worker process per env",
    )
    train.add_argument("--seed", type=seed_int, default=0, help="seed of the run (default 0)")
    train.add_argument(
        "--out", type=folder, default=None, help="output folder (default runs/ppo/ENV)"
    )
    train.add_argument(
        "--hyperparams", default=None, help="rl-zoo YAML (default: the shipped <algo>.yml)"
    )
    train.add_argument("--checkpoint-every", type=positive_int, default=50_000, help="env steps")
    train.add_argument("--eval-every", type=positive_int, default=25_000, help="env steps")
    train.add_argument("--eval-episodes", type=positive_int, default=5, help="held-out episodes")
    train.add_argument(
        "--num-threads",
        type=non_negative_int,
        default=1,
        help="PyTorch CPU threads (default 1: small networks; 0: PyTorch's default)",
    )
    train.add_argument(
        "--backend",
        choices=["sb3", "rllib"],
        default="sb3",
        help="sb3 (stable-baselines3, default) or rllib (Ray RLlib; pip install 'sfw-gym[ray]')",
    )
    train.add_argument(
        "--num-env-runners",
        type=non_negative_int,
        default=None,
        help="with --backend rllib: Ray processes collecting episodes (default 0: the driver)",
    )
    train.add_argument(
        "--address", default=None, help="with --backend rllib: a Ray cluster's address ('auto')"
    )
    train.add_argument("--resume", action="store_true", help="continue from the last checkpoint")
    train.add_argument("--no-progress", action="store_true", help="no progress bar")
    train.set_defaults(func=_cmd_train)
    ev = sub.add_parser(
        "evaluate", help="compare agents on the same floorplans and seeds (table, curves, paths)"
    )
    ev.add_argument(
        "--agents",
        default="frontier,cross-pass,random",
        help="comma-separated: frontier, cross-pass, greedy, random, ppo, ppo-waypoint (default: "
        "frontier,cross-pass,random)",
    )
    ev.add_argument(
        "--episodes", type=positive_int, default=10, help="episodes per agent (default 10)"
    )
    ev.add_argument("--seed", type=seed_int, default=0, help="episode i uses reset(seed=SEED + i)")
    ev.add_argument(
        "--floorplans",
        default=None,
        help="folder of plan files (cycled) or one file; default: the env's procedural plans",
    )
    ev.add_argument("--env", default="SfW-Explore-v0", help="env id (default SfW-Explore-v0)")
    ev.add_argument("--env-kwargs", default=None, help="extra gym.make kwargs as JSON")
    ev.add_argument(
        "--agent-params", default=None, help='per-agent parameters as JSON: {"frontier": {...}}'
    )
    ev.add_argument(
        "--out", type=folder, default="evaluation", help="output folder (resumes from it)"
    )
    _add_episode_runner_options(ev)
    ev.add_argument(
        "--vector-envs",
        type=positive_int,
        default=1,
        help="N > 1: run the episodes on the native vector env of N sub-envs, stepped together "
        "in this process with one agent per sub-env, instead of --workers; the same records "
        "(no GIFs)",
    )
    ev.add_argument("--gif", action="store_true", help="also write GIFs of the first episodes")
    ev.add_argument(
        "--gif-episodes", type=non_negative_int, default=1, help="episodes per agent with a GIF"
    )
    ev.set_defaults(func=_cmd_evaluate)

    bm = sub.add_parser(
        "benchmark",
        help="run an agent through the benchmark protocol, or compare two results files",
        description="sfw-gym benchmark run --agent AGENT [options] | sfw-gym benchmark compare "
        "A.json B.json (a bare 'sfw-gym benchmark --agent AGENT' runs too)",
    )
    actions = bm.add_subparsers(dest="action", metavar="{run,compare}", required=True)
    run = actions.add_parser("run", help="run an agent through the protocol → OUT/results.*")
    _add_benchmark_run_options(run)
    compare = actions.add_parser("compare", help="pair two results.json files (B − A)")
    compare.add_argument("results", nargs=2, metavar="RESULTS", help="A.json B.json")
    for parser_ in (run, compare):
        parser_.formatter_class = HelpWithDefaults
    bm.set_defaults(func=_cmd_benchmark)
    for name, example in EXAMPLES.items():
        sub.choices[name].formatter_class = HelpWithDefaults
        sub.choices[name].epilog = f"example:\n  {example}"
    return parser


def _add_fingerprints_parser(sub) -> None:
    """``fingerprints evaluate`` and ``fingerprints convert``."""
    from sfw_gym.datasets import DRIFT_HEADING_STD_RAD, DRIFT_TRANSLATION_STD
    from sfw_gym.datasets.readers import GENERIC_NOT_HEARD, UJI_SPLITS
    from sfw_gym.localization.fingerprinting import DEFAULT_METHOD, METHODS
    from sfw_gym.localization.tracking import TRACK_PARTICLES, WALL_WEIGHT

    fp = sub.add_parser(
        "fingerprints",
        help="WiFi fingerprint localisation on real surveys (CSV): evaluate, or convert a dataset",
        description="sfw-gym fingerprints evaluate --train TRAIN.csv --test TEST.csv --out DIR | "
        "sfw-gym fingerprints convert --format FORMAT SOURCE OUT.csv",
    )
    actions = fp.add_subparsers(dest="action", metavar="{evaluate,convert}", required=True)
    ev = actions.add_parser(
        "evaluate",
        help="fit on TRAIN, locate TEST → DIR/metrics.json, DIR/predictions.csv",
        description="CSV: a header; x, y (metres); optional floor, building (integers), "
        "trajectory (a label), t (seconds); every other column one access point's RSSI in dBm, "
        "--not-heard or an empty cell meaning not heard. --track: the test rows of each "
        "trajectory, in t order, are one walk; its odometry is SYNTHETIC (the true positions "
        "plus noise), and WiFi MCL on the Gaussian gridmaps tracks it.",
    )
    ev.add_argument("--train", required=True, help="training fingerprints (CSV)")
    ev.add_argument("--test", required=True, help="test fingerprints (CSV)")
    ev.add_argument("--out", type=folder, required=True, help="output folder")
    ev.add_argument("--method", default=DEFAULT_METHOD, choices=METHODS)
    ev.add_argument(
        "--not-heard", type=float, default=GENERIC_NOT_HEARD, help="the value meaning not heard"
    )
    ev.add_argument("--track", action="store_true", help="track each test trajectory (MCL)")
    ev.add_argument(
        "--floorplan",
        type=parse_floorplan_option,
        action="append",
        default=[],
        metavar="[FLOOR=]PLAN",
        help="with --track: particles keep to this plan's free space (a ROS map .yaml or a "
        "plan JSON); FLOOR=PLAN for one floor, repeatable",
    )
    ev.add_argument(
        "--wall-weight",
        type=checked(float, lambda v: 0 <= v <= 1, "a number in [0, 1]"),
        default=WALL_WEIGHT,
        help="with --floorplan: the share of its weight a particle keeps when it crosses a wall "
        "(0: walls are uncrossable; above 0 where the plan may be wrong)",
    )
    ev.add_argument(
        "--odometry-translation-std",
        type=non_negative_float,
        default=DRIFT_TRANSLATION_STD,
        help="synthetic odometry: translation noise per metre walked",
    )
    ev.add_argument(
        "--odometry-heading-std-rad",
        type=non_negative_float,
        default=DRIFT_HEADING_STD_RAD,
        help="synthetic odometry: heading noise per step (rad)",
    )
    ev.add_argument("--seed", type=seed_int, default=0, help="the odometry and particles' seed")
    ev.add_argument(
        "--particles", type=positive_int, default=TRACK_PARTICLES, help="particles per walk"
    )
    conv = actions.add_parser("convert", help="a dataset in its own layout → the generic CSV")
    conv.add_argument("--format", required=True, choices=["csv", "ujiindoorloc", "wifine"])
    conv.add_argument(
        "--split", default="train", choices=sorted(UJI_SPLITS), help="UJIIndoorLoc's split"
    )
    conv.add_argument(
        "--not-heard",
        type=float,
        default=GENERIC_NOT_HEARD,
        help="csv: the value meaning not heard",
    )
    conv.add_argument("source", help="UJIIndoorLoc's zip, a WiFine CSV or folder, or a CSV")
    conv.add_argument("output", help="the generic CSV to write")
    for parser_ in (ev, conv):
        parser_.formatter_class = HelpWithDefaults
    fp.set_defaults(func=_cmd_fingerprints)


def _add_benchmark_run_options(parser: argparse.ArgumentParser) -> None:
    """``benchmark run``'s options."""
    parser.add_argument(
        "--agent", required=True, help="a shipped agent name or package.module:Class of your own"
    )
    parser.add_argument("--protocol", default="benchmark-v1", help="protocol name or YAML path")
    parser.add_argument("--split", default="test", choices=["train", "validation", "test"])
    parser.add_argument("--agent-params", default=None, help="the agent's parameters as JSON")
    parser.add_argument("--seed", type=seed_int, default=0, help="the agent seed")
    parser.add_argument(
        "--plans", default=None, help="a folder of plan files to add (by the split)"
    )
    parser.add_argument(
        "--episodes", type=positive_int, default=None, help="at most this many episodes per env"
    )
    parser.add_argument(
        "--out", type=folder, default=None, help="default benchmark/AGENT/SPLIT (resumes)"
    )
    _add_episode_runner_options(parser)


def _bare_benchmark_runs(argv: list[str]) -> list[str]:
    """The form before the subcommands, ``benchmark --agent A ...``, read as ``benchmark run``."""
    i = next((j for j, token in enumerate(argv) if not token.startswith("-")), None)
    if i is not None and argv[i] == "benchmark":
        rest = argv[i + 1 :]
        if rest and rest[0] not in ("run", "compare", "-h", "--help"):
            return [*argv[: i + 1], "run", *rest]
    return argv


def _add_episode_runner_options(parser: argparse.ArgumentParser) -> None:
    """Where the jobs (episodes, the study's plans) run, the executor's options: ``--workers``,
    ``--backend``, ``--address``, ``--no-progress``."""
    parser.add_argument(
        "--workers", type=positive_int, default=2, help="worker processes (default 2)"
    )
    parser.add_argument(
        "--backend",
        choices=["local", "ray"],
        default="local",
        help="run the jobs in local worker processes or as Ray tasks (pip install sfw-gym[ray])",
    )
    parser.add_argument(
        "--address", default=None, help="with --backend ray: a cluster's address ('auto')"
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``sfw-gym``: exit status 0; 2 with a one-line error for bad input; 1 with
    a one-line error for any other failure (``--debug``: the traceback instead); 130 on Ctrl-C."""
    import gymnasium as gym

    argv = _bare_benchmark_runs(list(sys.argv[1:] if argv is None else argv))
    args = build_parser().parse_args(argv)
    # -v/-vv raise the package's log only (not numba's or matplotlib's); -q: errors only.
    levels = (logging.WARNING, logging.INFO, logging.DEBUG)
    level = logging.ERROR if args.quiet else levels[min(args.verbose, 2)]
    logging.basicConfig(
        format="%(levelname)s %(name)s: %(message)s",
        level=logging.ERROR if args.quiet else logging.WARNING,
        force=True,
    )
    logging.getLogger("sfw_gym").setLevel(level)
    try:
        return args.func(args)
    except (SfwGymError, gym.error.Error) as exc:
        if args.debug:
            raise
        status, message = 2, str(exc)
        if isinstance(exc, gym.error.Error):  # e.g. NameNotFound: an unknown env id
            message = f"--env {getattr(args, 'env', '')}: {exc}"
    except KeyboardInterrupt:
        print(f"sfw-gym {args.command}: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # a failure, not bad input: one line unless --debug
        if args.debug:
            raise
        status = 1
        message = f"failed: {type(exc).__name__}: {exc} (run with --debug for the traceback)"
    # One line, even when the message quotes a multi-line parser error (YAML, JSON).
    print(f"sfw-gym {args.command}: error: {' '.join(message.split())}", file=sys.stderr)
    return status


if __name__ == "__main__":
    sys.exit(main())
