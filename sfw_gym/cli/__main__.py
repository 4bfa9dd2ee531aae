"""``python -m sfw_gym.cli``: the ``sfw-gym`` command."""

import sys

from sfw_gym.cli import main

sys.exit(main())
