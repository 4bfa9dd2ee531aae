"""The facts every layer shares, written once: the belief encoding, radio and action tables, units.

Units throughout the package: metres, radians (counter-clockwise, 0 along +x), seconds, dBm for
RSSI and dB for losses; a name carries its unit where it is not obvious (``resolution_m``,
``wall_loss_db``). Grids are indexed ``[row, col]`` = ``[y, x]``.
"""

from __future__ import annotations

# -- the uint8 belief encoding (the mapping paper's): floor(255 · P(free)) ------------------------
#: A wall (ground truth) or certainly occupied (belief).
U8_WALL = 0
#: Unknown (belief) or outside the building (ground truth); log-odds 0.
U8_UNKNOWN = 127
#: Free space.
U8_FREE = 255
#: Graded beliefs are read by thirds: ``<= U8_WALL_MAX`` is a wall (P(occupied) > 2/3) ...
U8_WALL_MAX = 84
#: ... ``>= U8_FREE_MIN`` is free (P(occupied) < 1/3), anything between is unknown.
U8_FREE_MIN = 171

# -- radio ----------------------------------------------------------------------------------------
#: The reading of a router below the receiver's sensitivity ("not heard"), dBm.
NOT_HEARD_DBM = -100

# -- actions --------------------------------------------------------------------------------------
#: Discrete actions as (linear, angular) commands in [-1, 1]: 0 forward, 1 turn left, 2 turn right.
DISCRETE_ACTIONS = ((1.0, 0.0), (0.0, 1.0), (0.0, -1.0))
DISCRETE_ACTION_NAMES = ("forward", "turn_left", "turn_right")

#: Above this many vertices (or wall segments), world geometry takes its bulk paths: a HouseExpo
#: outline is simplified to 1 cm, the robot's walls are added in a shuffled order.
BULK_VERTICES = 2048
