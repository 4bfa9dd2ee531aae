"""The learned region explorer: trained by cloning then anchored fine-tuning, and acting on the
explore env exactly as in its training env."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import yaml

import sfw_gym  # noqa: F401  (registration)
from tests.envs.test_regions import SMALL

sb3_contrib = pytest.importorskip("sb3_contrib")
torch = pytest.importorskip("torch")
from sfw_gym.core.errors import ConfigError  # noqa: E402
from sfw_gym.rl.agent import RegionsPPOAgent  # noqa: E402
from sfw_gym.rl.finetune import AnchoredMaskablePPO  # noqa: E402
from sfw_gym.rl.region_policy import RegionsPolicy  # noqa: E402
from sfw_gym.rl.training import _copy_clone, latest_checkpoint, train_ppo  # noqa: E402

YAML = """
SfW-ExploreRegions-v0:
  policy: 'sfw_gym.rl.region_policy.RegionsPolicy'
  n_envs: 1
  env_kwargs:
    privileged: true
  n_steps: 16
  batch_size: 16
  n_epochs: 2
sfw_gym:
  SfW-ExploreRegions-v0:
    behaviour_cloning:
      episodes: 3
      epochs: 20
    fine_tuning:
      critic_warmup_updates: 1
      actor_warmup_updates: 2
      kl_coef: 0.5
      kl_half_life_updates: 2
"""


def test_the_agent_drives_the_explore_env_as_the_regions_env_does(tmp_path):
    env = gym.make("SfW-ExploreRegions-v0", **SMALL)
    model = sb3_contrib.MaskablePPO(RegionsPolicy, env, n_steps=16, batch_size=16, seed=3)
    model.save(tmp_path / "model.zip")
    obs, _ = env.reset(seed=4)
    for _ in range(6):
        action, _ = model.predict(
            obs, action_masks=env.unwrapped.action_masks(), deterministic=True
        )
        obs, _, _, _, info = env.step(int(action))
    steps, pose = env.unwrapped.explore.steps, info["true_pose"]
    agent = RegionsPPOAgent(tmp_path)
    explore = gym.make("SfW-Explore-v0", **SMALL)
    obs, _ = explore.reset(seed=4)
    agent.reset(explore, seed=0)
    for _ in range(steps):
        obs, _, _, _, info = explore.step(agent.act(obs))
    assert agent.n_decisions == 6 and steps == 6 * 20
    np.testing.assert_array_equal(info["true_pose"], pose)


@pytest.mark.slow
def test_cloning_then_anchored_fine_tuning_keeps_the_teacher_and_resumes(tmp_path):
    """ppo_mask with a fine_tuning block: the actor is cloned from the teacher first (it agrees
    with explore_lite's choices on a held-out episode), the anchor is that clone, and a resumed
    run continues the warm-up schedule where it stopped."""
    yml = tmp_path / "ppo_mask.yml"
    yml.write_text(YAML)
    out = tmp_path / "run"
    kwargs = dict(env_kwargs=SMALL, hyperparams_path=yml, algo="ppo_mask", progress_bar=False)
    train_ppo("SfW-ExploreRegions-v0", 32, out, checkpoint_every=16, **kwargs)
    model = AnchoredMaskablePPO.load(latest_checkpoint(out, "ppo_mask")[0])
    assert model.anchor is not None and model.n_train_calls == 2
    (fit,) = yaml.safe_load((out / "behaviour_cloning.yml").read_text())
    assert fit["decisions"] == 3 * 15 and fit["teacher_agreement"] > 0.5

    env = gym.make("SfW-ExploreRegions-v0", privileged=True, **SMALL)
    obs, _ = env.reset(seed=10_000)
    agree, done = [], False
    while not done:
        mask = env.unwrapped.action_masks()
        x = {k: torch.as_tensor(obs[k])[None] for k in RegionsPolicy.actor_keys}
        with torch.no_grad():
            logits = model.anchor.actor_logits(x)[0].numpy()
        teacher = env.unwrapped.teacher_action()
        agree.append(int(np.argmax(np.where(mask, logits, -np.inf))) == teacher)
        obs, _, terminated, truncated, _ = env.step(teacher)
        done = terminated or truncated
    assert np.mean(agree) > 0.5  # uniform choice among ~10 valid candidates: ~0.1

    # a fine-tuning variant starts from the same clone (behaviour_cloning.from_model)
    fresh = sb3_contrib.MaskablePPO(RegionsPolicy, env, n_steps=16, batch_size=16, seed=1)
    _copy_clone(fresh, out)
    for a, b in zip(
        fresh.policy.parameter_groups()["actor"],
        model.anchor.parameter_groups()["actor"],
        strict=True,
    ):
        torch.testing.assert_close(a, b)
    other = sb3_contrib.MaskablePPO(
        RegionsPolicy, env, n_steps=16, policy_kwargs={"map_context": False}
    )
    with pytest.raises(ConfigError, match=r"from_model: .*'s actor differs from this one"):
        _copy_clone(other, out)

    summary = train_ppo("SfW-ExploreRegions-v0", 48, out, resume=True, **kwargs)
    assert summary["steps"] == 48
    resumed = AnchoredMaskablePPO.load(out / "SfW-ExploreRegions-v0.zip")
    assert resumed.n_train_calls == 3
    for a, b in zip(resumed.anchor.parameters(), model.anchor.parameters(), strict=True):
        torch.testing.assert_close(a, b)  # the anchor stays the clone
