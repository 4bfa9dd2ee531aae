#!/usr/bin/env bash
# Ablations of the shipped candidate-goal explorer (docs/results/training.md#ablations): the shipped recipe
# (behaviour cloning + DAgger + 10,000 MaskablePPO decisions) with one thing changed, then paired
# with frontier on the 50 held-out seeds.
#   nomask: use_masking false (cloning, rollouts, updates and the agent ignore the masks)
#   shared: policy_kwargs shared_trunk=True (the critic reads the actor's per-candidate layer)
#   shipped: the recipe as is (the same run length, for a like-for-like row)
# Usage: scripts/studies/goals_ablations.sh [OUT=runs/ablations] [NAMES...]   (~8 min per training on 2 cores)
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
env_id = "SfW-ExploreGoals-v0"
table = yaml.safe_load(open(data_path("agents", "hyperparams", "ppo_mask.yml")))
# the rl-zoo block, and sfw-gym's own keys (cloning, use_masking) in the sfw_gym block
block, own = table[env_id], (table.get("sfw_gym") or {}).get(env_id) or {}
if name == "nomask":
    own["use_masking"] = False
elif name == "shared":
    block["policy_kwargs"] = "dict(shared_trunk=True)"
elif name != "shipped":
    raise SystemExit(f"unknown ablation {name!r}")
yaml.safe_dump({env_id: block, "sfw_gym": {env_id: own}}, open(path, "w"), sort_keys=False)
PY
  sfw-gym train ppo_mask --env SfW-ExploreGoals-v0 --timesteps 10000 --checkpoint-every 10000 \
    --eval-every 25000 --eval-episodes 3 --hyperparams "$out/$name.yml" --out "$out/$name" \
    --resume --no-progress
  sfw-gym evaluate --agents frontier,goals-ppo \
    --agent-params "{\"goals-ppo\": {\"path\": \"$out/$name\"}}" \
    --episodes 50 --seed 2000000 --out "$out/$name-eval"
done
