"""An optional simulated 2-D LiDAR: beams cast against the plan's wall faces.

Beam ``k`` points at ``theta + angles[k]`` and returns the distance to the first wall face
(:attr:`Floorplan.edges <sfw_gym.world.floorplan.Floorplan.edges>`) along it, ``inf`` where
nothing lies within ``max_range_m`` or the beam drops out; hits get Gaussian range noise.

The compiled kernel visits each edge once: edges farther than the maximum range are skipped
after a bounding-box and a point-to-segment test, and a kept edge is only intersected with the
few beams inside the angle it spans as seen from the robot (widened by 1e-9 rad for round-off),
so a scan costs about ``O(E + beams × walls per beam)`` rather than ``O(E × beams)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numba import njit

from sfw_gym.core.config import Config, setting
from sfw_gym.core.errors import ConfigError
from sfw_gym.world.floorplan import Floorplan

_TWO_PI = 2.0 * math.pi
_ANGLE_MARGIN = 1e-9  # radians added to each side of an edge's span (round-off)
_EDGE_SLACK = 1e-9  # an edge is hit this far (in edge lengths) beyond its ends (round-off)


@dataclass(frozen=True)
class LidarConfig(Config):
    """A planar LiDAR's settings (distances in metres)."""

    prefix: ClassVar[str | None] = "lidar"
    beams: int = setting(360, integer=True, ge=1)
    fov_deg: float = setting(360.0, gt=0.0, le=360.0)  # centred on the heading
    max_range_m: float = setting(8.0, gt=0.0)
    range_noise_std_m: float = setting(0.01, ge=0.0)  # Gaussian, added to each hit
    dropout: float = setting(0.0, ge=0.0, lt=1.0)  # probability that a beam returns nothing


@njit(cache=True)
def _cast(edges, x, y, theta, cos_a, sin_a, start, step, max_range, out):
    """Distance along each beam to the first edge within ``max_range`` (``inf`` if none).

    Args:
        edges: ``(E, 4)`` wall faces ``x0, y0, x1, y1``.
        x, y, theta: The sensor's pose.
        cos_a, sin_a: ``(n,)`` cosine and sine of the beams' angles relative to the heading.
        start, step: Beam ``k`` lies at ``start + k * step`` relative to the heading.
        max_range: Hits farther than this are ignored.
        out: ``(n,)`` ranges, written.
    """
    n = out.shape[0]
    ct = math.cos(theta)
    st = math.sin(theta)
    out[:] = np.inf
    first = (theta + start) % _TWO_PI - _TWO_PI  # the first beam's world angle, in [-2π, 0)
    for e in range(edges.shape[0]):
        x0 = edges[e, 0]
        y0 = edges[e, 1]
        x1 = edges[e, 2]
        y1 = edges[e, 3]
        if (
            min(x0, x1) > x + max_range
            or max(x0, x1) < x - max_range
            or min(y0, y1) > y + max_range
            or max(y0, y1) < y - max_range
        ):
            continue
        wx = x0 - x
        wy = y0 - y
        ex = x1 - x0
        ey = y1 - y0
        len2 = ex * ex + ey * ey
        if len2 == 0.0:
            continue
        u = min(1.0, max(0.0, -(wx * ex + wy * ey) / len2))
        cx = wx + u * ex
        cy = wy + u * ey
        if cx * cx + cy * cy > max_range * max_range:
            continue
        # The edge's angular span seen from the robot, as offsets from the first beam.
        a0 = math.atan2(wy, wx)
        span = math.atan2(y1 - y, x1 - x) - a0
        if span > math.pi:
            span -= _TWO_PI
        elif span < -math.pi:
            span += _TWO_PI
        if span < 0.0:
            a0 += span
            span = -span
        a0 -= first  # in (-2π, 3π]: brought into [0, 2π)
        if a0 < 0.0:
            a0 += _TWO_PI
        elif a0 >= _TWO_PI:
            a0 -= _TWO_PI
        lo_end = a0 - _ANGLE_MARGIN
        hi_end = a0 + span + _ANGLE_MARGIN
        for shift in (-_TWO_PI, 0.0, _TWO_PI):  # the span may wrap past either end
            if (shift < 0.0 and hi_end < _TWO_PI) or (shift > 0.0 and lo_end >= 0.0):
                continue
            k_lo = max(0, int(np.ceil((lo_end + shift) / step)))
            k_hi = min(n, int(np.floor((hi_end + shift) / step)) + 1)
            for k in range(k_lo, k_hi):
                dx = ct * cos_a[k] - st * sin_a[k]
                dy = st * cos_a[k] + ct * sin_a[k]
                denom = dx * ey - dy * ex
                if denom == 0.0:  # parallel: its neighbours catch a collinear face
                    continue
                s = (wx * dy - wy * dx) / denom
                if s < -_EDGE_SLACK or s > 1.0 + _EDGE_SLACK:  # a beam through a vertex hits
                    continue
                t = (wx * ey - wy * ex) / denom
                if 0.0 <= t <= max_range and t < out[k]:
                    out[k] = t


