"""The map-context region policy and anchored fine-tuning, on a tiny fake ExploreRegions env."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces

torch = pytest.importorskip("torch")
sb3_contrib = pytest.importorskip("sb3_contrib")
from sfw_gym.rl.finetune import AnchoredMaskablePPO  # noqa: E402
from sfw_gym.rl.region_policy import RegionsPolicy  # noqa: E402

P, K, F, S = 36, 4, 10, 8


@pytest.fixture(autouse=True)
def _one_thread():
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(threads)


class FakeRegions(gym.Env):
    """Random observations with ExploreRegions' spaces; reward 1 for the valid candidate with
    the largest first feature. Episodes of 8 steps."""

    def __init__(self, privileged: bool = True) -> None:
        entries = {
            "map": spaces.Box(0, 255, (3, P, P), np.uint8),
            "local": spaces.Box(0, 255, (1, 48, 48), np.uint8),
            "state": spaces.Box(-1, 1, (S,), np.float32),
            "candidates": spaces.Box(-1, 4, (K, F), np.float32),
            "candidate_mask": spaces.Box(0, 1, (K,), np.int8),
            "candidate_px": spaces.Box(0, 1, (K, 2), np.float32),
        }
        if privileged:
            entries["true_map"] = spaces.Box(0, 255, (1, P, P), np.uint8)
        self.observation_space = spaces.Dict(entries)
        self.action_space = spaces.Discrete(K)
        self._mask = np.ones(K, dtype=bool)
        self._best, self._t = 0, 0

    def _obs(self) -> dict[str, np.ndarray]:
        obs = self.observation_space.sample()
        mask = self.np_random.random(K) < 0.7
        mask[self.np_random.integers(K)] = True
        obs["candidates"][~mask] = 0.0
        obs["candidate_px"][~mask] = 0.0
        obs["candidate_mask"] = mask.astype(np.int8)
        self._mask = mask
        self._best = int(np.argmax(np.where(mask, obs["candidates"][:, 0], -np.inf)))
        return obs

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.observation_space.seed(int(self.np_random.integers(2**31)))
        self._t = 0
        return self._obs(), {}

    def step(self, action):
        reward = float(action == self._best)
        self._t += 1
        return self._obs(), reward, False, self._t >= 8, {}

    def action_masks(self) -> np.ndarray:
        return self._mask.copy()


def batch_of(n: int = 6, seed: int = 0) -> dict[str, np.ndarray]:
    env = FakeRegions()
    observations = [env.reset(seed=seed)[0]] + [env.step(0)[0] for _ in range(n - 1)]
    return {k: np.stack([o[k] for o in observations]) for k in observations[0]}


def as_tensors(obs: dict[str, np.ndarray]) -> dict[str, torch.Tensor]:
    return {k: torch.as_tensor(v) for k, v in obs.items()}


def make_policy(**policy_kwargs) -> RegionsPolicy:
    torch.manual_seed(0)
    return RegionsPolicy(
        FakeRegions().observation_space, spaces.Discrete(K), lambda _: 3e-4, **policy_kwargs
    )


def make_model(algo=AnchoredMaskablePPO, learning_rate=1e-3, policy_kwargs=None, **kwargs):
    settings = {"n_steps": 16, "batch_size": 8, "n_epochs": 2, "seed": 0, "device": "cpu"}
    settings.update(kwargs)
    return algo(
        RegionsPolicy,
        FakeRegions(),
        learning_rate=learning_rate,
        policy_kwargs=policy_kwargs or {},
        **settings,
    )


def params_of(parameters) -> list[torch.Tensor]:
    return [p.detach().clone() for p in parameters]


def same(a: list[torch.Tensor], b: list[torch.Tensor]) -> bool:
    return len(a) == len(b) and all(torch.equal(x, y) for x, y in zip(a, b, strict=True))


def test_the_privileged_map_reaches_the_critic_only():
    policy = make_policy()
    assert "true_map" not in policy.actor_keys
    obs = batch_of()
    other = dict(obs, true_map=255 - obs["true_map"])
    mask = obs["candidate_mask"].astype(bool)
    with torch.no_grad():
        assert torch.equal(policy.actor_logits(obs), policy.actor_logits(other))
        probs = [
            policy.get_distribution(as_tensors(o), action_masks=mask).distribution.probs
            for o in (obs, other)
        ]
        assert torch.equal(*probs)
        values = [policy.predict_values(as_tensors(o)) for o in (obs, other)]
        assert not torch.allclose(*values)
        # the actor needs nothing but its own keys
        only_actor = {k: obs[k] for k in policy.actor_keys}
        assert torch.equal(policy.actor_logits(only_actor), policy.actor_logits(obs))
    unprivileged = make_policy(privileged_critic=False)
    with torch.no_grad():
        values = [unprivileged.predict_values(as_tensors(o)) for o in (obs, other)]
    assert torch.equal(*values)


@pytest.mark.parametrize("map_context", [True, False])
def test_the_map_at_a_candidate_moves_its_logit_only_with_map_context(map_context):
    policy = make_policy(map_context=map_context)
    obs = batch_of(1)
    obs["candidate_px"][0] = [[0.25, 0.25], [0.75, 0.75], [0.25, 0.75], [0.75, 0.25]]
    painted = {k: v.copy() for k, v in obs.items()}
    painted["map"][0, :, 4:14, 4:14] = 255 - painted["map"][0, :, 4:14, 4:14]  # at (9, 9)
    moved = {k: v.copy() for k, v in obs.items()}
    moved["candidate_px"][0, 0] = [0.75, 0.75]  # candidate 0 looks where candidate 1 is
    with torch.no_grad():
        logits, after_paint, after_move = (policy.actor_logits(o)[0] for o in (obs, painted, moved))
    if map_context:
        assert abs(float(after_paint[0] - logits[0])) > 1e-6
        assert abs(float(after_move[0] - logits[0])) > 1e-6
        assert torch.equal(after_move[1:], logits[1:])  # its map features are its own
    else:
        assert torch.equal(after_paint, logits) and torch.equal(after_move, logits)


def test_masked_candidates_get_no_probability():
    model = make_model(algo=sb3_contrib.MaskablePPO)
    obs = batch_of(8)
    mask = obs["candidate_mask"].astype(bool)
    assert not mask.all()
    dist = model.policy.get_distribution(as_tensors(obs), action_masks=mask)
    probs = dist.distribution.probs.detach().numpy()
    assert np.all(probs[~mask] == 0.0)
    np.testing.assert_allclose(probs.sum(1), 1.0, rtol=1e-5)
    for i in range(len(mask)):
        single = {k: v[i] for k, v in obs.items()}
        action, _ = model.predict(single, action_masks=mask[i])
        assert mask[i, int(action)]


@pytest.mark.parametrize("map_context", [True, False])
def test_the_value_loss_does_not_reach_the_actor(map_context):
    policy = make_policy(map_context=map_context)
    groups = policy.parameter_groups()
    actor, critic = ({id(p) for p in groups[g]} for g in ("actor", "critic"))
    assert actor and critic and not actor & critic
    assert actor | critic == {id(p) for p in policy.parameters()}
    policy.predict_values(as_tensors(batch_of())).sum().backward()
    assert all(p.grad is None or not p.grad.any() for p in groups["actor"])
    assert any(p.grad is not None and p.grad.abs().sum() > 0 for p in groups["critic"])


def test_the_critic_warms_up_alone_then_the_actor_learns():
    model = make_model(critic_warmup_updates=2, actor_warmup_updates=2)
    groups = model.policy.parameter_groups()
    actor0, critic0 = params_of(groups["actor"]), params_of(groups["critic"])
    model.learn(32)  # two rollouts of 16: two updates
    assert model.n_train_calls == 2
    assert same(params_of(groups["actor"]), actor0)
    assert not same(params_of(groups["critic"]), critic0)
    assert model.logger.name_to_value["train/actor_lr"] == 0.0
    assert model.actor_lr_scale() == 0.5  # the next update: half the rate
    model.learn(32, reset_num_timesteps=False)
    assert model.n_train_calls == 4 and model.n_updates == 4 * model.n_epochs
    assert not same(params_of(groups["actor"]), actor0)
    assert model.logger.name_to_value["train/actor_lr"] == pytest.approx(1e-3)
    assert model.logger.name_to_value["train/critic_lr"] == pytest.approx(1e-3)


def test_the_ramp_scales_the_actors_step():
    """An update at a quarter of the rate moves the actor a quarter as far as at the full rate
    (first Adam steps from the same state)."""
    steps = []
    for ramp in (4, 0):
        model = make_model(actor_warmup_updates=ramp, n_epochs=1, batch_size=16)
        actor = model.policy.parameter_groups()["actor"]
        before = params_of(actor)
        model.learn(16)
        steps.append(
            torch.cat([(a - b).flatten() for a, b in zip(params_of(actor), before, strict=True)])
        )
    assert model.logger.name_to_value["train/actor_lr"] == pytest.approx(1e-3)
    torch.testing.assert_close(steps[0], 0.25 * steps[1], rtol=1e-3, atol=1e-7)


def test_a_kl_coefficient_needs_an_anchor():
    model = make_model(kl_coef=1.0)
    with pytest.raises(ValueError, match="set_anchor"):
        model.learn(16)


def test_the_anchor_holds_the_policy_near_the_cloned_one():
    obs = batch_of(32, seed=5)
    mask = obs["candidate_mask"].astype(bool)
    kls = []
    for kl_coef in (0.0, 5.0):
        model = make_model(learning_rate=1e-2, kl_coef=kl_coef, kl_half_life_updates=1e9)
        model.set_anchor()
        anchor0 = params_of(model.anchor.parameters())
        model.learn(16 * 8)
        assert same(params_of(model.anchor.parameters()), anchor0)
        assert "train/kl_to_anchor" in model.logger.name_to_value
        kls.append(float(model.kl_to_anchor(obs, mask).mean()))
    assert kls[0] > 0.05  # the policy moved
    assert kls[1] < 0.2 * kls[0]


def test_the_anchor_run_once_per_rollout_trains_as_once_per_minibatch(monkeypatch):
    """The anchor's distribution kept per rollout sample gives the same update, bit for bit, as
    the anchor run on each minibatch (the policy's samples do not depend on their batch)."""
    trained = []
    for cached in (True, False):
        if not cached:
            monkeypatch.setattr(AnchoredMaskablePPO, "_cache_anchor_rows", lambda self: False)
        model = make_model(kl_coef=5.0, n_steps=24, batch_size=8, n_epochs=3)
        model.set_anchor()
        model.learn(48)
        assert set(model.rollout_buffer.observations) == set(FakeRegions().observation_space)
        trained.append(
            (params_of(model.policy.parameters()), model.logger.name_to_value["train/kl_to_anchor"])
        )
    assert trained[0][1] > 0  # the policy moved off its anchor
    assert same(trained[0][0], trained[1][0]) and trained[0][1] == trained[1][1]


def test_the_kl_weight_halves_every_half_life_after_the_critic_warm_up():
    model = make_model(critic_warmup_updates=3, kl_coef=2.0, kl_half_life_updates=4)
    assert model.kl_weight(0) == model.kl_weight(3) == 2.0
    assert model.kl_weight(7) == pytest.approx(1.0)
    assert model.kl_weight(11) == pytest.approx(0.5)


def test_save_and_load_keep_the_policy_the_anchor_and_the_warm_up(tmp_path):
    model = make_model(critic_warmup_updates=1, kl_coef=0.5)
    model.set_anchor()
    model.learn(48)
    path = tmp_path / "model.zip"
    model.save(path)
    obs = batch_of()
    loaded = AnchoredMaskablePPO.load(path, device="cpu")
    with torch.no_grad():
        logits = model.policy.actor_logits(obs)
        assert not torch.equal(logits, model.anchor.actor_logits(obs))  # it has learnt
        assert torch.equal(loaded.policy.actor_logits(obs), logits)
    assert loaded.anchor is not None
    assert same(params_of(loaded.anchor.parameters()), params_of(model.anchor.parameters()))
    assert all(not p.requires_grad for p in loaded.anchor.parameters())
    assert loaded.n_train_calls == 3 and loaded.n_updates == model.n_updates
    assert loaded.kl_coef == 0.5 and loaded.critic_warmup_updates == 1
    # the file is still a MaskablePPO model (for sfw_gym.rl.agent)
    plain = sb3_contrib.MaskablePPO.load(path, device="cpu")
    with torch.no_grad():
        assert torch.equal(plain.policy.actor_logits(obs), logits)


def test_regions_policy_trains_saves_and_loads_with_plain_maskable_ppo(tmp_path):
    model = make_model(algo=sb3_contrib.MaskablePPO, policy_kwargs={"hidden": 32})
    model.learn(32)
    model.save(tmp_path / "plain.zip")
    loaded = sb3_contrib.MaskablePPO.load(tmp_path / "plain.zip", device="cpu")
    assert isinstance(loaded.policy, RegionsPolicy) and loaded.policy.hidden == 32
    obs = batch_of()
    with torch.no_grad():
        assert torch.equal(loaded.policy.actor_logits(obs), model.policy.actor_logits(obs))
