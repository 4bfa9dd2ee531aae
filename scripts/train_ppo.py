"""Train PPO on SfW-Explore: the same as ``sfw-gym train ppo …`` (see ``--help``)."""

from __future__ import annotations

import sys

from sfw_gym.cli import main

if __name__ == "__main__":
    sys.exit(main(["train", "ppo", *sys.argv[1:]]))
