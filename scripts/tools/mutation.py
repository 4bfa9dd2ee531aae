"""Mutation testing of sfw_gym with mutmut 3 per module group; the table: docs/results/testing.md.

Not run in CI (it takes minutes to hours). Run it from the repository root, niced on a shared box:

    nice -n 10 .venv/bin/python scripts/tools/mutation.py --modules mapper radio navigation
    nice -n 10 .venv/bin/python scripts/tools/mutation.py --modules agents env cli
    nice -n 10 .venv/bin/python scripts/tools/mutation.py --modules navigation \
        --files sfw_gym/navigation/planning.py sfw_gym/navigation/regions.py   # some modules only
    .venv/bin/python scripts/tools/mutation.py --report-only   # the table from mutants/ only

How long it took (x86_64, 2 cores shared with other work, load ≈ 2, 2 workers, niced):
mapper + radio + navigation, 2,012 mutants: 7.7 min wall (4.5 mutants/s; the unit tests of these
groups take ~0.1 s per mutant); ``--survivors`` after adding tests: under 1 min. The agents, env
and cli groups run integration tests (episodes, PPO, the CLI) per mutant: expect seconds per
mutant, i.e. hours for a group; run one group at a time and use ``--survivors`` afterwards.
Stats collection (one run of the groups' test files with mutmut's trampolines) comes first.
Since the kernels are mutated (2026-11-29, JIT disabled: every test of these groups runs its
kernels as Python), the kernel groups are far slower: mapper 4,010 mutants (about 0.1-0.5 per
second; its stats collection alone about 8 min, the compiled-vs-Python k-means tests dominate),
radio 1,318, navigation several thousand; hence ``--sample`` for them (mapper 30 per module:
24 min wall, radio 20 per module: 3 min; raycast.py in full, 276 mutants: 9.7 min). A kernel
mutant that loops forever is stopped after ``(estimate + timeout_constant) * 30`` CPU seconds
(``TIMEOUT_CONSTANT_S``), where the estimate is the time of the tests that call the function:
for a kernel that most tests call (planning's Dijkstra) that can exceed an hour, so stop such a
mutant by hand with ``kill -XCPU <pid>`` (mutmut records it as a timeout) and make the loop end.
Issue 39 (2026-11-27, load 5-7 from other work): evaluation, 180 sampled mutants of its 9 slow
modules, 26 min; navigation with the agents' unit tests, 10-35 mutants/min (a full run of the
four issue-39 modules, 2,358 mutants, would have taken over an hour, hence ``--sample``).

What it does
------------
1. Runs ``mutmut run`` on the source files of the chosen groups (``GROUPS``), with mutmut's
   configuration from ``[tool.mutmut]`` in pyproject.toml, except two fields that it sets for the
   run: ``only_mutate`` (the groups' files) and ``pytest_add_cli_args_test_selection`` (the
   groups' test files). mutmut already runs, for each mutant, only the tests that called the
   mutated function while it collected its stats; restricting the collection to the groups' unit
   tests keeps the integration tests (whole episodes, PPO, CLI) out of every mapper mutant's run.
   Every mutant of the chosen groups is run again (explicit mutant globs), because mutmut keeps a
   verdict as long as the *function* is unchanged, even after tests were added.
2. Reads the verdicts from mutmut's meta files (``mutants/<source>.py.meta``, the same files that
   ``mutmut results`` and ``mutmut export-cicd-stats`` read; exit codes → statuses through
   ``mutmut.stats.status_by_exit_code``).
3. Subtracts the mutants reviewed as equivalent (``scripts/tools/mutation_equivalent.toml``: mutant
   name → one-line reason; a name there that is *killed* is reported, since the entry is stale),
   writes the per-module table to stdout, stores the group's numbers in
   ``docs/results/data/mutation_results.json`` (so that a run of other groups keeps them) and
   rewrites the table between ``<!-- mutation:begin -->`` and ``<!-- mutation:end -->`` in
   docs/results/testing.md.

score = killed / (mutants − equivalent); "timeout" and "no tests" mutants count against it.

mutmut notes: it copies the package and tests into ``mutants/`` (git-ignored) and imports from
there; decorated functions are not mutated, but for the numba ``@njit`` kernels: the runs set
``NUMBA_DISABLE_JIT=1``, under which ``njit`` returns the Python function, and mutmut is told to
mutate functions whose only decorators are ``njit`` (see ``_BOOTSTRAP``);
``conftest.HOUSEEXPO_DIR`` resolves to ``mutants/../shared`` = ``<repo>/shared``, which does not
exist, so the three HouseExpo tests of test_floorplan.py skip under mutmut (no group here relies on
them). Two mutmut 3.8 quirks this script works around: a file copied unmutated by a run of other
groups (or other ``--files``) is newer than its source, and mutmut then never mutates it again (the
script deletes such copies before a run of that file; mutmut keeps the verdicts of its unchanged
functions); and mutmut reuses its stats when the test selection is unchanged, so functions of a
newly mutated file get "no tests" (the script deletes ``mutants/mutmut-stats.json`` before each
run, so mutmut also never sees a change of the test selection: verdicts in mutants/ stay until a
run names them). The numbers of every group stay in ``docs/results/data/mutation_results.json``.

``--files`` runs some modules of a group (the rest keep their stored numbers), e.g. a full run of
the fast modules and ``--sample`` of the slow ones of the same group, as for ``evaluation``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import random
import re
import subprocess
import sys
import textwrap
import time
from datetime import date
from pathlib import Path

import tomllib

ROOT = Path(__file__).resolve().parents[2]
EQUIVALENT_FILE = ROOT / "scripts" / "tools" / "mutation_equivalent.toml"
RESULTS_FILE = ROOT / "docs" / "results" / "data" / "mutation_results.json"
RESULTS_PAGE = ROOT / "docs" / "results" / "testing.md"
BEGIN, END = "<!-- mutation:begin -->", "<!-- mutation:end -->"

#: group -> (source files to mutate, test files whose tests may kill them)
GROUPS: dict[str, tuple[list[str], list[str]]] = {
    "mapper": (
        [
            "sfw_gym/mapping/sparse.py",
            "sfw_gym/mapping/k_estimation.py",
            "sfw_gym/mapping/kmeans1d.py",
            "sfw_gym/mapping/grid.py",
            "sfw_gym/mapping/raycast.py",
            "sfw_gym/mapping/dry_run.py",
            "sfw_gym/mapping/dense.py",
            "sfw_gym/mapping/reference.py",
            "sfw_gym/mapping/lidar_map.py",
        ],
        [
            "tests/mapping/test_sparse_mapper.py",
            "tests/mapping/test_mapper_rules.py",
            "tests/mapping/test_k_estimation.py",
            "tests/mapping/test_grid.py",
            "tests/mapping/test_dense_mapper.py",
            "tests/mapping/test_dry_run.py",
            "tests/mapping/test_reference.py",
            "tests/mapping/test_lidar_map.py",
        ],
    ),
    # the radio model and the wall geometry its attenuation counts walls with
    "radio": (
        [
            "sfw_gym/world/radio.py",
            "sfw_gym/world/wall_crossing.py",
            "sfw_gym/world/wall_index.py",
        ],
        [
            "tests/world/test_radio.py",
            "tests/world/test_wall_index.py",
            "tests/world/test_radio_kernels.py",
        ],
    ),
    # the robot's motion (its compiled free-space substeps) and the LiDAR's beams
    "world": (
        ["sfw_gym/world/robot.py", "sfw_gym/world/lidar.py"],
        [
            "-m",
            "not slow",
            "tests/world/test_robot.py",
            "tests/world/test_lidar.py",
            "tests/world/test_plan_limits.py",
        ],
    ),
    # the navigation unit tests, the region env's (the one user of regions.py) and the agents'
    # unit tests (frontier's approach cells, greedy's choice, cross-pass's dominance bands)
    "navigation": (
        sorted(str(p.relative_to(ROOT)) for p in (ROOT / "sfw_gym" / "navigation").glob("*.py")),
        [
            "-m",
            "not slow",
            *sorted(
                str(p.relative_to(ROOT)) for p in (ROOT / "tests" / "navigation").glob("test_*.py")
            ),
            "tests/envs/test_regions.py",
            "tests/agents/test_agents.py",
            "tests/agents/test_agent_rules.py",
            # and the tests that drive an agent for a whole episode: with the kernels run as
            # Python (JIT off) they take 10-100 s each, 3.5 of the selection's 7 min
            "-k",
            "not bounded_first_search and not drives_on_to_its_goal"
            " and not ground_truth_through_the_interface and not every_agent_builds",
        ],
    ),
    "agents": (
        sorted(str(p.relative_to(ROOT)) for p in (ROOT / "sfw_gym" / "agents").glob("*.py")),
        [
            "tests/agents/test_agents.py",
            "tests/agents/test_agent_rules.py",
            "tests/agents/test_agent_behaviour.py",
            "tests/rl/test_ppo_agent.py",
            "tests/rl/test_waypoint_agent.py",
        ],
    ),
    "env": (
        ["sfw_gym/envs/explore.py", "sfw_gym/envs/waypoint.py"],
        [
            "tests/envs/test_envs.py",
            "tests/envs/test_explore_env.py",
            "tests/envs/test_waypoint.py",
            "tests/envs/test_rewards.py",
        ],
    ),
    "cli": (["sfw_gym/cli.py"], ["tests/cli/test_cli.py", "tests/cli/test_demo.py"]),
    # the evaluation tests but the slow ones (whole benchmark runs, worker pools, a resumed run
    # killed five times: minutes per mutant on 2 cores); fingerprints.py is run from the CLI
    "evaluation": (
        sorted(str(p.relative_to(ROOT)) for p in (ROOT / "sfw_gym" / "evaluation").glob("*.py")),
        [
            "-m",
            "not slow",
            *sorted(
                str(p.relative_to(ROOT))
                for p in (ROOT / "tests" / "evaluation").glob("test_*.py")
                if p.name != "test_compare_runs.py"  # it tests scripts/, which mutants/ lacks
            ),
            "tests/cli/test_fingerprints_cli.py",
        ],
    ),
}

#: mutmut's ``timeout_constant`` for groups whose tests have no slow fixtures (pyproject's 30 s
#: is for the agents' whole-episode module fixtures). A mutant's CPU limit is mutmut 3.8's
#: ``(estimated test time + constant) * timeout_multiplier (15) * 2``: with 30 s, every kernel
#: mutant that loops forever (e.g. an index step mutated to 0) held a worker 15 min or more.
TIMEOUT_CONSTANT_S = {"mapper": 5.0, "radio": 5.0, "world": 5.0, "navigation": 5.0}

COLUMNS = ["mutants", "killed", "survived", "timeout", "no tests", "other", "equivalent"]

# Runs mutmut in a child interpreter with two config fields overridden. mutmut's fork server and
# workers are os.fork()ed from it, so they inherit the patched configuration.
#
# The numba kernels are mutated too: mutmut skips decorated functions (a decorator may not survive
# being applied to its trampoline and mutant copies), but ``@njit(...)`` returns the function
# itself when NUMBA_DISABLE_JIT=1, which the child runs with, so a kernel is plain Python there.
_BOOTSTRAP = """
import json, sys
import libcst as cst
import mutmut.configuration as configuration
import mutmut.mutation.file_mutation as file_mutation