class Lidar:
    """A simulated 2-D LiDAR in one floorplan.

    Attributes:
        config: Its settings.
        angles: ``(beams,)`` beam angles relative to the heading, radians, from ``-fov/2``
            (the last beam at ``+fov/2`` unless the field of view is a full circle).
    """

    def __init__(self, floorplan: Floorplan, config: LidarConfig | None = None) -> None:
        self.config = cfg = config or LidarConfig()
        self._edges = np.ascontiguousarray(floorplan.edges, dtype=np.float64)
        fov = math.radians(cfg.fov_deg)
        full = cfg.fov_deg >= 360.0
        self.angles = np.linspace(-fov / 2, fov / 2, cfg.beams, endpoint=not full)
        self.angles.setflags(write=False)
        self._start = -fov / 2
        self._step = fov / (cfg.beams - (0 if full else 1)) if cfg.beams > 1 else _TWO_PI
        self._cos = np.cos(self.angles)
        self._sin = np.sin(self.angles)

    def scan(self, pose: Any, rng: np.random.Generator) -> np.ndarray:
        """Ranges ``(beams,)`` float64 in metres from ``pose`` ``(x, y, theta)``; ``inf`` where
        a beam hits nothing within range or drops out. Noise and dropout come from ``rng``."""
        x, y, theta = _pose(pose)
        cfg = self.config
        ranges = np.empty(cfg.beams, np.float64)
        _cast(
            self._edges,
            x,
            y,
            theta,
            self._cos,
            self._sin,
            self._start,
            self._step,
            cfg.max_range_m,
            ranges,
        )
        if cfg.range_noise_std_m > 0.0:
            ranges += rng.normal(0.0, cfg.range_noise_std_m, cfg.beams)  # inf stays inf
            np.maximum(ranges, 0.0, out=ranges)
        if cfg.dropout > 0.0:
            ranges[rng.random(cfg.beams) < cfg.dropout] = np.inf
        return ranges

    def points(self, pose: Any, ranges: np.ndarray) -> np.ndarray:
        """The finite hits of ``ranges`` as ``(M, 2)`` points seen from ``pose``: world
        coordinates for the robot's pose, the robot's frame (x forward, y left) for
        ``(0, 0, 0)``."""
        x, y, theta = _pose(pose)
        r = np.asarray(ranges, np.float64)
        if r.shape != self.angles.shape:
            raise ConfigError(f"ranges must have shape {self.angles.shape}, got {r.shape}")
        hit = np.isfinite(r)
        a = theta + self.angles[hit]
        return np.column_stack([x + r[hit] * np.cos(a), y + r[hit] * np.sin(a)])


def _pose(pose: Any) -> tuple[float, float, float]:
    try:
        x, y, theta = (float(v) for v in pose)
    except (TypeError, ValueError):
        raise ConfigError(f"pose must be (x, y, theta), got {pose!r:.80}") from None
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(theta)):
        raise ConfigError(f"pose must be finite, got {(x, y, theta)!r}")
    return x, y, theta
