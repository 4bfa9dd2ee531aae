#!/usr/bin/env bash
# Ablations of the region explorer (BENCHMARKS.md, issue 30): the shipped recipe with one thing
# changed, trained for STEPS decisions (compare with the shipped run's checkpoint at the same
# count), then paired with frontier and the full recipe on the validation seeds.
#   nomap: policy_kwargs map_context=False (the actor scores candidates by their features alone)
#   noprivileged: env_kwargs privileged false (the critic sees no true plan)
#   nofinetune: no fine_tuning block (plain MaskablePPO after cloning)
# Usage: scripts/regions_ablations.sh [OUT=runs/regions_ablations] [STEPS=9000] [FULL=runs/regions]
#        [NAMES...]   (about 10 min per training on 2 cores, cloning included)
set -euo pipefail
out=${1:-runs/regions_ablations}
steps=${2:-9000}
full=${3:-runs/regions}
shift 3 || true
names=${*:-nomap noprivileged nofinetune}
mkdir -p "$out"
for name in $names; do
  python - "$name" "$out/$name.yml" <<'PY'
import sys, yaml
from sfw_gym.core.data import data_path
name, path = sys.argv[1], sys.argv[2]
env_id = "SfW-ExploreRegions-v0"
block = yaml.safe_load(open(data_path("agents", "hyperparams", "ppo_mask.yml")))[env_id]
if name == "nomap":
    block["policy_kwargs"] = "dict(map_context=False)"
elif name == "noprivileged":
    block["env_kwargs"] = {"privileged": False}
elif name == "nofinetune":
    del block["fine_tuning"]
else:
    raise SystemExit(f"unknown ablation {name!r}")
yaml.safe_dump({env_id: block}, open(path, "w"), sort_keys=False)
PY
  sfw-gym train ppo_mask --env SfW-ExploreRegions-v0 --timesteps "$steps" \
    --checkpoint-every "$steps" --eval-every 100000 --eval-episodes 1 \
    --hyperparams "$out/$name.yml" --out "$out/$name" --resume --no-progress
done
