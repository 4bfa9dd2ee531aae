"""The learned map predictor: a small U-Net that reads the robot's belief, trajectory and
routers and predicts, for every cell, the probability that it is free, a wall or outside.

It is trained supervised on (belief snapshot, true plan) pairs
(:func:`~sfw_gym.evaluation.prediction.collect_snapshots`, :func:`train_predictor`) and shipped
in the package (``sfw_gym/data/agents/predictor/``). Its uncertainty is an ensemble of output
heads on one trunk, each trained on its own bootstrap of the cells (MapEx's ensemble, at the
cost of one network): ``spread`` is the heads' standard deviation of ``p_free``. The network is
fully convolutional, so it reads a map of any size (padded to a multiple of 8).
"""

from __future__ import annotations

import json
import pickle
import time
from collections import Counter
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn
from torch.nn import functional as F

from sfw_gym.core.atomic import atomic_path, write_text_atomic
from sfw_gym.core.data import DEFAULT_PREDICTOR_DIR
from sfw_gym.core.errors import ConfigError
from sfw_gym.navigation.prediction import (
    INPUT_CHANNELS,
    OUTSIDE,
    UNKNOWN,
    PredictedMap,
    input_channels,
)

#: The network sees maps padded to a multiple of this (three halvings).
PAD_TO = 8
#: The label of cells outside the map (padding): no loss.
IGNORE = 255


@dataclass(frozen=True)
class PredictorConfig:
    """The network's shape.

    Attributes:
        width: Channels at full resolution (doubled at 1/2, quadrupled at 1/4 and 1/8).
        heads: Ensemble heads (each three logits per cell: free, wall, outside).
    """

    width: int = 12
    heads: int = 4


def _conv(cin: int, cout: int, stride: int = 1, dilation: int = 1) -> nn.Sequential:
    return nn.Sequential(
        nn.Conv2d(cin, cout, 3, stride, padding=dilation, dilation=dilation, bias=False),
        nn.BatchNorm2d(cout),
        nn.ReLU(inplace=True),
    )


class MapPredictorNet(nn.Module):
    """A U-Net over (1, 1/2, 1/4, 1/8) resolutions; dilated convolutions at 1/8 see about 10 m."""

    def __init__(self, config: PredictorConfig = PredictorConfig()) -> None:
        super().__init__()
        w, c = config.width, len(INPUT_CHANNELS)
        self.config = config
        self.enc0 = _conv(c, w)
        self.enc1 = nn.Sequential(_conv(w, 2 * w, 2), _conv(2 * w, 2 * w))
        self.enc2 = nn.Sequential(_conv(2 * w, 4 * w, 2), _conv(4 * w, 4 * w))
        self.enc3 = nn.Sequential(
            _conv(4 * w, 4 * w, 2), _conv(4 * w, 4 * w, dilation=2), _conv(4 * w, 4 * w, dilation=4)
        )
        self.dec2 = _conv(8 * w, 4 * w)
        self.dec1 = _conv(6 * w, 2 * w)
        self.dec0 = nn.Sequential(  # a 1x1 mix at full resolution: the cost is per cell
            nn.Conv2d(3 * w, w, 1, bias=False), nn.BatchNorm2d(w), nn.ReLU(inplace=True)
        )
        self.head = nn.Conv2d(w, 3 * config.heads, 1)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        """Logits ``(B, heads, 3, H, W)`` of inputs ``(B, C, H, W)`` (H, W multiples of 8)."""
        e0 = self.enc0(x)
        e1 = self.enc1(e0)
        e2 = self.enc2(e1)
        e3 = self.enc3(e2)
        d2 = self.dec2(torch.cat([F.interpolate(e3, scale_factor=2.0), e2], 1))
        d1 = self.dec1(torch.cat([F.interpolate(d2, scale_factor=2.0), e1], 1))
        d0 = self.dec0(torch.cat([F.interpolate(d1, scale_factor=2.0), e0], 1))
        b, _, h, w = x.shape
        return self.head(d0).view(b, self.config.heads, 3, h, w)


