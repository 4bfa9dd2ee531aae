"""Re-make realistic bugs by hand, one at a time, and check that the suite notices each.

Usage: ``python scripts/tools/hand_made_bugs.py [NAME ...]`` (default: every case). Each case
replaces one
exact snippet in a source file, runs the named tests with ``-x``, prints CAUGHT (a test failed) or
MISSED, and restores the file. The first five are the bugs of issue 21; the rest are the
behaviours that issue's change added. Takes about 3 minutes on 2 cores.
"""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
VECTOR_TESTS = '-m "slow or not slow" tests/envs/test_vector_env.py'  # its 1,000-step runs
CASES = [
    (
        "bug1.worst-goal",
        "sfw_gym/agents/frontier.py",
        "best = int(ok[np.argmax(u)])",
        "best = int(ok[np.argmin(u)])",
        "tests/agents/test_agent_behaviour.py",
    ),
    (
        "bug2a.ppo-waypoint-sample",
        "sfw_gym/rl/waypoint_agent.py",
        "        if self.settings.deterministic:",
        "        if False:",
        "tests/rl/test_waypoint_agent.py",
    ),
    (
        "bug2b.ppo-continuous-sample",
        "sfw_gym/rl/waypoint_agent.py",
        "self.model.predict(obs, deterministic=True)",
        "self.model.predict(obs, deterministic=False)",
        "tests/rl/test_waypoint_agent.py",
    ),
    (
        "bug3.waypoint-reward",
        "sfw_gym/envs/waypoint.py",
        "            total += float(reward)",
        "            total = float(reward)",
        "tests/envs/test_rewards.py tests/envs/test_waypoint.py",
    ),
    (
        "bug4.cli-floorplan",
        "sfw_gym/cli/__init__.py",
        "    except (SfwGymError, gym.error.Error) as exc:",
        "    except gym.error.Error as exc:",
        "tests/cli/test_cli.py",
    ),
    (
        "cli.non_negative_int",
        "sfw_gym/cli/options.py",
        'non_negative_int = checked(int, lambda v: v >= 0, "an integer >= 0")',
        "non_negative_int = int",
        "tests/cli/test_cli.py",
    ),
    (
        "cli.positive_float",
        "sfw_gym/cli/options.py",
        "lambda v: math.isfinite(v) and v > 0,",
        "lambda v: True,",
        "tests/cli/test_cli.py",
    ),
    (
        "frontier.candidates",
        "sfw_gym/agents/frontier.py",
        "zip(map(tuple, menu.target_rc[ok].tolist()), u.tolist(), strict=True)",
        "zip(map(tuple, menu.target_rc[ok].tolist()), u[::-1].tolist(), strict=True)",
        "tests/agents/test_agent_behaviour.py -k chosen_goal",
    ),
    (
        "greedy.candidates",
        "sfw_gym/agents/greedy.py",
        "zip(menu.target_rc.tolist(), score.tolist(), strict=True)",
        "zip(menu.target_rc.tolist(), score[::-1].tolist(), strict=True)",
        "tests/agents/test_agent_behaviour.py tests/agents/test_agent_rules.py -k greedy",
    ),
    (
        "candidates.unknown-area-inside",
        "sfw_gym/navigation/candidates.py",
        "* inside).sum(axis=1)",
        ").sum(axis=1)",
        "tests/navigation/test_candidates.py -k unknown_area",
    ),
    (
        "driver.discrete-forward",
        "sfw_gym/navigation/waypoints.py",
        "bumped and self._drove_forward:",
        "bumped:",
        "tests/envs/test_rewards.py -k waypoint",
    ),
    (
        "bench.load-line",
        "sfw_gym/bench.py",
        '    lines.append(\n        f"machine:',
        '    (\n        f"machine:',
        "tests/cli/test_cli.py -k memory",
    ),
    (
        "cli.positive_int",
        "sfw_gym/cli/options.py",
        'positive_int = checked(int, lambda v: v >= 1, "an integer >= 1")',
        "positive_int = int",
        "tests/cli/test_cli.py",
    ),
    (
        "cli.seed_int",
        "sfw_gym/cli/options.py",
        "lambda v: 0 <= v < 2**32",
        "lambda v: True",
        "tests/cli/test_cli.py",
    ),
    (
        "cli.folder",
        "sfw_gym/cli/options.py",
        "lambda v: not Path(v).exists() or Path(v).is_dir()",
        "lambda v: True",
        "tests/cli/test_cli.py",
    ),
    (
        "cli.gym-error",
        "sfw_gym/cli/__init__.py",
        "    except (SfwGymError, gym.error.Error) as exc:",
        "    except SfwGymError as exc:",
        "tests/cli/test_cli.py",
    ),
    (
        "cli.one-line",
        "sfw_gym/cli/__init__.py",
        "{' '.join(message.split())}",
        "{message}",
        "tests/cli/test_cli.py",
    ),
    (
        "cli.routers-count",
        "sfw_gym/cli/options.py",
        "if text.isdigit() and int(text) >= 1:",
        "if text.isdigit():",
        "tests/cli/test_cli.py",
    ),
    (
        "cli.routers-finite",
        "sfw_gym/cli/options.py",
        " or not np.isfinite(arr).all():",
        ":",
        "tests/cli/test_cli.py",
    ),
    (
        "cli.train-spec",
        "sfw_gym/cli/train.py",
        "        gym.spec(args.env)",
        "        pass",
        "tests/cli/test_cli.py",
    ),
    (
        "evaluate.params-dict",
        "sfw_gym/evaluation/runner.py",
        "        if not isinstance(params, dict):",
        "        if False:",
        "tests/cli/test_cli.py",
    ),
    (
        "evaluate.make_agent",
        "sfw_gym/evaluation/runner.py",
        "            make_agent(name, **params)",
        "            pass",
        "tests/cli/test_cli.py",
    ),
    (
        "evaluate.env-kwargs",
        "sfw_gym/evaluation/runner.py",
        "        gym.make(env_id, **(env_kwargs or {})).close()",
        "        pass",
        "tests/cli/test_cli.py",
    ),
    # issues 32 and 33: the config tree, agents on info, the step's speed-ups, the vector envs
    (
        "robot.clearance-skip",
        "sfw_gym/world/robot.py",
        "        if clearance - math.hypot(x - qx, y - qy) - _CLEARANCE_ROUNDING_M >= reach:",
        "        if clearance >= reach:",
        "tests/world/test_robot.py -k shortcut",
    ),
    (
        "robot.sync-before-contact",
        "sfw_gym/world/robot.py",
        "            self._sync_body()\n            space.remove(self._disc)",
        "            space.remove(self._disc)",
        "tests/world/test_robot.py -k shortcut",
    ),
    (
        "robot.substep-order",
        "sfw_gym/world/robot.py",
        "                if i and w != 0.0:",
        "                if i > 1 and w != 0.0:",
        "tests/world/test_robot.py -k shortcut",
    ),
    (
        "obs.crop-edge",
        "sfw_gym/envs/observation.py",
        "min(crop, cols - c0)",
        "min(crop, cols - c0 - 1)",
        "tests/envs/test_explore_env.py -k local_crop",
    ),
    (
        "explore.k-accuracy-cap",
        "sfw_gym/envs/explore.py",
        "self.k_correct += est == min(true, max_k)",
        "self.k_correct += est == true",
        "tests/envs/test_explore_env.py tests/envs/test_rewards.py",
    ),
    (
        "explore.router-slots",
        "sfw_gym/envs/explore.py",
        "readings + [NOT_HEARD_DBM] *",
        "readings + [0] *",
        "tests/envs/test_explore_env.py",
    ),
    (
        "tracker.wall-precision",
        "sfw_gym/envs/map_tracker.py",
        '"wall_precision": ratio(c[_WALL_NEAR], c[_N_EST_WALL])',
        '"wall_precision": ratio(c[_WALL_NEAR], c[_N_EST_WALL] + 1)',
        "tests/envs/test_explore_env.py",
    ),
    (
        "config.k0-level",
        "sfw_gym/envs/config.py",
        'mapper_defaults["k0_level_dbm"] = radio.tx_power_dbm - radio.d0_loss_db',
        'mapper_defaults["k0_level_dbm"] = radio.tx_power_dbm',
        "tests/envs/test_behaviour_digest.py tests/envs/test_explore_env.py",
    ),
    (
        "config.slam-heading-weight",
        "sfw_gym/envs/config.py",
        '"odometry_sigma_rad": max(robot.odometry_heading_std_rad, 1e-3)',
        '"odometry_sigma_rad": 1e-3',
        "tests/envs/test_pose_source.py",
    ),
    (
        "agent.view-from-info",
        "sfw_gym/agents/base.py",
        '        if info is not None and "robot_view" in info:',
        "        if False:",
        "tests/agents/test_agents.py -k info",
    ),
    (
        "robot-view-in-info.step",
        "sfw_gym/envs/robot_view_info.py",
        '{**info, "robot_view": view}',
        "info",
        "tests/agents/test_agents.py -k info",
    ),
    (
        "vector.autoreset",
        "sfw_gym/envs/vector.py",
        "            if self._autoreset[i]:",
        "            if False:",
        "tests/envs/test_vector_env.py",
    ),
    (
        "vector.seed-offset",
        "sfw_gym/envs/vector.py",
        "int(seed) + i for i",
        "int(seed) for i",
        "tests/envs/test_vector_env.py",
    ),
    (
        "vector.info-mask",
        "sfw_gym/envs/vector.py",
        "        mask[have] = True",
        "        mask[:] = True",
        "tests/envs/test_vector_env.py",
    ),
    (
        "sb3.terminal-obs",
        "sfw_gym/rl/vec_env.py",
        "{key: rows[i] for key, rows in obs.items()}",
        "{key: rows[0] for key, rows in obs.items()}",
        "tests/rl/test_sb3_vec_env.py",
    ),
    (
        "sb3.options-per-env",
        "sfw_gym/rl/vec_env.py",
        "(g for g in groups if g[0] == (options or {}))",
        "(g for g in groups)",
        "tests/rl/test_sb3_vec_env.py",
    ),
    (
        "radio.finite-point",
        "sfw_gym/world/radio.py",
        "        if not (math.isfinite(x) and math.isfinite(y)):",
        "        if False:",
        "tests/world/test_radio.py",
    ),
    (
        "agents.own-init-params",
        "sfw_gym/agents/base.py",
        "        for klass in type(self).__mro__:",
        "        for klass in ():",
        "tests/agents/test_agents.py -k params_hold",
    ),
    (
        "config.setting-of-range",
        "sfw_gym/core/config.py",
        "    return field(default=f.default, metadata=f.metadata)",
        "    return field(default=f.default)",
        "tests/agents/test_agent_rules.py -k bad_value",
    ),
    (
        "cli.localize-json-alias",
        "sfw_gym/cli/localize.py",
        '        "--json",  # its name before issue 32, kept as an alias\n',
        "",
        "tests/localization/test_study.py -k json_is",
    ),
    (
        "agents.unknown-setting",
        "sfw_gym/core/config.py",
        "                raise unknown_key_error(what, key, names)",
        "                pass",
        "tests/agents/test_agents.py -k act_before",
    ),
    # issue 33, the batched step: each breaks one line of what keeps a sub-env the single env
    (
        "batch.generator-not-put-back",
        "sfw_gym/envs/batch_step.py",
        "        if drawn_from is not None:",
        "        if False:",
        VECTOR_TESTS,
    ),
    (
        "batch.image-not-redrawn",
        "sfw_gym/envs/batch_step.py",
        "            _redraw_touched(track, maps[2], int(c[GRID_COLS]), belief_px, px_rows, px_cols)",  # noqa: E501
        "            pass",
        VECTOR_TESTS,
    ),
    (
        "batch.libm-hypot",
        "sfw_gym/envs/batch_step.py",
        "    distance = hypot(dx, dy)",
        "    distance = math.hypot(dx, dy)",
        VECTOR_TESTS,
    ),
    (
        "batch.unwrapped-heading",
        "sfw_gym/envs/batch_step.py",
        "        tx, ty, tt = s[X], s[Y], wrap_heading(s[A])",
        "        tx, ty, tt = s[X], s[Y], s[A]",
        VECTOR_TESTS,
    ),
    (
        "batch.odometry-not-written-back",
        "sfw_gym/envs/batch_step.py",
        "        robot._odometry = (s[ODO_X], s[ODO_Y], s[ODO_T])",
        "        pass",
        VECTOR_TESTS,
    ),
    (
        "batch.history-growth-not-reattached",
        "sfw_gym/envs/batch_step.py",
        "                h.reserve(len(h) + 1)\n            self.load(i, env)",
        "                h.reserve(len(h) + 1)",
        VECTOR_TESTS,
    ),
    (
        "batch.image-not-redrawn-after-python",
        "sfw_gym/envs/batch_step.py",
        "            self._episodes[i].belief_px[:] = env.obs_builder.image_of(env.mapper.occupancy_u8)",  # noqa: E501
        "            pass",
        VECTOR_TESTS,
    ),
    (
        "vector.steps-an-ended-episode",
        "sfw_gym/envs/vector.py",
        "        can = ~self._autoreset & self._can_batch",
        "        can = self._can_batch",
        VECTOR_TESTS,
    ),
    (
        "robot.no-contact-margin",
        "sfw_gym/world/robot.py",
        "    contact_m = radii_m + _CONTACT_MARGIN_M",
        "    contact_m = radii_m - 0.01",
        "tests/world/test_robot.py",
    ),
]
only = sys.argv[1:]
for name, f, old, new, tests in CASES:
    if only and name not in only:
        continue
    p = ROOT / f
    src = p.read_text()
    assert src.count(old) == 1, (name, src.count(old))
    p.write_text(src.replace(old, new))
    try:
        r = subprocess.run(
            f"{sys.executable} -m pytest -q -p no:cacheprovider -x {tests}",
            shell=True,
            cwd=ROOT,
            capture_output=True,
            text=True,
        )
        failed = [line for line in r.stdout.splitlines() if line.startswith("FAILED")]
        print(f"{name}: {'CAUGHT' if r.returncode else 'MISSED'} {failed[:1]}", flush=True)
    finally:
        p.write_text(src)
