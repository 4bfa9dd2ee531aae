#!/usr/bin/env bash
# Ablations of the shipped candidate-goal explorer (BENCHMARKS.md, issue 13): the shipped recipe
# (behaviour cloning + DAgger + 10,000 MaskablePPO decisions) with one thing changed, then paired
# with frontier on the 50 held-out seeds.
#   nomask: use_masking false (cloning, rollouts, updates and the agent ignore the masks)
#   shared: policy_kwargs shared_trunk=True (the critic reads the actor's per-candidate layer)
#   shipped: the recipe as is (the same run length, for a like-for-like row)
# Usage: scripts/goals_ablations.sh [OUT=runs/ablations] [NAMES...]   (~8 min per training on 2 cores)
set -euo pipefail
out=${1:-runs/ablations}
shift || true
names=${*:-nomask shared shipped}
mkdir -p "$out"
for name in $names; do
  python - "$name" "$out/$name.yml" <<'PY'
import sys, yaml
from sfw_gym.core.data import data_path
name, path = sys.argv[1], sys.argv[2]
block = yaml.safe_load(open(data_path("agents", "hyperparams", "ppo_mask.yml")))["SfW-ExploreGoals-v0"]
block.update({"nomask": {"use_masking": False},
              "shared": {"policy_kwargs": "dict(shared_trunk=True)"},
              "shipped": {}}[name])
yaml.safe_dump({"SfW-ExploreGoals-v0": block}, open(path, "w"), sort_keys=False)
PY
  sfw-gym train ppo_mask --env SfW-ExploreGoals-v0 --timesteps 10000 --checkpoint-every 10000 \
    --eval-every 25000 --eval-episodes 3 --hyperparams "$out/$name.yml" --out "$out/$name" \
    --resume --no-progress
  sfw-gym evaluate --agents frontier,ppo --agent-params "{\"ppo\": {\"path\": \"$out/$name\"}}" \
    --episodes 50 --seed 2000000 --out "$out/$name-eval"
done