def _padded(x: np.ndarray) -> tuple[np.ndarray, int, int]:
    """``x`` ``(C, H, W)`` zero-padded at the bottom and right to multiples of :data:`PAD_TO`."""
    _, h, w = x.shape
    ph, pw = -h % PAD_TO, -w % PAD_TO
    return np.pad(x, ((0, 0), (0, ph), (0, pw))), h, w


class LearnedMapPredictor:
    """The trained predictor behind :class:`~sfw_gym.navigation.prediction.MapPredictor`.

    Args:
        path: A folder with ``model.pt`` and ``config.json`` (default: the shipped one).
        threads: Torch threads for inference (one by default: agents run one per process).
    """

    def __init__(self, path: str | Path | None = None, threads: int = 1) -> None:
        folder = Path(path) if path else DEFAULT_PREDICTOR_DIR
        self.path = folder
        self.net = load_predictor_net(folder)
        self.net.eval()
        self.threads = threads

    def predict_codes(self, codes: np.ndarray, proximity: np.ndarray) -> PredictedMap:
        """The predicted map for belief ``codes`` (the believed cells keep their belief)."""
        x, h, w = _padded(input_channels(codes, proximity))
        previous = torch.get_num_threads()
        torch.set_num_threads(self.threads)
        try:
            with torch.inference_mode():
                probs = torch.softmax(self.net(torch.from_numpy(x)[None]), dim=2)[0]
        finally:
            torch.set_num_threads(previous)
        p = probs[..., :h, :w].numpy()  # (heads, 3, H, W)
        mean = p.mean(axis=0)
        return PredictedMap.with_belief(codes, mean[0], mean[1], p[:, 0].std(axis=0))


def load_predictor_net(folder: str | Path) -> MapPredictorNet:
    """The network saved in ``folder`` (``config.json`` and ``model.pt``, weights only)."""
    folder = Path(folder)
    try:
        config = PredictorConfig(**json.loads((folder / "config.json").read_text())["network"])
        with torch.random.fork_rng(devices=[]):  # the initial weights, replaced: no global draw
            net = MapPredictorNet(config)
        net.load_state_dict(torch.load(folder / "model.pt", map_location="cpu", weights_only=True))
    except (OSError, KeyError, TypeError, ValueError, RuntimeError, pickle.UnpicklingError) as exc:
        reason = str(exc).splitlines()[0]
        raise ConfigError(
            f"{folder}: not a map predictor (config.json + model.pt): {reason}"
        ) from None
    return net


# ------------------------------------------------------------------------------------ training
@dataclass(frozen=True)
class PredictorTraining:
    """How :func:`train_predictor` trains.

    Attributes:
        steps: Gradient steps.
        batch: Crops per step.
        crop: Crop side (cells; a multiple of 8).
        lr: Adam's learning rate (cosine decay to a tenth).
        known_weight: Loss weight of the cells the belief already knows (the unknown ones
            weigh 1: they are what the predictor is for).
        seed: Seeds the crops, the bootstrap and the initial weights.
        threads: Torch threads.
    """

    steps: int = 20_000
    batch: int = 32
    crop: int = 80
    lr: float = 2e-3
    known_weight: float = 0.1
    seed: int = 0
    threads: int = 2


