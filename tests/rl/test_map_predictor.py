"""The learned map predictor (issue 46): it learns a family of plans whose continuation is
certain, its training resumes from its checkpoint, a bad folder is named, and the shipped
weights load from the package."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from sklearn.metrics import roc_auc_score

torch = pytest.importorskip("torch")

from sfw_gym.core.errors import ConfigError  # noqa: E402
from sfw_gym.navigation.prediction import (  # noqa: E402
    FREE,
    INPUT_CHANNELS,
    OUTSIDE,
    UNKNOWN,
    WALL,
)
from sfw_gym.rl.map_predictor import (  # noqa: E402
    DEFAULT_PREDICTOR_DIR,
    IGNORE,
    LearnedMapPredictor,
    MapPredictorNet,
    PredictorConfig,
    PredictorTraining,
    SnapshotSampler,
    export_checkpoint,
    predictor_loss,
    predictor_record,
    save_predictor,
    train_predictor,
)

H, W = 24, 48


def corridor(row: int, known_cols: int) -> tuple[np.ndarray, np.ndarray]:
    """A corridor along the map, rows ``row``..``row + 3`` free between two wall rows, outside
    elsewhere; the belief knows its first ``known_cols`` columns (walls and floor)."""
    truth = np.full((H, W), OUTSIDE, np.uint8)
    truth[row - 1] = truth[row + 4] = WALL
    truth[row : row + 4] = FREE
    codes = np.full((H, W), UNKNOWN, np.uint8)
    codes[row - 1 : row + 5, :known_cols] = truth[row - 1 : row + 5, :known_cols]
    return codes, truth


def corridor_episodes(rng: np.random.Generator, n: int) -> list[SimpleNamespace]:
    out = []
    for _ in range(n):
        row = int(rng.integers(3, H - 8))
        snaps = [corridor(row, int(k))[0] for k in rng.integers(6, 20, size=4)]
        truth = corridor(row, 0)[1]
        out.append(
            SimpleNamespace(
                codes=np.stack(snaps), truth=truth, proximity=np.zeros((H, W), np.float32)
            )
        )
    return out


@pytest.mark.slow
def test_the_predictor_learns_where_a_corridor_goes():
    """Corridors at random heights, seen up to a random column: the predictor must read the
    belief to say where the free space and the walls go on (no prior alone can)."""
    torch.manual_seed(0)
    rng = np.random.default_rng(0)
    sampler = SnapshotSampler(corridor_episodes(rng, 40), 48, rng)  # the whole map
    net = MapPredictorNet(PredictorConfig(width=8, heads=2))
    opt = torch.optim.Adam(net.parameters(), lr=2e-3)
    for _ in range(300):
        x, y = sampler.batch(8)
        xt, yt = torch.from_numpy(x), torch.from_numpy(y)
        loss = predictor_loss(net(xt), yt, xt, 0.1)
        opt.zero_grad()
        loss.backward()
        opt.step()
    predictor = LearnedMapPredictor.__new__(LearnedMapPredictor)
    predictor.net, predictor.threads = net.eval(), 1
    codes, truth = corridor(11, 10)  # a corridor at a row it may not have seen
    p = predictor.predict_codes(codes, np.zeros((H, W), np.float32))
    unseen = codes == UNKNOWN
    floor, walls = unseen & (truth == FREE), unseen & (truth == WALL)
    outside = unseen & (truth == OUTSIDE)
    # free space goes on where the corridor goes, walls beside it, nothing elsewhere
    assert p.p_free[floor].mean() > 0.6, p.p_free[floor].mean()
    assert p.p_wall[walls].mean() > 0.3, p.p_wall[walls].mean()
    assert p.p_free[outside].mean() < 0.1 and p.p_wall[outside].mean() < 0.1
    assert roc_auc_score(truth[unseen] == FREE, p.p_free[unseen]) > 0.95
    assert roc_auc_score(truth[unseen] == WALL, p.p_wall[unseen]) > 0.9
    assert 0.0 <= p.spread.min() and p.spread.max() <= 0.5


def test_training_checkpoints_and_resumes(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    from sfw_gym.evaluation.prediction import load_snapshots

    rng = np.random.default_rng(1)
    episodes = []
    for i, ep in enumerate(corridor_episodes(rng, 3)):
        f = tmp_path / f"ep{i}.npz"
        np.savez_compressed(
            f,
            codes=ep.codes,
            steps=np.arange(len(ep.codes)),
            truth=ep.truth,
            routers_xy=np.array([[1.0, 1.0]]),
            origin_xy=np.zeros(2),
            resolution_m=np.float64(0.1),
            agent=np.str_("frontier"),
            seed=np.int64(i),
            floorplan=np.str_(""),
        )
        episodes.append(load_snapshots(f))
    training = PredictorTraining(steps=4, batch=2, crop=24, threads=1)
    net_config = PredictorConfig(width=4, heads=2)
    out = tmp_path / "model"
    train_predictor(episodes, out, training, net_config, log_every=2, checkpoint_every=2)
    first = torch.load(out / "model.pt", weights_only=True)
    # resumed: a longer run continues from step 4 (the log goes on, nothing is redone)
    longer = PredictorTraining(steps=6, batch=2, crop=24, threads=1)
    batches = []
    draw = SnapshotSampler.batch
    monkeypatch.setattr(
        SnapshotSampler, "batch", lambda self, n: batches.append(n) or draw(self, n)
    )
    train_predictor(episodes, out, longer, net_config, log_every=2, checkpoint_every=2)
    assert len(batches) == 2  # steps 5 and 6 only
    steps = [int(line.split(",")[0]) for line in (out / "log.csv").read_text().splitlines()[1:]]
    assert steps == [2, 4, 6]
    assert not all(
        torch.equal(first[k], v) for k, v in torch.load(out / "model.pt", weights_only=True).items()
    )
    p = LearnedMapPredictor(out)
    assert p.net.config == net_config
    record = predictor_record(out)
    assert record["steps_done"] == 6 and record["episodes"] == 3
    assert 0 < record["unknown_prior"]["p_free"] < 1


def test_a_run_stopped_early_exports_its_checkpoint(tmp_path: Path):
    episodes = corridor_episodes(np.random.default_rng(2), 2)
    out = tmp_path / "model"
    planned = PredictorTraining(steps=4, batch=2, crop=24, threads=1)
    train_predictor(episodes, out, planned, PredictorConfig(4, 2), checkpoint_every=2)
    (out / "model.pt").unlink()
    checkpoint = torch.load(out / "checkpoint.pt", weights_only=False)
    checkpoint["step"] = 2  # as if stopped halfway through the 4 steps planned
    torch.save(checkpoint, out / "checkpoint.pt")
    export_checkpoint(episodes, out)
    record = predictor_record(out)
    assert record["steps_done"] == 2
    assert record["network"] == {"width": 4, "heads": 2} and record["training"]["steps"] == 4
    net = LearnedMapPredictor(out).net
    for name, value in net.state_dict().items():
        assert torch.equal(value, checkpoint["net"][name])
    with pytest.raises(ConfigError, match="no training checkpoint"):
        export_checkpoint(episodes, tmp_path / "nothing")


def test_a_folder_without_a_predictor_is_named(tmp_path: Path):
    with pytest.raises(ConfigError, match="not a map predictor"):
        LearnedMapPredictor(tmp_path)
    save_predictor(MapPredictorNet(PredictorConfig(4, 1)), tmp_path, PredictorTraining(), [])
    (tmp_path / "model.pt").write_bytes(b"garbage")
    with pytest.raises(ConfigError, match=str(tmp_path)):
        LearnedMapPredictor(tmp_path)


def test_the_shipped_predictor_loads_and_predicts_any_map_size():
    assert (DEFAULT_PREDICTOR_DIR / "model.pt").stat().st_size < 10 * 2**20
    p = LearnedMapPredictor()
    for shape in ((37, 53), (64, 64)):
        codes = np.full(shape, UNKNOWN, np.uint8)
        codes[10:20, 10:20] = FREE
        m = p.predict_codes(codes, np.zeros(shape, np.float32))
        assert m.p_free.shape == shape
        assert np.all(m.p_free[10:20, 10:20] == 1.0)
        assert np.all((m.p_free >= 0) & (m.p_free + m.p_wall <= 1.0 + 1e-5))


def loss_case(correct_on_unknown: bool, wrong_on_known: bool, margin: float = 20.0):
    """2 x 3 cells, 2 heads: the left column unknown, the rest known; one unknown cell IGNOREd
    (padding)."""
    labels = torch.tensor([[[FREE, WALL, OUTSIDE], [IGNORE, WALL, FREE]]])
    inputs = torch.zeros(1, len(INPUT_CHANNELS), 2, 3)
    inputs[0, INPUT_CHANNELS.index("unknown"), :, 0] = 1.0
    logits = torch.zeros(1, 2, 3, 2, 3)
    for r in range(2):
        for c in range(3):
            true = int(labels[0, r, c]) if labels[0, r, c] != IGNORE else FREE
            unknown = c == 0
            right = (unknown and correct_on_unknown) or (not unknown and not wrong_on_known)
            cls = true if right else (true + 1) % 3
            logits[0, :, cls, r, c] = margin
    return logits, labels, inputs


def test_predictor_loss_is_a_weighted_cross_entropy_by_its_limits():
    """Uniform logits give ln 3 whatever the weights; known cells weigh ``known_weight`` (0: a
    wrong guess there costs nothing); an IGNOREd cell never counts."""
    torch.manual_seed(0)
    logits, labels, inputs = loss_case(True, True)
    uniform = torch.zeros_like(logits)
    assert float(predictor_loss(uniform, labels, inputs, 0.1)) == pytest.approx(np.log(3), rel=1e-6)
    assert float(predictor_loss(logits, labels, inputs, 0.0)) < 1e-6  # only the right ones count
    wrong_known = float(predictor_loss(logits, labels, inputs, 1.0))
    assert wrong_known > 5.0  # a wrong guess by 20 nats on known cells, now weighed in
    ignored = logits.clone()
    ignored[0, :, :, 1, 0] = torch.tensor([-50.0, 50.0, 0.0])  # wrong for any label: IGNOREd
    assert float(predictor_loss(ignored, labels, inputs, 0.0)) < 1e-6


class CellwiseNet(torch.nn.Module):
    """A stand-in for the network: per cell, head ``k`` gives the logits
    ``((k + 1) · proximity, 0, 0)`` (free, wall, outside), so that a cell's output is its own
    input's; it keeps the input it was given."""

    heads = 2

    def forward(self, x):
        self.seen = x.clone()
        prox = x[:, INPUT_CHANNELS.index("router_proximity")]
        logits = torch.zeros(x.shape[0], self.heads, 3, *x.shape[2:])
        for k in range(self.heads):
            logits[:, k, 0] = (k + 1) * prox
        return logits


