#!/usr/bin/env bash
# What a new user gets from the wheel, with no checkout in sight: build it, install it in a fresh
# venv in a temp folder, and run there (1) the light core without torch, (2) with the [rl] extra,
# wheels-ppo, WaypointPPOAgent(), PPOAgent(), `sfw-gym demo` and `sfw-gym train ppo`. CI runs this after the tests.
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
python="${PYTHON:-python3}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$python" -m pip wheel --quiet --no-deps --wheel-dir "$work/dist" "$repo"
wheel="$(ls "$work"/dist/sfw_gym-*.whl)"
echo "built $(basename "$wheel") ($(du -h "$wheel" | cut -f1))"
"$python" - "$wheel" <<'PY'
import sys, zipfile
names = zipfile.ZipFile(sys.argv[1]).namelist()
meta = zipfile.ZipFile(sys.argv[1]).read(next(n for n in names if n.endswith("dist-info/METADATA")))
assert b"License-Expression: MIT" in meta, "the wheel's metadata names no MIT licence"
assert any(n.endswith("dist-info/licenses/LICENSE") for n in names), "the wheel carries no LICENSE"
print("the wheel carries the MIT licence (License-Expression: MIT, LICENSE)")
PY
"$python" -m venv "$work/venv"
py="$work/venv/bin/python"
cd "$work"  # the checkout is neither the working directory nor on sys.path

"$py" -m pip install --quiet "$wheel"
"$py" - <<'PY'
import importlib.util, sys
import gymnasium as gym
import sfw_gym
from sfw_gym.agents import make_agent
assert "site-packages" in sfw_gym.__file__, sfw_gym.__file__
assert importlib.util.find_spec("torch") is None, "the core must not pull torch"
env = gym.make("SfW-ExploreSmall-v0")
obs, _ = env.reset(seed=0)
agent = make_agent("frontier")
agent.reset(env, seed=0)
for _ in range(50):
    obs, *_ = env.step(agent.act(obs))
assert "torch" not in sys.modules
print("core without torch: gym.make, step and the frontier agent work")
PY

"$py" -m pip install --quiet torch==2.13.0  # the CPU build (an unpinned torch pulls CUDA)
"$py" -m pip install --quiet "$wheel[rl]"
"$py" -c "from sfw_gym.agents import make_agent; a = make_agent('wheels-ppo'); print('wheels-ppo loads', a.settings.path)"
"$py" -c "from sfw_gym.rl import WaypointPPOAgent; a = WaypointPPOAgent(); print('WaypointPPOAgent() loads', a.settings.path)"
"$py" -c "from sfw_gym.rl import PPOAgent; a = PPOAgent(); print('PPOAgent() loads', a.settings.path)"
"$py" -c "from sfw_gym.rl import RegionsPPOAgent; a = RegionsPPOAgent(); print('RegionsPPOAgent() loads', a.settings.path)"
"$py" -c "from sfw_gym.agents import make_agent; a = make_agent('predict-explore'); p = a.make_predictor(); print('predict-explore loads its predictor', p.path)"
"$py" - <<'PY'
import gymnasium as gym

import sfw_gym  # noqa: F401
from sfw_gym.agents import make_agent

env = gym.make("SfW-ExploreSmall-v0")
obs, _ = env.reset(seed=0)
agent = make_agent("rollout-explore")
agent.reset(env, seed=0)
for _ in range(40):
    obs, *_ = env.step(agent.act(obs))
print("rollout-explore drives from the wheel, dry runs and all:", agent.predictor.path)
PY
"$work/venv/bin/sfw-gym" demo --episodes 1 --workers 1 --out "$work/report" --no-progress | tail -3
"$work/venv/bin/sfw-gym" train ppo --env SfW-ExploreSmall-v0 --timesteps 256 --out "$work/run" \
    --no-progress | tail -2
test -f "$work/run/SfW-ExploreSmall-v0.zip"  # rl-zoo's name for the model
echo "wheel check passed"
