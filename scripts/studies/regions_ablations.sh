#!/usr/bin/env bash
# Ablations of the region explorer (docs/results/training.md#ablations): the shipped recipe with one thing
# changed, trained for STEPS decisions; compare with the full run's checkpoint at the same count
# on the validation seeds (scripts/studies/regions_study.py --seed 1000000). The fine-tuning ablations
# start from the full run's clone (behaviour_cloning.from_model), so only the fine-tuning differs.
#   nofinetune: no fine_tuning block (plain MaskablePPO after cloning)
#   noprivileged: env_kwargs privileged false (the critic sees no true plan)
#   nomap: policy_kwargs map_context=False (the actor scores candidates by their features
#          alone; cloned afresh: its actor differs)
# Usage: [BASE=recipe.yml] scripts/studies/regions_ablations.sh [OUT=runs/regions_ablations] [STEPS=9000]
#        [FULL=runs/regions] [NAMES...]   (BASE: the recipe to ablate, default the shipped
#        ppo_mask.yml; the figures in docs/results/training.md ablate the greedy-teacher variant written
#        there, from its run's clone)
set -euo pipefail
out=${1:-runs/regions_ablations}
steps=${2:-9000}
full=${3:-runs/regions}
shift 3 || true
names=${*:-nofinetune noprivileged nomap}
mkdir -p "$out"
for name in $names; do
  python - "$name" "$out/$name.yml" "$full" "${BASE:-}" <<'PY'
import sys, yaml
from sfw_gym.core.data import data_path
name, path, full, base = sys.argv[1:5]
env_id = "SfW-ExploreRegions-v0"
table = yaml.safe_load(open(base or data_path("agents", "hyperparams", "ppo_mask.yml")))
# the rl-zoo block, and sfw-gym's own keys (cloning, fine-tuning) in the sfw_gym block
block, own = table[env_id], (table.get("sfw_gym") or {}).get(env_id) or {}
if name == "nomap":
    block["policy_kwargs"] = "dict(map_context=False)"
else:
    own["behaviour_cloning"] = {"from_model": full}
    if name == "nofinetune":
        del own["fine_tuning"]
    elif name == "noprivileged":
        block["env_kwargs"] = {"privileged": False}
    else:
        raise SystemExit(f"unknown ablation {name!r}")
yaml.safe_dump({env_id: block, "sfw_gym": {env_id: own}}, open(path, "w"), sort_keys=False)
PY
  sfw-gym train ppo_mask --env SfW-ExploreRegions-v0 --timesteps "$steps" \
    --checkpoint-every "$steps" --eval-every 100000 --eval-episodes 1 \
    --hyperparams "$out/$name.yml" --out "$out/$name" --resume --no-progress
done