def _is_njit(decorator):
    target = decorator.decorator
    target = target.func if isinstance(target, cst.Call) else target
    return isinstance(target, cst.Name) and target.value == "njit"

_skip = file_mutation.MutationVisitor._skip_node_and_children

def _skip_but_kernels(self, node):
    kernel = isinstance(node, cst.FunctionDef) and node.decorators
    if kernel and all(map(_is_njit, node.decorators)):
        return _skip(self, node.with_changes(decorators=[]))  # as if undecorated
    return _skip(self, node)

file_mutation.MutationVisitor._skip_node_and_children = _skip_but_kernels
only_mutate, tests, args, timeout_constant = json.loads(sys.argv[1])
cfg = configuration.config()
cfg.only_mutate = only_mutate
cfg.pytest_add_cli_args_test_selection = tests
if timeout_constant is not None:
    cfg.timeout_constant = timeout_constant
from mutmut.__main__ import cli
cli(["run", *args])
"""


def module_name(path: str) -> str:
    return path[: -len(".py")].replace("/", ".")


def forget_unmutated_copies(files: list[str]) -> None:
    """Delete ``mutants/<file>`` where it holds no mutants.

    A run of other groups (or of other ``--files``) copies this file into mutants/ unmutated
    (it is not in only_mutate), and mutmut 3.8 takes a copy newer than its source for an
    up-to-date mutated file (it compares mtimes only): it would generate no mutants for it.
    Deleting the copy makes mutmut generate them again; the verdicts in the file's meta are
    kept for the functions whose source did not change.
    """
    for f in files:
        copy = ROOT / "mutants" / f
        if copy.exists() and (
            not (ROOT / "mutants" / (f + ".meta")).exists()
            or "__mutmut_" not in copy.read_text(encoding="utf-8")
        ):
            copy.unlink()


def run_mutmut(
    files: list[str],
    tests: list[str],
    max_children: int,
    names: list[str] | None = None,
    check: bool = True,
    timeout_constant: float | None = None,
    fresh_stats: bool = True,
) -> float:
    """Run mutmut on ``files`` (every mutant, or only ``names``); return the wall time."""
    forget_unmutated_copies(files)
    # Fresh stats: mutmut reuses its stats file when the test selection is unchanged, and then
    # knows no tests for functions of a file that was not mutated when the stats were taken
    # (every mutant of it would be "no tests"). Collecting them again costs one test run
    # (minutes for the kernel groups): not done right after ``sample_mutants`` generated the
    # mutants, since that run collected them for the same files and tests.
    if fresh_stats:
        (ROOT / "mutants" / "mutmut-stats.json").unlink(missing_ok=True)
    globs = names if names else [module_name(f) + ".*" for f in files]
    args = ["--max-children", str(max_children), *globs]
    payload = json.dumps([files, tests, args, timeout_constant])
    start = time.perf_counter()
    env = os.environ | {"NUMBA_DISABLE_JIT": "1"}  # the kernels as Python, so mutmut reaches them
    cmd = [sys.executable, "-c", _BOOTSTRAP, payload]
    proc = subprocess.run(cmd, cwd=ROOT, env=env, check=False)
    wall = time.perf_counter() - start
    if check and proc.returncode not in (0, None):
        sys.exit(f"mutmut run failed with exit code {proc.returncode}")
    return wall


def sample_mutants(
    files: list[str], n: int, tests: list[str], max_children: int
) -> tuple[list[str], bool]:
    """``n`` mutant names per file, drawn with seed 0 (mutmut generates them first if needed),
    and whether mutmut ran to generate them (its stats are then current)."""
    generated = not all(statuses(f) for f in files)
    if generated:
        # generate only: mutmut then stops, with an error, as no mutant has that name (after
        # collecting its stats)
        run_mutmut(files, tests, max_children, names=["none.such.mutant"], check=False)
    rng = random.Random(0)
    names: list[str] = []
    for f in files:
        population = sorted(statuses(f))
        chosen = set(rng.sample(population, min(n, len(population))))
        names += sorted(chosen)
        # forget earlier verdicts outside the sample, so that the table counts the sample only
        meta = ROOT / "mutants" / (f + ".meta")
        data = json.loads(meta.read_text())
        for name in population:
            if name not in chosen:
                data["exit_code_by_key"][name] = None
        meta.write_text(json.dumps(data))
    return names, generated


def statuses(path: str) -> dict[str, str]:
    """Mutant name -> mutmut status, from mutmut's meta file for ``path``."""
    from mutmut.stats import status_by_exit_code

    meta = ROOT / "mutants" / (path + ".meta")
    if not meta.exists():
        return {}
    codes = json.loads(meta.read_text())["exit_code_by_key"]
    return {name: status_by_exit_code[code] for name, code in codes.items()}


