"""Fuzz the command line: any argv ends with exit 0, or exit 2 and one error line (no traceback)."""

from __future__ import annotations

import contextlib
import io

from hypothesis import given
from hypothesis import strategies as st

from sfw_gym.cli import main
from sfw_gym.core.errors import SfwGymError
from tests.fuzz.conftest import outcome

values = st.one_of(
    st.sampled_from(["0", "-1", "1", "3", "0.5", "nan", "inf", "1e9", "", "x", "1,1", "1,1;2,2"]),
    st.text(alphabet=st.characters(blacklist_categories=["Cs"]), max_size=6),
)
OPTIONS = {
    "world": ["--seed", "--resolution", "--preset", "--band", "--floorplan", "--routers"],
    "map": ["--routers", "--scale", "--px-per-m", "--resolution", "--margin", "--rssi-column"],
    "bench": ["--env", "--steps", "--resets", "--memory-steps"],
    "slam": ["--keyframes", "--odometry-sigma", "--heading-sigma"],
    "evaluate": ["--agents", "--episodes", "--seed", "--env", "--env-kwargs", "--agent-params"],
    "benchmark": ["--agent", "--split", "--episodes", "--seed", "--agent-params", "--protocol"],
}
#: A one-episode protocol of 5 steps per split, so that the valid benchmark runs stay short.
TINY_PROTOCOL = """
name: tiny
version: 1
envs:
  - id: SfW-ExploreSmall-v0
    kwargs: {max_steps: 5}
    episodes: {train: 1, validation: 1, test: 1}
splits:
  seeds: {train: [0, 9], validation: [10, 19], test: [20, 29]}
  plan_files: {train: [0, 1, 2, 3, 4, 5], validation: [6, 7], test: [8, 9]}
metrics: [coverage, path_length_m]
intervals: {confidence: 0.95, resamples: 100, random_state: 0}
"""


@st.composite
def argvs(draw) -> list[str]:
    command = draw(st.sampled_from(sorted(OPTIONS)))
    argv = [command]
    if command == "benchmark":
        argv += ["--agent", "random", "--protocol", "{tmp}/tiny.yml"]  # fuzzed values follow
    if command == "map":
        argv.append(draw(st.sampled_from(["{tmp}/log.csv", "{tmp}/none.csv", ""])))
    if command == "slam":
        argv.append(draw(st.sampled_from(["{tmp}/slam.csv", "{tmp}/log.csv", "{tmp}", ""])))
    for option in draw(st.lists(st.sampled_from(OPTIONS[command]), max_size=3, unique=True)):
        argv += [option, draw(values)]
    return argv


@given(argvs())
def test_command_lines(tmp_path_factory, argv):
    tmp = tmp_path_factory.mktemp("cli")
    (tmp / "log.csv").write_text("x,y,rssi\n1,1,-40\n2,1,-45\n3,1,-60\n")
    (tmp / "slam.csv").write_text(
        "time,odom_x,odom_y,odom_theta,a,b\n0,0,0,0,-40,-70\n1,1,0,0,-45,\n2,2,0,0.1,-60,-65\n"
    )
    (tmp / "tiny.yml").write_text(TINY_PROTOCOL)
    argv = [a.replace("{tmp}", str(tmp)) for a in argv]
    if argv[0] in ("bench", "evaluate"):  # keep the valid ones short
        argv += ["--env", "SfW-ExploreSmall-v0"]
    if argv[0] == "bench":
        argv += ["--steps", "5", "--resets", "1", "--memory-steps", "5"]
    if argv[0] == "evaluate":
        argv += ["--episodes", "1", "--workers", "1", "--no-progress", "--out", str(tmp / "ev")]
        argv += ["--env-kwargs", '{"max_steps": 5}']
    if argv[0] == "benchmark":
        argv += ["--workers", "1", "--no-progress", "--out", str(tmp / "bm")]
    if argv[0] in ("world", "map"):
        argv += ["--out", str(tmp / "out.png")]
    if argv[0] == "slam":
        argv += ["--out", str(tmp / "slam_out")]
    err = io.StringIO()

    def run() -> None:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            try:
                code = main(argv)
            except SystemExit as exc:  # argparse's usage errors
                code = exc.code
        assert code in (0, 2), (argv, code, err.getvalue())
        if code == 2:
            lines = [line for line in err.getvalue().splitlines() if line.startswith("sfw-gym")]
            assert len(lines) == 1 and "Traceback" not in err.getvalue(), err.getvalue()
            raise ExitedWithError(lines[0])

    outcome("CLI argv", run)


class ExitedWithError(SfwGymError):
    """The command exited with status 2 and this one error line."""
