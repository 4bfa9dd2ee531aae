"""Map prediction's data and its judge: (belief snapshot, true plan) pairs taken along episodes
on the native vector env, and the quality of a predicted map on the cells still unknown.

Snapshots go to one ``.npz`` per episode (:func:`collect_snapshots`), holding ``codes``
``(S, H, W)`` (:meth:`~sfw_gym.navigation.prediction.PredictorInputs.codes`), ``steps`` ``(S,)``,
``truth`` ``(H, W)`` (:func:`~sfw_gym.navigation.prediction.truth_class`), ``routers_xy``,
``origin_xy`` and ``resolution_m``, and the ``agent``, ``seed`` and ``floorplan`` that made them.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, cast

import gymnasium as gym
import numpy as np
from sklearn.metrics import roc_auc_score

from sfw_gym.core.atomic import atomic_path
from sfw_gym.core.errors import ConfigError
from sfw_gym.envs.explore import unwrap_sfw
from sfw_gym.evaluation.vector import check_native_vector_env, reset_sub_env
from sfw_gym.mapping.grid import GridSpec
from sfw_gym.navigation.prediction import (
    FREE,
    UNKNOWN,
    WALL,
    MapPredictor,
    PredictedMap,
    PredictorInputs,
    router_proximity,
    truth_class,
)


@dataclass(frozen=True)
class SnapshotEpisode:
    """One episode to take snapshots of.

    Attributes:
        agent: A registered agent name.
        seed: The env's reset seed (and the agent's).
        steps: The steps after which a snapshot is taken (the episode ends after the last; one
            that ends sooner gives its last state once, with the step it ended at).
        floorplan: A plan file instead of the generator (None: the seed's generated plan).
    """

    agent: str
    seed: int
    steps: tuple[int, ...]
    floorplan: str | None = None

    @property
    def name(self) -> str:
        plan = Path(self.floorplan).stem if self.floorplan else "gen"
        return f"{self.agent}_{plan}_{self.seed}.npz"


def collect_snapshots(
    episodes: Sequence[SnapshotEpisode],
    out: str | Path,
    *,
    env_id: str = "SfW-Explore-v0",
    num_envs: int = 8,
    progress: Callable[[int], None] | None = None,
) -> list[Path]:
    """Run ``episodes`` on ``num_envs`` native sub-envs and write each one's snapshots to
    ``out/<agent>_<plan>_<seed>.npz`` (atomically; episodes already written are skipped, so an
    interrupted collection resumes). Returns the files, in ``episodes``' order."""
    from sfw_gym.agents import make_agent

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    todo = [e for e in episodes if not (out / e.name).exists()]
    if todo:
        check_native_vector_env(env_id)
        n = min(num_envs, len(todo))
        vec = cast(Any, gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point"))
        try:
            _run(vec, n, list(todo), out, make_agent, progress)
        finally:
            vec.close()
    return [out / e.name for e in episodes]


def _run(vec: Any, n: int, queue: list[SnapshotEpisode], out: Path, make_agent, progress) -> None:
    """Each sub-env takes the next episode when its last one is done."""
    slots: list[dict[str, Any] | None] = [None] * n
    still = np.zeros(vec.single_action_space.shape, vec.single_action_space.dtype)

    def start(i: int) -> None:
        slots[i] = None
        if not queue:
            return
        ep = queue.pop(0)
        plan = {"floorplan": ep.floorplan} if ep.floorplan else None
        obs, _ = reset_sub_env(vec, i, ep.seed, plan)
        agent = make_agent(ep.agent)
        agent.reset(vec.envs[i], seed=ep.seed)
        view = unwrap_sfw(vec.envs[i]).robot_view()
        slots[i] = {
            "ep": ep,
            "agent": agent,
            "obs": {k: v[i] for k, v in obs.items()},
            "inputs": PredictorInputs(view),
            "codes": [],
            "taken": [],
            "step": 0,
        }

    for i in range(n):
        start(i)
    while any(slots):
        vec.envs  # noqa: B018 (writes the batched state back into the sub-envs: their views)
        actions = [still if s is None else s["agent"].act(s["obs"]) for s in slots]
        obs, _, terminated, truncated, _ = vec.step(np.stack(actions))
        vec.envs  # noqa: B018
        for i, slot in enumerate(slots):
            if slot is None:
                continue
            slot["step"] += 1
            slot["obs"] = {k: v[i] for k, v in obs.items()}
            ep: SnapshotEpisode = slot["ep"]
            sfw = unwrap_sfw(vec.envs[i])
            ended = bool(terminated[i] or truncated[i])
            if slot["step"] in ep.steps or (ended and len(slot["codes"]) < len(ep.steps)):
                slot["codes"].append(slot["inputs"].codes(sfw.robot_view()))
                slot["taken"].append(slot["step"])
            if ended or len(slot["codes"]) == len(ep.steps):
                _write_episode(out / ep.name, ep, slot, sfw)
                if progress:
                    progress(1)
                start(i)


def _write_episode(path: Path, ep: SnapshotEpisode, slot: dict[str, Any], sfw: Any) -> None:
    truth, view = sfw.ground_truth(), sfw.robot_view()
    with atomic_path(path) as tmp:
        np.savez_compressed(
            tmp,
            codes=np.stack(slot["codes"]),
            steps=np.array(slot["taken"], np.int64),
            truth=truth_class(truth.truth_u8),
            routers_xy=np.asarray(view.routers_xy, np.float64),
            origin_xy=np.asarray(view.grid.origin_xy, np.float64),
            resolution_m=np.float64(view.grid.resolution_m),
            agent=np.str_(ep.agent),
            seed=np.int64(ep.seed),
            floorplan=np.str_(ep.floorplan or ""),
        )


@dataclass(frozen=True)
class Snapshots:
    """One episode's snapshots, loaded (:func:`load_snapshots`)."""

    codes: np.ndarray
    steps: np.ndarray
    truth: np.ndarray
    proximity: np.ndarray
    agent: str
    seed: int


def load_snapshots(path: str | Path) -> Snapshots:
    """An episode file of :func:`collect_snapshots`."""
    try:
        with np.load(path) as z:
            grid = GridSpec(
                tuple(z["origin_xy"].tolist()), float(z["resolution_m"]), z["truth"].shape
            )
            return Snapshots(
                z["codes"],
                z["steps"],
                z["truth"],
                router_proximity(grid, z["routers_xy"]),
                str(z["agent"]),
                int(z["seed"]),
            )
    except (OSError, KeyError, ValueError) as exc:
        raise ConfigError(f"{path}: not a snapshot file of collect_snapshots ({exc})") from None


#: The figures of :func:`prediction_quality`, in a table's order.
QUALITY_METRICS = ("free_iou", "wall_f1", "free_auroc", "wall_auroc")


def prediction_quality(
    predicted: Sequence[PredictedMap], codes: Sequence[np.ndarray], truths: Sequence[np.ndarray]
) -> dict[str, float]:
    """Free IoU, wall F1 and the AUROC of ``p_free`` (truly free) and ``p_wall`` (truly a wall),
    pooled over the cells still unknown in each snapshot (``codes``) against its true classes.
    A cell is called free or wall by the largest of ``p_free``, ``p_wall`` and the rest
    (outside)."""
    pf, pw, tc = [], [], []
    for p, c, t in zip(predicted, codes, truths, strict=True):
        unknown = (c & 3) == UNKNOWN
        pf.append(p.p_free[unknown])
        pw.append(p.p_wall[unknown])
        tc.append(t[unknown])
    p_free, p_wall, truth = np.concatenate(pf), np.concatenate(pw), np.concatenate(tc)
    call = np.argmax(np.stack([p_free, p_wall, 1.0 - p_free - p_wall]), axis=0)
    free_call, wall_call = call == FREE, call == WALL
    true_free, true_wall = truth == FREE, truth == WALL
    union = np.count_nonzero(free_call | true_free)
    tp_wall = np.count_nonzero(wall_call & true_wall)
    denom = np.count_nonzero(wall_call) + np.count_nonzero(true_wall)
    return {
        "free_iou": np.count_nonzero(free_call & true_free) / union if union else float("nan"),
        "wall_f1": 2 * tp_wall / denom if denom else float("nan"),
        "free_auroc": _auroc(true_free, p_free),
        "wall_auroc": _auroc(true_wall, p_wall),
    }


def _auroc(labels: np.ndarray, scores: np.ndarray) -> float:
    if labels.all() or not labels.any():
        return float("nan")
    return float(roc_auc_score(labels, scores))


def predict_snapshots(predictor: MapPredictor, snaps: Snapshots) -> list[PredictedMap]:
    """``predictor``'s map for each of an episode's snapshots."""
    return [predictor.predict_codes(c, snaps.proximity) for c in snaps.codes]