def load_equivalent() -> dict[str, str]:
    if not EQUIVALENT_FILE.exists():
        return {}
    return dict(tomllib.loads(EQUIVALENT_FILE.read_text())["equivalent"])


def tally(path: str, equivalent: dict[str, str]) -> tuple[dict[str, int], list[str], list[str]]:
    """Counts for one source file, the surviving non-equivalent mutants, and stale entries."""
    counts = dict.fromkeys(COLUMNS, 0)
    open_mutants, stale = [], []
    for name, status in sorted(statuses(path).items()):
        if status == "not checked":  # outside a sampled run's sample
            continue
        counts["mutants"] += 1
        if name in equivalent:
            if status == "killed":
                stale.append(name)
            else:
                counts["equivalent"] += 1
                continue
        if status in ("killed", "survived", "timeout", "no tests"):
            counts[status] += 1
        else:
            counts["other"] += 1
        if status != "killed":
            open_mutants.append(f"{name}: {status}")
    return counts, open_mutants, stale


def score(c: dict[str, int]) -> float:
    denominator = c["mutants"] - c["equivalent"]
    return c["killed"] / denominator if denominator else float("nan")


def wilson(c: dict[str, int]) -> tuple[float, float]:
    """95 % Wilson interval of the score (for a random sample of a module's mutants)."""
    n = c["mutants"] - c["equivalent"]
    if not n:
        return float("nan"), float("nan")
    p, z = c["killed"] / n, 1.96
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return centre - half, centre + half