class SnapshotSampler:
    """Random crops of (input channels, true classes) from loaded episodes, rotated and mirrored
    (the plans' statistics do not depend on the map's orientation)."""

    def __init__(self, episodes: list[Any], crop: int, rng: np.random.Generator) -> None:
        if not episodes:
            raise ConfigError("no snapshot episodes to train on")
        self.episodes, self.crop, self.rng = episodes, crop, rng
        sizes = np.array([len(e.codes) for e in episodes], np.float64)
        self.p = sizes / sizes.sum()

    def batch(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """``n`` crops: inputs ``(n, C, crop, crop)`` float32, labels ``(n, crop, crop)`` int64
        (:data:`IGNORE` beyond the map)."""
        xs, ys = [], []
        for e in self.rng.choice(len(self.episodes), n, p=self.p):
            ep = self.episodes[e]
            codes = ep.codes[self.rng.integers(len(ep.codes))]
            codes, proximity, y = self._crop(codes, ep.proximity, ep.truth)
            x = input_channels(codes, proximity)
            x[:, y == IGNORE] = 0.0  # beyond the map: nothing, as in a padded map
            k = int(self.rng.integers(4))
            x, y = np.rot90(x, k, (1, 2)), np.rot90(y, k)
            if self.rng.random() < 0.5:
                x, y = x[:, :, ::-1], y[:, ::-1]
            xs.append(np.ascontiguousarray(x))
            ys.append(np.ascontiguousarray(y))
        return np.stack(xs), np.stack(ys).astype(np.int64)

    def _crop(self, *maps: np.ndarray) -> list[np.ndarray]:
        """The same random ``crop`` x ``crop`` window of each map (padded where smaller; the
        last, the truth, with :data:`IGNORE`)."""
        s = self.crop
        h, w = maps[0].shape
        ph, pw = max(s - h, 0), max(s - w, 0)
        r = int(self.rng.integers(h + ph - s + 1))
        c = int(self.rng.integers(w + pw - s + 1))
        out = []
        for i, m in enumerate(maps):
            fill = IGNORE if i == len(maps) - 1 else 0
            m = np.pad(m, ((0, ph), (0, pw)), constant_values=fill)
            out.append(m[r : r + s, c : c + s])
        return out


def predictor_loss(
    logits: torch.Tensor,
    labels: torch.Tensor,
    inputs: torch.Tensor,
    known_weight: float,
) -> torch.Tensor:
    """Cross-entropy of every head, each cell weighted by a Poisson(1) bootstrap draw per head
    (the ensemble's diversity), by ``known_weight`` where the belief knows it, 0 beyond the map."""
    b, heads, _, h, w = logits.shape
    unknown = inputs[:, INPUT_CHANNELS.index("unknown")]
    weight = torch.where(unknown > 0, 1.0, known_weight) * (labels != IGNORE)
    boot = torch.poisson(torch.ones(b, heads, h, w))
    target = labels.clamp(max=OUTSIDE)[:, None].expand(b, heads, h, w)
    ce = F.cross_entropy(logits.permute(0, 2, 1, 3, 4), target, reduction="none")
    w_all = boot * weight[:, None]
    return (ce * w_all).sum() / w_all.sum().clamp(min=1.0)


def train_predictor(
    episodes: list[Any],
    out: str | Path,
    training: PredictorTraining = PredictorTraining(),
    network: PredictorConfig = PredictorConfig(),
    log_every: int = 200,
    checkpoint_every: int = 1000,
) -> Path:
    """Train a predictor on ``episodes`` (each with ``codes``, ``truth`` and ``proximity``: a
    :class:`~sfw_gym.evaluation.prediction.Snapshots`) into ``out`` (``model.pt``, ``config.json``,
    ``log.csv``). Checkpoints atomically every ``checkpoint_every`` steps
    (``checkpoint.pt``) and resumes from it when run again with the same ``out``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    torch.set_num_threads(training.threads)
    torch.manual_seed(training.seed)
    net = MapPredictorNet(network)
    opt = torch.optim.Adam(net.parameters(), lr=training.lr)
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, training.steps, training.lr / 10)
    start, spent = 0, 0.0
    ckpt = out / "checkpoint.pt"
    rng = np.random.default_rng(training.seed)
    if ckpt.exists():
        state = torch.load(ckpt, map_location="cpu", weights_only=False)
        net.load_state_dict(state["net"])
        opt.load_state_dict(state["opt"])
        sched.load_state_dict(state["sched"])
        rng.bit_generator.state = state["rng"]
        torch.set_rng_state(state["torch_rng"])
        start = int(state["step"])
        spent = float(state.get("seconds", 0.0))
    sampler = SnapshotSampler(list(episodes), training.crop, rng)
    log = out / "log.csv"
    if start == 0:
        log.write_text("step,loss,seconds\n")
    began = time.perf_counter()
    net.train()
    running = 0.0
    for step in range(start, training.steps):
        x, y = sampler.batch(training.batch)
        xt, yt = torch.from_numpy(x), torch.from_numpy(y)
        loss = predictor_loss(net(xt), yt, xt, training.known_weight)
        opt.zero_grad()
        loss.backward()
        opt.step()
        sched.step()
        running += loss.item()
        done = step + 1
        if done % log_every == 0:
            with log.open("a") as fh:
                seconds = spent + time.perf_counter() - began
                fh.write(f"{done},{running / log_every:.5f},{seconds:.1f}\n")
            running = 0.0
        if done % checkpoint_every == 0 or done == training.steps:
            with atomic_path(ckpt) as tmp:
                torch.save(
                    {
                        "net": net.state_dict(),
                        "opt": opt.state_dict(),
                        "sched": sched.state_dict(),
                        "rng": rng.bit_generator.state,
                        "torch_rng": torch.get_rng_state(),
                        "step": done,
                        "seconds": spent + time.perf_counter() - began,
                        "training": asdict(training),
                        "network": asdict(network),
                    },
                    tmp,
                )
    save_predictor(net, out, training, sampler.episodes, spent + time.perf_counter() - began)
    return out


def export_checkpoint(
    episodes: list[Any],
    out: str | Path,
    training: PredictorTraining = PredictorTraining(),
    network: PredictorConfig = PredictorConfig(),
) -> Path:
    """Write ``out``'s latest checkpoint as a predictor (``model.pt``, ``config.json``): a run
    stopped before its last step still gives a model. ``episodes`` are those it trained on;
    ``training`` and ``network`` are the run's, where its checkpoint does not record them."""
    out = Path(out)
    try:
        state = torch.load(out / "checkpoint.pt", map_location="cpu", weights_only=False)
        training = PredictorTraining(**state.get("training", asdict(training)))
        network = PredictorConfig(**state.get("network", asdict(network)))
    except (OSError, KeyError, TypeError, RuntimeError, pickle.UnpicklingError) as exc:
        raise ConfigError(f"{out}: no training checkpoint to export ({exc})") from None
    with torch.random.fork_rng(devices=[]):
        net = MapPredictorNet(network)
    net.load_state_dict(state["net"])
    save_predictor(net, out, training, episodes, float(state["seconds"]), int(state["step"]))
    return out


def unknown_prior(episodes: list[Any], every: int = 10) -> dict[str, float]:
    """The share of the cells still unknown that are truly free and truly a wall, over every
    ``every``-th snapshot of ``episodes``: the free-prior baseline's probabilities."""
    counts = np.zeros(3)
    for ep in episodes:
        unknown = (ep.codes[::every] & 3) == UNKNOWN
        counts += np.bincount(np.broadcast_to(ep.truth, unknown.shape)[unknown], minlength=3)[:3]
    total = max(counts.sum(), 1.0)
    return {"p_free": counts[0] / total, "p_wall": counts[1] / total}


def save_predictor(
    net: MapPredictorNet,
    out: Path,
    training: PredictorTraining,
    episodes: list[Any],
    seconds: float = float("nan"),
    steps_done: int | None = None,
) -> None:
    """``model.pt`` (the weights) and ``config.json`` (the network's shape, how it was trained,
    how long and how many of its steps were done, on what, and the unknown cells' class
    shares), each written atomically."""
    with atomic_path(out / "model.pt") as tmp:
        torch.save(net.state_dict(), tmp)
    record = {
        "network": asdict(net.config),
        "training": asdict(training),
        "training_seconds": round(seconds, 1),
        "steps_done": training.steps if steps_done is None else steps_done,
        "episodes": len(episodes),
        "snapshots": sum(len(e.codes) for e in episodes),
        "agents": dict(Counter(getattr(e, "agent", "?") for e in episodes)),
        "unknown_prior": unknown_prior(episodes) if episodes else {},
        "parameters": sum(p.numel() for p in net.parameters()),
        "inputs": list(INPUT_CHANNELS),
    }
    write_text_atomic(out / "config.json", json.dumps(record, indent=2) + "\n")


def predictor_record(folder: str | Path | None = None) -> dict[str, Any]:
    """The ``config.json`` of a predictor's folder (default: the shipped one)."""
    return json.loads((Path(folder or DEFAULT_PREDICTOR_DIR) / "config.json").read_text())
