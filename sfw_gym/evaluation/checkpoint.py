"""A run folder's state on disk: the JSONL checkpoint of finished episodes (one record appended
per episode, resumed from after a kill) and the manifests that a resume checks, so that a folder
never mixes the records of two different runs."""

from __future__ import annotations

import json
import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from sfw_gym.core.atomic import remove_stale_temps, write_text_atomic
from sfw_gym.core.errors import ConfigError

#: The checkpoint's file name in a run folder.
CHECKPOINT = "episodes.jsonl"


def load_checkpoint(path: Path) -> list[dict[str, Any]]:
    """The records of a JSONL checkpoint (an unreadable trailing line is ignored)."""
    if not path.exists():
        return []
    records = []
    for line in path.read_text(encoding="utf-8").splitlines():
        try:
            records.append(json.loads(line))
        except json.JSONDecodeError:
            continue
    return records


def save_checkpoint(path: Path, records: Iterable[dict[str, Any]]) -> None:
    """Rewrite the checkpoint with ``records`` (atomically)."""
    write_text_atomic(path, "".join(json.dumps(r) + "\n" for r in records))


def append_record(path: Path, record: dict[str, Any]) -> None:
    """One record onto the checkpoint, on disk before returning (O(1) per episode: a study of
    16,000 episodes must not rewrite the file each time). A line cut by a kill is dropped by
    :func:`load_checkpoint`, and :func:`open_checkpoint` rewrites the file clean before the next
    appends."""
    with path.open("a", encoding="utf-8") as fh:
        fh.write(json.dumps(record) + "\n")
        fh.flush()
        os.fsync(fh.fileno())


def open_checkpoint(out: Path) -> list[dict[str, Any]]:
    """The records already in ``out``'s checkpoint, after removing the temp files of a run
    killed mid-write and rewriting the checkpoint clean (no line cut by a kill before the next
    appends)."""
    out.mkdir(parents=True, exist_ok=True)
    remove_stale_temps(out)
    path = out / CHECKPOINT
    records = load_checkpoint(path)
    save_checkpoint(path, records)
    return records


def evaluation_manifest(
    out: Path,
    records: list[dict[str, Any]],
    agents: list[str],
    episodes: int,
    seed: int,
    env_id: str,
    floorplans: str | Path | None,
    env_kwargs: dict[str, Any] | None,
    agent_params: dict[str, dict[str, Any]] | None,
    routers: list[list[float]] | int | None = None,
) -> dict[str, Any]:
    """An evaluation's ``config.json``: what its episodes ran with. Resuming in a folder whose
    recorded episodes ran with another env, plans, routers, env kwargs or agent parameters is
    refused (their records would be reused as if they were this run's); more agents or episodes
    extend it."""
    given = json.loads(
        json.dumps(
            {
                "env_id": env_id,
                "floorplans": str(floorplans) if floorplans else None,
                "env_kwargs": env_kwargs or {},
                "routers": routers,
                "agent_params": {name: (agent_params or {}).get(name, {}) for name in agents},
            }
        )
    )
    path = out / "config.json"
    previous: dict[str, Any] = {}
    if records and path.is_file():
        try:
            previous = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, json.JSONDecodeError) as exc:
            raise ConfigError(
                f"{path}: unreadable run manifest ({exc}); use another --out"
            ) from None
    ran = {r["agent"] for r in records}
    for key in ("env_id", "floorplans", "routers", "env_kwargs"):
        if previous and previous.get(key) != given[key]:
            raise ConfigError(
                f"{out}: its {len(records)} recorded episodes ran with {key} "
                f"{previous.get(key)!r}, this run asks for {given[key]!r}; use another --out "
                f"(or delete {out / CHECKPOINT} to start over)"
            )
    before = previous.get("agent_params", {})
    for name in agents:
        if previous and name in ran and before.get(name, {}) != given["agent_params"][name]:
            raise ConfigError(
                f"{out}: its recorded {name!r} episodes ran with parameters "
                f"{before.get(name, {})!r}, this run asks for {given['agent_params'][name]!r}; "
                f"use another --out"
            )
    return {
        "agents": list(dict.fromkeys([*previous.get("agents", []), *agents])),
        "episodes": max(episodes, int(previous.get("episodes", 0))),
        "seed": seed,
        **given,
        "agent_params": {**before, **given["agent_params"]},
    }


def require_same_run(out: Path, run: dict[str, Any], what: str) -> None:
    """Resuming in ``out`` is allowed for the same run only (its checkpoint's records would
    otherwise count as this run's): ``OUT/run.json`` records ``run`` (JSON values), and a
    folder holding another is refused, naming the keys that differ."""
    path = out / "run.json"
    if path.is_file():
        previous = json.loads(path.read_text(encoding="utf-8"))
        if previous != run:
            changed = sorted(k for k in run if previous.get(k) != run[k])
            raise ConfigError(
                f"{out} holds another {what} run (different {', '.join(changed)}): "
                "choose another --out"
            )
    write_text_atomic(path, json.dumps(run, indent=1, sort_keys=True) + "\n")