def group_record(rec: dict) -> dict:
    """A group's stored numbers as ``{"modules": {path: counts}, "runs": [run, ...]}``.

    A sampled module's counts carry ``sample_of`` (its number of mutants); each run names the
    ``files`` it ran. Records written before ``--files`` existed (one run per group, a
    group-wide ``sample``) are converted.
    """
    if "runs" in rec:
        return rec
    run = {k: v for k, v in rec.items() if k not in ("modules", "sample", "population")}
    run["files"] = list(rec.get("modules", {}))
    modules = {}
    for path, c in rec.get("modules", {}).items():
        modules[path] = dict(c)
        if rec.get("sample"):
            modules[path]["sample_of"] = rec.get("population", {}).get(path, "?")
    return {"modules": modules, "runs": [run]}


def table(results: dict) -> str:
    head = ["group", "module", *COLUMNS, "score"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * 2 + "---:|" * (len(head) - 2)]
    for group in GROUPS:
        if group not in results["groups"]:
            continue
        for path, c in results["groups"][group]["modules"].items():
            cell = f"{score(c):.1%}"
            if "sample_of" in c:
                low, high = wilson(c)
                cell += f" (95 % CI {low:.0%}–{high:.0%}; sample of {c['sample_of']})"
            cells = [group, f"`{path}`", *(str(c[k]) for k in COLUMNS), cell]
            lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def section(results: dict) -> str:
    runs: dict[str, list[str]] = {}  # run description -> groups (groups run together share one)
    for g, r in ((g, r) for g, rec in results["groups"].items() for r in rec["runs"]):
        line = f"{r.get('command', '?')}: {r.get('n_mutants', '?')} mutants,"
        if "wall_s" in r:
            line += f" {r['wall_s'] / 60:.1f} min wall,"
        line += f" {r.get('date', '?')}"
        line += f", {r.get('machine', '?')}"
        if "rerun" in r:
            line += f"; after the review, {r['rerun']}"
        runs.setdefault(line, []).append(f"`{g}`")
    text = (
        f"Made by `scripts/tools/mutation.py` (mutmut {results.get('mutmut', '?')}, configuration"
        " `[tool.mutmut]` in pyproject.toml, fork-server isolation, 2 workers); not run in CI."
        " score = killed / (mutants − equivalent); timeouts, crashes and mutants without tests"
        " count as not killed. Equivalent mutants, each with its reason:"
        " `scripts/tools/mutation_equivalent.toml`; the others not killed:"
        " `scripts/tools/mutation.py --report-only --list-survivors`. The numba `@njit` kernels"
        " (the sparse mapper's ray update, k-means and the k thresholds, grid traversal, the RSSI"
        " and wall-crossing kernels, planning's Dijkstra, ...) are mutated too: the runs set"
        " `NUMBA_DISABLE_JIT=1`, so each mutant runs as plain Python, and mutmut is told to mutate"
        " functions whose only decorators are `njit`; rows measured before that change (the"
        " groups' runs dated before 2026-11-29) count the kernels' Python callers only. Each"
        " mutant runs only the tests of its group's test files that call the mutated function"
        " (`GROUPS` in the script)."
    )
    return "\n".join(
        [
            BEGIN,
            "",
            textwrap.fill(text, width=100, break_on_hyphens=False),
            "",
            table(results),
            "",
            "Runs (machine as reported by the script):",
            "",
            *(f"- {', '.join(groups)}: {line}" for line, groups in runs.items()),
            "",
            END,
        ]
    )


