"""``sfw-gym train`` says, as it starts and in its help, which policy it trains, what one
timestep counts, roughly how long it takes, and which command trains the default learned agent."""

from __future__ import annotations

import yaml

from sfw_gym.cli.train import (
    DEFAULT_AGENT_COMMAND,
    WHEELS_DECISIONS_PER_S,
    _print_notice,
    describe,
    notice,
)
from sfw_gym.core.data import data_path, default_hyperparams
from sfw_gym.rl.training import zoo_hyperparams


def test_training_the_default_env_says_it_is_the_wheels_policy_and_how_long(capsys):
    _print_notice("SfW-Explore-v0", default_hyperparams("ppo"), 500_000)
    line = capsys.readouterr().out
    assert line.count("\n") == 1
    assert "wheels-ppo, from scratch" in line
    assert "one timestep is one decision (a wheel command held for 4 env steps)" in line
    minutes = round(500_000 / WHEELS_DECISIONS_PER_S / 60)
    assert f"500,000 timesteps take roughly {minutes} min" in line
    assert f"trained by: {DEFAULT_AGENT_COMMAND}" in line


def test_an_older_waypoint_block_says_it_is_the_waypoint_policy():
    wrapped = {"env_wrapper": [{"sfw_gym.envs.waypoint.WaypointWrapper": {}}]}
    line = notice("SfW-Explore-v0", wrapped, 200_000)
    assert "waypoint-ppo" in line and "one timestep is one waypoint (about 35 env steps" in line
    assert "200,000 timesteps take roughly 69 min" in line


def test_training_the_region_policy_says_it_is_the_default_agent():
    params = zoo_hyperparams("SfW-ExploreRegions-v0", default_hyperparams("ppo_mask"))
    line = notice("SfW-ExploreRegions-v0", params, 30_000)
    assert "regions-ppo, the default learned agent" in line
    # the shipped run's record: its total wall time, cloning included, in minutes
    record = yaml.safe_load(
        data_path("agents", "ppo_mask", "SfW-ExploreRegions-v0_1", "config.yml").read_text()
    )
    minutes = round(record["total_wall_time_s"] / 60)
    assert "one region decision (up to 20 env steps)" in line and f"roughly {minutes} min" in line
    assert DEFAULT_AGENT_COMMAND not in line  # it is this command


def test_another_env_counts_env_steps_and_rllib_gives_no_time():
    line = notice("SfW-ExploreSmall-v0", {}, 32)
    assert "a policy over the env's own actions" in line and "one timestep is one env step" in line
    assert "times were measured for other envs only" in line
    wrapped = {"env_wrapper": [{"sfw_gym.envs.waypoint.WaypointWrapper": {}}]}
    line = notice("SfW-Explore-v0", wrapped, 1000, rllib=True)
    assert "waypoint-ppo" in line and "measured for stable-baselines3 only" in line


def test_the_help_says_it_for_each_env():
    text = describe()
    for words in ("regions-ppo, the default learned agent", "goals-ppo", "wheels-ppo"):
        assert words in text
    assert DEFAULT_AGENT_COMMAND in text and "one env step" in text


def test_device_reaches_the_training(monkeypatch):
    """``--device cuda`` is handed to train_ppo (the policy's torch device); auto by default."""
    import sfw_gym.rl.training as training
    from sfw_gym.cli import main

    seen = []

    def fake_train(*args, **kwargs):
        seen.append(kwargs["device"])
        return {"steps": 0, "wall_time_s": 0.0, "model": "none"}

    monkeypatch.setattr(training, "train_ppo", fake_train)
    for extra in ([], ["--device", "cuda"]):
        assert main(["train", "ppo", "--env", "SfW-ExploreSmall-v0", "--no-progress", *extra]) == 0
    assert seen == ["auto", "cuda"]
