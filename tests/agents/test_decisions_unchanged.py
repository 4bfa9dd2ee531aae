"""The classical agents' actions, bit for bit, against digests recorded before the planning was
made incremental (issue 39): reusing the cost field, the wall terms and the menu must not change
a single action. A digest here changes only with a deliberate change of an agent's rule (record
the new one with ``python tests/agents/test_decisions_unchanged.py``, and say why in the commit).
"""

from __future__ import annotations

import hashlib

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.agents import make_agent

#: (agent, env id, env seed, steps): long enough for hundreds of replans, bumps and escapes.
CASES = [
    ("frontier", "SfW-Explore-v0", 2_000_000, 1000),
    ("frontier", "SfW-ExploreSmall-v0", 7, 300),
    ("cross-pass", "SfW-Explore-v0", 2_000_001, 600),
    ("greedy", "SfW-Explore-v0", 2_000_002, 600),
    ("region-teacher", "SfW-Explore-v0", 2_000_003, 600),
]

DIGESTS = {
    ("frontier", "SfW-Explore-v0", 2_000_000): "06962fa3ee88e09c",
    ("frontier", "SfW-ExploreSmall-v0", 7): "ce1c8b72e20f7023",
    ("cross-pass", "SfW-Explore-v0", 2_000_001): "c9eec96c8077f1ad",
    ("greedy", "SfW-Explore-v0", 2_000_002): "8b3e988c82b73d15",
    ("region-teacher", "SfW-Explore-v0", 2_000_003): "5b9bd703225ae5c2",
}


def action_digest(agent_name: str, env_id: str, seed: int, steps: int) -> str:
    """SHA-256 (first 16 hex digits) of the agent's actions over ``steps`` steps (float64)."""
    env = gym.make(env_id)
    obs, _ = env.reset(seed=seed)
    agent = make_agent(agent_name)
    agent.reset(env, seed=0)
    actions = []
    for _ in range(steps):
        action = agent.act(obs)
        actions.append(np.asarray(action, np.float64))
        obs, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            break
    env.close()
    return hashlib.sha256(np.concatenate(actions).tobytes()).hexdigest()[:16]


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c[0]}-{c[1]}")
def test_actions_equal_the_recorded_ones(case):
    assert action_digest(*case) == DIGESTS[case[:3]]


if __name__ == "__main__":
    for case in CASES:
        print(f"    {case[:3]!r}: {action_digest(*case)!r},")