def write_benchmarks(text: str) -> None:
    doc = RESULTS_PAGE.read_text()
    if BEGIN in doc and END in doc:
        doc = re.sub(re.escape(BEGIN) + r".*?" + re.escape(END), lambda _: text, doc, flags=re.S)
    else:
        doc = doc.rstrip("\n") + "\n\n## Mutation testing\n\n" + text + "\n"
    RESULTS_PAGE.write_text(doc)


def machine() -> str:
    load = os.getloadavg()[0]
    return f"{platform.machine()}, {os.cpu_count()} cores, load {load:.1f} at the end"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--modules", nargs="+", choices=list(GROUPS), default=list(GROUPS))
    ap.add_argument("--max-children", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--report-only", action="store_true", help="do not run mutmut, only report")
    ap.add_argument("--list-survivors", action="store_true", help="print surviving mutants")
    ap.add_argument(
        "--survivors",
        action="store_true",
        help="re-run only the mutants not killed (and not equivalent) in the last run of the "
        "same groups, e.g. after adding tests; the other verdicts are kept",
    )
    ap.add_argument(
        "--sample",
        type=int,
        default=0,
        metavar="N",
        help="run a random sample (seed 0) of N mutants per module instead of all of them; the "
        "table then gives the score's 95 %% Wilson interval (for groups whose tests run whole "
        "episodes: all of their mutants take hours on 2 cores)",
    )
    ap.add_argument(
        "--files",
        nargs="+",
        metavar="SOURCE",
        help="only these source files of the chosen groups (e.g. sfw_gym/navigation/regions.py);"
        " the group's other modules keep their stored numbers",
    )
    args = ap.parse_args(argv)

    import mutmut

    results = json.loads(RESULTS_FILE.read_text()) if RESULTS_FILE.exists() else {"groups": {}}
    results["groups"] = {g: group_record(r) for g, r in results["groups"].items()}
    results["mutmut"] = mutmut.__version__
    equivalent = load_equivalent()

    files = [f for g in args.modules for f in GROUPS[g][0]]
    if args.files:
        unknown = sorted(set(args.files) - set(files))
        if unknown:
            ap.error(f"not a source file of the groups {args.modules}: {', '.join(unknown)}")
        files = [f for f in files if f in args.files]
    wall = None
    if not args.report_only:
        tests = [t for g in args.modules for t in GROUPS[g][1]]
        # a listed test file that does not exist (yet) would make pytest, and so mutmut, fail
        tests = [t for t in tests if not t.endswith(".py") or (ROOT / t).exists()]
        constants = [TIMEOUT_CONSTANT_S.get(g) for g in args.modules]
        timeout = None if None in constants else max(constants)
        names, generated, t_sample = None, False, 0.0
        if args.survivors:
            names = [
                name
                for f in files
                for name, status in statuses(f).items()
                if status not in ("killed", "not checked") and name not in equivalent
            ]
            print(f"re-running {len(names)} mutants that were not killed")
        elif args.sample:
            t_sample = time.perf_counter()  # generating the mutants is part of the run's time
            names, generated = sample_mutants(files, args.sample, tests, args.max_children)
            t_sample = time.perf_counter() - t_sample
            print(f"running a sample of {len(names)} mutants")
        if names is None or names:
            wall = t_sample + run_mutmut(
                files, tests, args.max_children, names, timeout, fresh_stats=not generated
            )

    modules = " ".join(args.modules)
    command = f"`nice -n 10 .venv/bin/python scripts/tools/mutation.py --modules {modules}"
    command += f" --files {' '.join(args.files)}" if args.files else ""
    command += f" --sample {args.sample}`" if args.sample else "`"
    fresh = wall is not None and not args.survivors  # a new run, not a rerun of survivors
    for group in args.modules:
        group_files = [f for f in GROUPS[group][0] if f in files]
        record = results["groups"].get(group, {"modules": {}, "runs": []})
        modules, survivors = {}, []
        for path in group_files:
            counts, open_mutants, stale = tally(path, equivalent)
            if counts["mutants"]:
                modules[path] = counts
                earlier = record["modules"].get(path, {})
                if fresh and args.sample:
                    counts["sample_of"] = len(statuses(path))
                elif not fresh and "sample_of" in earlier:
                    counts["sample_of"] = earlier["sample_of"]
            survivors += open_mutants
            for name in stale:
                print(f"warning: {name} is listed as equivalent but was killed", file=sys.stderr)
        checked = any(c["mutants"] > c["other"] for c in modules.values())
        if not modules or (wall is None and not checked):
            continue  # nothing measured (or verdicts reset by a later run of other groups)
        if wall is not None and args.survivors:
            rerun = (
                f"{command[:-1]} --survivors`: {len(names or [])} mutants not killed before,"
                f" {wall / 60:.1f} min, {date.today()}"
            )
            for run in record["runs"]:
                if set(run.get("files", [])) & set(group_files):
                    run["rerun"] = rerun
        elif fresh:
            run = {"command": command, "wall_s": round(wall, 1), "date": str(date.today())}
            run["n_mutants"] = sum(c["mutants"] for c in modules.values())
            run["machine"] = machine()
            run["files"] = list(modules)
            # an earlier run keeps only the modules this one did not measure again
            for r in record["runs"]:
                r["files"] = [f for f in r.get("files", []) if f not in modules]
            record["runs"] = [r for r in record["runs"] if r["files"]]
            record["runs"].append(run)
        if fresh and not args.files:
            record["modules"] = modules
        else:
            record["modules"].update(modules)
        results["groups"][group] = record
        if args.list_survivors:
            print(f"# {group}: not killed, not equivalent")
            print("\n".join(survivors) or "(none)")

    print(table(results))
    RESULTS_FILE.write_text(json.dumps(results, indent=2, sort_keys=True) + "\n")
    write_benchmarks(section(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
