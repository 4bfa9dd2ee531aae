"""WiFi RSSI simulation: log-distance path loss, per-wall losses, correlated shadowing, noise.

RSSI [dBm] = P_tx − (PL(d0) + 10·n·log10(d/d0)) − min(Σ wall losses, cap) + shadowing(x) + noise,
rounded to an integer; a reading below the sensitivity floor is "not heard" (``NOT_HEARD_DBM``).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any

import numpy as np
from numba import njit, prange
from shapely.geometry import Point

from sfw_gym.core.config import Config, Range, setting
from sfw_gym.core.constants import NOT_HEARD_DBM
from sfw_gym.core.errors import ConfigError
from sfw_gym.world.floorplan import MATERIALS, Floorplan
from sfw_gym.world.wall_crossing import DEFAULT_MIN_PIECE_M
from sfw_gym.world.wall_index import DEFAULT_BUCKETS, build_wall_index, cross_from_router

#: Above this many points, wall counting runs on all cores.
_PARALLEL_MIN_POINTS = 256

#: Sentinel RSSI of a router that is not heard.
_SPEED_OF_LIGHT_M_S = 299_792_458.0
#: Per-material losses at 2.4 GHz (COST-231, IEEE TGax); "generic" is an unknown wall (HouseExpo).
RESIDENTIAL_LOSS_DB = MappingProxyType(
    {"generic": 10.0, "drywall": 3.0, "wood": 3.0, "glass": 2.0, "brick": 8.0, "concrete": 12.0}
)
PRESETS = ("default", "thick", "residential")
BANDS = {"2.4": 2.437, "5": 5.25}


def free_space_path_loss_db(distance_m: float, frequency_ghz: float) -> float:
    """Friis free-space path loss 20·log10(4π d f / c) in dB."""
    return 20.0 * math.log10(4.0 * math.pi * distance_m * frequency_ghz * 1e9 / _SPEED_OF_LIGHT_M_S)


def _uniform_losses(loss_db: float) -> dict[str, float]:
    return dict.fromkeys(MATERIALS, loss_db)


@dataclass(frozen=True)
class RadioConfig(Config):
    """Radio model parameters (DESIGN.md defaults: the ``default`` preset at 2.4 GHz).

    ``path_loss_d0_db`` of ``None`` means the free-space loss at ``reference_distance_m`` for
    ``frequency_ghz`` (40.2 dB at 1 m, 2.437 GHz). Distances below ``reference_distance_m`` are
    clamped to it.
    """

    frequency_ghz: float = setting(2.437, ge=0.1, le=100.0)
    tx_power_dbm: float = setting(20.0, ge=-50.0, le=60.0)
    path_loss_d0_db: float | None = setting(None, optional=True, ge=0.0, le=200.0)
    reference_distance_m: float = setting(1.0, ge=1e-3, le=100.0)
    path_loss_exponent: float = setting(2.0, gt=0.0, le=10.0)
    wall_loss_db: Mapping[str, float] = field(default_factory=lambda: _uniform_losses(10.0))
    max_total_wall_loss_db: float = setting(45.0, ge=0.0, le=500.0)
    shadowing_sigma_db: float = setting(4.0, ge=0.0, le=50.0)
    shadowing_correlation_m: float = setting(5.0, gt=0.0, le=1e4)
    noise_sigma_db: float = setting(2.0, ge=0.0, le=50.0)
    sensitivity_dbm: float = setting(-90.0, ge=-200.0, le=0.0)

    def validate(self) -> None:
        loss = Range(ge=0.0)
        if isinstance(self.wall_loss_db, numbers.Real) and not isinstance(self.wall_loss_db, bool):
            # One number: the same loss for every material.
            uniform = loss.check("RadioConfig.wall_loss_db", self.wall_loss_db)
            object.__setattr__(self, "wall_loss_db", _uniform_losses(uniform))
        if not isinstance(self.wall_loss_db, Mapping):
            raise ConfigError(
                "RadioConfig.wall_loss_db must map material names to losses in dB, or be one "
                f"loss for every material; got {self.wall_loss_db!r}"
            )
        missing = sorted(set(MATERIALS) - set(self.wall_loss_db))
        unknown = sorted(set(self.wall_loss_db) - set(MATERIALS))
        if missing or unknown:
            raise ConfigError(
                f"RadioConfig.wall_loss_db must give a loss for exactly {list(MATERIALS)}; "
                f"missing {missing}, unknown {unknown}"
            )
        # A private plain copy: picklable, and safe from the caller's later edits.
        object.__setattr__(
            self,
            "wall_loss_db",
            {
                m: loss.check(f"RadioConfig.wall_loss_db[{m!r}]", v)
                for m, v in self.wall_loss_db.items()
            },
        )

    @classmethod
    def preset(cls, name: str = "default", band: str = "2.4", **overrides: Any) -> RadioConfig:
        """A named preset: ``default`` (10 dB per wall), ``thick`` (15 dB, the paper's building),
        ``residential`` (per-material losses: the hard mode); ``band`` "2.4" or "5" GHz.

        At 5 GHz only the frequency (hence PL(d0) ≈ 46.8 dB) changes; wall losses stay the preset's.
        A ``wall_loss_db`` override may name some materials only (the rest keep the preset's), or
        be one number for every material.
        """
        losses = {
            "default": _uniform_losses(10.0),
            "thick": _uniform_losses(15.0),
            "residential": RESIDENTIAL_LOSS_DB,
        }
        if name not in losses:
            raise ConfigError(f"unknown radio preset {name!r}; choose one of {list(PRESETS)}")
        if band not in BANDS:
            raise ConfigError(f"unknown radio band {band!r}; choose one of {list(BANDS)}")
        overrides = dict(overrides)
        given = overrides.get("wall_loss_db")
        if isinstance(given, Mapping):  # some materials: the others keep the preset's losses
            overrides["wall_loss_db"] = {**losses[name], **given}
        return cls.from_dict(
            {"frequency_ghz": BANDS[band], "wall_loss_db": losses[name], **overrides}, "radio"
        )

    @property
    def d0_loss_db(self) -> float:
        """PL(d0) in dB: the configured value or the free-space loss at d0."""
        if self.path_loss_d0_db is not None:
            return float(self.path_loss_d0_db)
        return free_space_path_loss_db(self.reference_distance_m, self.frequency_ghz)

    def noiseless(self) -> RadioConfig:
        """The same model without shadowing or temporal noise."""
        return replace(self, shadowing_sigma_db=0.0, noise_sigma_db=0.0)


class ShadowingField:
    """Spatially correlated Gaussian shadowing, one independent field per router, fixed once drawn.

    Exponential covariance σ²·exp(−r/L) (Gudmundson), drawn by random Fourier features (the
    spectral density of the 2-D exponential kernel is a bivariate Student-t with 1 degree of
    freedom, scaled by 1/L) and tabulated on a grid that is interpolated bilinearly.
    """

    def __init__(
        self,
        bounds: tuple[float, float, float, float],
        n_routers: int,
        sigma_db: float,
        correlation_m: float,
        rng: np.random.Generator,
        *,
        n_features: int = 128,
        spacing_m: float = 0.5,
    ) -> None:
        xmin, ymin, xmax, ymax = bounds
        self.origin = np.array([xmin - spacing_m, ymin - spacing_m])
        self.spacing_m = spacing_m
        nx = math.ceil((xmax - xmin) / spacing_m) + 3
        ny = math.ceil((ymax - ymin) / spacing_m) + 3
        gy, gx = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
        nodes = self.origin + spacing_m * np.stack([gx.ravel(), gy.ravel()], axis=1)
        tables = []
        for _ in range(n_routers):
            omega = rng.standard_normal((n_features, 2)) / (
                correlation_m * np.abs(rng.standard_normal((n_features, 1))) + 1e-12
            )
            phase = rng.uniform(0.0, 2.0 * np.pi, n_features)
            values = sigma_db * math.sqrt(2.0 / n_features) * np.cos(nodes @ omega.T + phase).sum(1)
            tables.append(values.reshape(ny, nx))
        self.table_db = np.stack(tables)  # (R, ny, nx), node (j, i) at origin + spacing·(i, j)

    def __call__(self, points: np.ndarray) -> np.ndarray:
        """Shadowing in dB at points (M, 2) for every router: (M, R)."""
        return _bilinear(self.table_db, self.origin, self.spacing_m, points)


@njit(cache=True)
def _bilinear(
    tables: np.ndarray, origin: np.ndarray, spacing: float, pts: np.ndarray
) -> np.ndarray:
    """Bilinear interpolation of (R, ny, nx) node tables at points (M, 2), clamped to the grid."""
    out = np.empty((pts.shape[0], tables.shape[0]))
    _bilinear_into(tables, origin, spacing, pts, out, 0, pts.shape[0])
    return out


@njit(cache=True)
def _bilinear_into(tables, origin, spacing, pts, out, lo, hi):
    """`_bilinear` at points lo..hi, written into those rows of ``out``."""
    n_r, ny, nx = tables.shape
    for m in range(lo, hi):
        fx = min(max((pts[m, 0] - origin[0]) / spacing, 0.0), nx - 1.000001)
        fy = min(max((pts[m, 1] - origin[1]) / spacing, 0.0), ny - 1.000001)
        i = int(fx)
        j = int(fy)
        tx = fx - i
        ty = fy - j
        for r in range(n_r):
            top = tables[r, j, i] * (1 - tx) + tables[r, j, i + 1] * tx
            bottom = tables[r, j + 1, i] * (1 - tx) + tables[r, j + 1, i + 1] * tx
            out[m, r] = top * (1 - ty) + bottom * ty


@njit(cache=True)
def _rssi_range(
    edges, edge_loss, index, routers, pts, params, tables, origin, spacing, rssi, k, lo, hi,
    scratch,
):  # fmt: skip
    """Mean RSSI and wall counts for points lo..hi: the whole model in one compiled loop
    (``index``: the walls' `wall_index` around the routers, and the edges 0..E-1;
    ``scratch``: `crossing_scratch`)."""
    tx, pl0, ten_n, d0, cap, min_piece = params
    starts, edge_ids, all_edges = index
    ts, ids = scratch
    _bilinear_into(tables, origin, spacing, pts, rssi, lo, hi)  # the shadowing, added below
    for m in range(lo, hi):
        for r in range(routers.shape[0]):
            c, loss = cross_from_router(
                edges,
                edge_loss,
                starts,
                edge_ids,
                all_edges,
                r,
                routers[r, 0],
                routers[r, 1],
                pts[m, 0],
                pts[m, 1],
                min_piece,
                ts,
                ids,
            )
            d = max(np.hypot(pts[m, 0] - routers[r, 0], pts[m, 1] - routers[r, 1]), d0)
            k[m, r] = c
            rssi[m, r] = tx - (pl0 + ten_n * np.log10(d / d0)) - min(loss, cap) + rssi[m, r]


@njit(cache=True)
def crossing_scratch(edges):
    """The wall crossings' scratch arrays (sorted crossings and their edges) for ``edges``."""
    return np.empty(edges.shape[0] + 1), np.empty(edges.shape[0] + 1, np.int64)


@njit(cache=True)
def _rssi(edges, edge_loss, index, routers, pts, params, tables, origin, spacing):
    rssi = np.empty((pts.shape[0], routers.shape[0]))
    k = np.empty((pts.shape[0], routers.shape[0]), np.int32)
    _rssi_range(
        edges, edge_loss, index, routers, pts, params, tables, origin, spacing, rssi, k, 0,
        len(pts), crossing_scratch(edges),
    )  # fmt: skip
    return rssi, k


@njit(cache=True, parallel=True)
def _rssi_parallel(edges, edge_loss, index, routers, pts, params, tables, origin, spacing):
    m = pts.shape[0]
    rssi = np.empty((m, routers.shape[0]))
    k = np.empty((m, routers.shape[0]), np.int32)
    n_chunks = (m + 511) // 512
    for c in prange(n_chunks):
        _rssi_range(
            edges,
            edge_loss,
            index,
            routers,
            pts,
            params,
            tables,
            origin,
            spacing,
            rssi,
            k,
            c * 512,
            min(m, (c + 1) * 512),
            crossing_scratch(edges),
        )
    return rssi, k


class RadioModel:
    """RSSI from routers at fixed positions in one floorplan, with one episode's shadowing.

    Args:
        floorplan: the ground-truth plan.
        routers: (R, 2) router positions in metres; each must lie in the free space unless
            ``in_free_space`` is False (background access points).
        config: the radio parameters.
        rng: the source of the shadowing field (drawn here) and of temporal noise (each reading).
    """

    def __init__(
        self,
        floorplan: Floorplan,
        routers: np.ndarray,
        config: RadioConfig | None = None,
        rng: np.random.Generator | None = None,
        *,
        in_free_space: bool = True,
    ) -> None:
        self.floorplan = floorplan
        self.config = config or RadioConfig()
        if in_free_space:
            self.routers = validate_routers(floorplan, routers)
        else:  # background access points may stand anywhere, walls and neighbours included
            self.routers = np.asarray(routers, np.float64).reshape(-1, 2)
        self.rng = rng if rng is not None else np.random.default_rng()
        self._d0_loss_db = self.config.d0_loss_db
        edges = floorplan.edges
        self._wall_index = (
            *build_wall_index(edges, self.routers, DEFAULT_BUCKETS),
            np.arange(len(edges)),
        )
        losses = self.config.wall_loss_db
        self._edge_loss_db = np.array([losses[m] for m in floorplan.edge_materials], np.float64)
        cfg = self.config
        self._params = np.array(
            [
                cfg.tx_power_dbm,
                self._d0_loss_db,
                10.0 * cfg.path_loss_exponent,
                cfg.reference_distance_m,
                cfg.max_total_wall_loss_db,
                DEFAULT_MIN_PIECE_M,
            ]
        )
        if cfg.shadowing_sigma_db > 0:
            field = ShadowingField(
                floorplan.bounds,
                len(self.routers),
                cfg.shadowing_sigma_db,
                cfg.shadowing_correlation_m,
                self.rng,
            )
            self._shadow_args = (field.table_db, field.origin, field.spacing_m)
        else:  # a flat zero table: no shadowing
            self._shadow_args = (np.zeros((len(self.routers), 2, 2)), np.zeros(2), 1.0)

    @property
    def n_routers(self) -> int:
        """Number of routers R."""
        return len(self.routers)

    def _points(self, points: np.ndarray) -> np.ndarray:
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        if not np.isfinite(pts).all():
            raise ConfigError("points must be finite (got NaN or inf)")
        return pts

    def path_loss_db(self, points: np.ndarray) -> np.ndarray:
        """Log-distance path loss (no walls) to each router: (M, R) dB."""
        pts = self._points(points)
        d = np.linalg.norm(pts[:, None, :] - self.routers[None, :, :], axis=2)
        d = np.maximum(d, self.config.reference_distance_m)
        ratio = np.log10(d / self.config.reference_distance_m)
        return self._d0_loss_db + 10.0 * self.config.path_loss_exponent * ratio

    def _model(self, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Mean RSSI (M, R) and true k (M, R) at points, in one compiled pass."""
        kernel = _rssi_parallel if len(pts) >= _PARALLEL_MIN_POINTS else _rssi
        return kernel(
            self.floorplan.edges,
            self._edge_loss_db,
            self._wall_index,
            self.routers,
            pts,
            self._params,
            *self._shadow_args,
        )

    def true_k(self, points: np.ndarray) -> np.ndarray:
        """Number of walls between each router and each point: (M, R) int."""
        return self._model(self._points(points))[1]

    def mean_rssi(self, points: np.ndarray) -> np.ndarray:
        """RSSI without temporal noise (path loss, capped walls, shadowing): (M, R) float dBm."""
        return self._model(self._points(points))[0]

    def measure(self, point: np.ndarray) -> np.ndarray:
        """One reading at ``point`` (2,): (R,) integer dBm, ``NOT_HEARD_DBM`` below sensitivity."""
        return self.measure_with_k(point)[0]

    def measure_with_k(self, point: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One reading at ``point`` and the true k of each router there (one wall traversal)."""
        x, y = self._points(point)[0].tolist()
        return self.measure_at(x, y)

    def measure_at(self, x: float, y: float) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`measure_with_k` at ``(x, y)`` (floats), without the array checks: the env's
        step reads the radio this way."""
        if not (math.isfinite(x) and math.isfinite(y)):
            raise ConfigError(f"points must be finite (got {x!r}, {y!r})")
        pts = np.array(((x, y),))
        rssi, k = _rssi(
            self.floorplan.edges, self._edge_loss_db, self._wall_index, self.routers, pts,
            self._params, *self._shadow_args,
        )  # fmt: skip
        return self._reading(rssi[0]), k[0]

    def _reading(self, rssi: np.ndarray) -> np.ndarray:
        """Mean RSSI (R,) → one reading: temporal noise, rounded to whole dBm, ``NOT_HEARD_DBM``
        below sensitivity."""
        if self.config.noise_sigma_db > 0:
            rssi += self.rng.normal(0.0, self.config.noise_sigma_db, rssi.shape)
        reading = np.rint(rssi).astype(np.int32)
        reading[reading < self.config.sensitivity_dbm] = NOT_HEARD_DBM
        return reading


def validate_routers(floorplan: Floorplan, routers: np.ndarray) -> np.ndarray:
    """Routers as a (R, 2) float array, each in the plan's free space, else a ConfigError."""
    arr = np.asarray(routers, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 2 or len(arr) == 0:
        raise ConfigError(f"routers must have shape (R, 2) with R ≥ 1, got {arr.shape}")
    if not np.isfinite(arr).all():
        raise ConfigError(f"router positions must be finite, got {arr.tolist()}")
    free = floorplan.is_free(arr)
    for i in np.flatnonzero(~free):
        x, y = arr[i]
        inside = floorplan.footprint.contains(Point(x, y))
        where = "inside a wall" if inside else "outside the building"
        raise ConfigError(
            f"router {i} at ({x:.3f}, {y:.3f}) is {where} of floorplan {floorplan.name!r}; "
            f"routers must stand in free space"
        )
    return arr