@pytest.mark.parametrize("shape", [(11, 19), (16, 24)])
def test_the_prediction_is_the_heads_softmax_cell_by_cell_with_the_padding_cut_off(shape):
    """An 11 x 19 map is padded to 16 x 24 (multiples of 8, zeros at the bottom and right); a
    16 x 24 map is not. With proximity ``ln m`` at a cell, head 0 gives ``(m, 1, 1) / (m + 2)``
    and head 1 ``(m², 1, 1) / (m² + 2)``: ``p_free`` and ``p_wall`` are the two heads' means,
    ``spread`` half the difference of their ``p_free`` (the standard deviation of two). Each
    cell has its own m, so a shifted or transposed crop would not match."""
    h, w = shape
    m = 1.0 + np.arange(h * w, dtype=np.float64).reshape(h, w) / 50.0
    codes = np.full(shape, UNKNOWN, np.uint8)
    predictor = LearnedMapPredictor.__new__(LearnedMapPredictor)
    predictor.net, predictor.threads = CellwiseNet(), 1
    p = predictor.predict_codes(codes, np.log(m).astype(np.float32))
    free0, free1 = m / (m + 2), m**2 / (m**2 + 2)
    wall0, wall1 = 1 / (m + 2), 1 / (m**2 + 2)
    np.testing.assert_allclose(p.p_free, (free0 + free1) / 2, rtol=1e-5)
    np.testing.assert_allclose(p.p_wall, (wall0 + wall1) / 2, rtol=1e-5)
    np.testing.assert_allclose(p.spread, np.abs(free1 - free0) / 2, rtol=1e-4, atol=1e-7)
    seen = predictor.net.seen[0].numpy()
    assert seen.shape[1:] == (16, 24)  # the next multiples of 8
    inside = seen[INPUT_CHANNELS.index("inside")]
    assert inside[:h, :w].all() and not seen[:, h:].any() and not seen[:, :, w:].any()
