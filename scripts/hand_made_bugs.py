"""Re-make realistic bugs by hand, one at a time, and check that the suite notices each.

Usage: ``python scripts/hand_made_bugs.py [NAME ...]`` (default: every case). Each case replaces one
exact snippet in a source file, runs the named tests with ``-x``, prints CAUGHT (a test failed) or
MISSED, and restores the file. The first five are the bugs of issue 21; the rest are the
behaviours that issue's change added. Takes about 3 minutes on 2 cores.
"""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
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
        "sfw_gym/cli.py",
        "    except (SfwGymError, gym.error.Error) as exc:",
        "    except gym.error.Error as exc:",
        "tests/cli/test_cli.py",
    ),
    (
        "cli.non_negative_int",
        "sfw_gym/cli.py",
        'non_negative_int = checked(int, lambda v: v >= 0, "an integer >= 0")',
        "non_negative_int = int",
        "tests/cli/test_cli.py",
    ),
    (
        "cli.positive_float",
        "sfw_gym/cli.py",
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
        "sfw_gym/cli.py",
        'positive_int = checked(int, lambda v: v >= 1, "an integer >= 1")',
        "positive_int = int",
        "tests/cli/test_cli.py",
    ),
    (
        "cli.seed_int",
        "sfw_gym/cli.py",
        "lambda v: 0 <= v < 2**32",
        "lambda v: True",
        "tests/cli/test_cli.py",
    ),
    (
        "cli.folder",
        "sfw_gym/cli.py",
        "lambda v: not Path(v).exists() or Path(v).is_dir()",
        "lambda v: True",
        "tests/cli/test_cli.py",
    ),
    (
        "cli.gym-error",
        "sfw_gym/cli.py",
        "    except (SfwGymError, gym.error.Error) as exc:",
        "    except SfwGymError as exc:",
        "tests/cli/test_cli.py",
    ),
    (
        "cli.one-line",
        "sfw_gym/cli.py",
        "{' '.join(message.split())}",
        "{message}",
        "tests/cli/test_cli.py",
    ),
    (
        "cli.routers-count",
        "sfw_gym/cli.py",
        "if text.isdigit() and int(text) >= 1:",
        "if text.isdigit():",
        "tests/cli/test_cli.py",
    ),
    (
        "cli.routers-finite",
        "sfw_gym/cli.py",
        " or not np.isfinite(arr).all():",
        ":",
        "tests/cli/test_cli.py",
    ),
    (
        "cli.train-spec",
        "sfw_gym/cli.py",
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
