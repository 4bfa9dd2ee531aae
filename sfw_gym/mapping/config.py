"""`MapperConfig`: every knob of k-estimation and sparse inverse k-visibility, validated."""

from __future__ import annotations

import math
from dataclasses import dataclass

from sfw_gym.core.config import Config, setting
from sfw_gym.core.errors import ConfigError

K_ESTIMATORS = ("distance_aware", "kmeans")
ROUTER_POLICIES = ("strongest", "all")


@dataclass(frozen=True)
class MapperConfig(Config):
    """Configuration of the RSSI->k estimator and the sparse inverse k-visibility mapper.

    Log-odds fields are natural-log odds of "occupied" added per observation; negative = free.

    Attributes:
        k_estimator: ``"distance_aware"`` clusters ``rssi + 10 n log10(d)`` (log-distance term
            removed); ``"kmeans"`` clusters raw RSSI (the paper).
        max_k: Largest k-value the estimator can output (K; K + 1 k-means clusters).
        filter_window: Length of the sliding-window mean over each router's readings (1 = off).
        filter_reset_db: Edge-preserving filter: a reading farther than this from every reading
            in the window starts a new window (the robot crossed into another k; averaging
            across the step would make features between two levels, misread and mis-fitted
            as a level of their own). None: ``0.7 * prior_wall_loss_db`` (a one-wall step
            restarts; one noisy reading seldom does); 0: a plain sliding mean.
        path_loss_exponent: n in the log-distance term of the distance-aware feature.
        min_distance_m: Near field: distances below this are raised to it in the log-distance
            term, and such readings are not used to fit thresholds (the model fails there).
        refit_min_samples: Samples per router before the first k-means fit (a prior before).
        refit_growth: Geometric refit schedule: the next fit after ``n * refit_growth`` samples.
        refit_max_interval: Refit at least every this many samples, whatever the growth.
        fit_buffer_size: Most samples per router kept for fitting (a uniform, strided subsample).
        prior_wall_loss_db: Expected loss per wall: the threshold spacing of the prior before
            the first fit, and of thresholds extrapolated beyond the levels seen so far.
        k0_level_dbm: Optional calibration (``"distance_aware"`` only): the distance-corrected
            RSSI with no wall in between, i.e. ``P_tx - PL(1 m)``. With it, the strongest level
            seen is not assumed to be k = 0 but gets ``round((k0_level_dbm - C_0) /
            prior_wall_loss_db)``, so a router heard only through walls is read right. None:
            the strongest level is k = 0 (the paper).
        min_cluster_gap_db: Adjacent sorted centroids closer than this are merged (so data with
            fewer than K + 1 levels is not split); 0 keeps exactly K + 1 clusters as the paper.
            The default, 0.7 of the default wall loss, also keeps k-means from cutting one level
            broadened by shadowing into two (measured in scripts/benchmarks/bench_mapper_quality.py:
            k-accuracy 0.66 -> 0.72 with the default radio noise, noise-off maps unchanged).
        min_level_fraction: Clusters holding less than this fraction of the samples are merged
            into their nearest neighbour (outliers, e.g. right beside a router, must not
            become the k = 0 level); 0 disables.
        router_policy: ``"strongest"`` updates along the strongest router's ray only (the
            paper); ``"all"`` fuses the rays of every heard router.
        robot_radius_m: Footprint radius; footprint cells are observed free (rule 1).
        free_log_odds: Per-cell log-odds on a ray piece with equal k at both ends (rules 2, 4).
        footprint_log_odds: Per-cell log-odds for the robot's footprint each update.
        bump_log_odds: Log-odds for the contact cell when the bumper fires.
        wall_peak_probability: Eq. 6 peak P(occupied) of a one-wall piece no longer than
            ``wall_ref_length_m``; longer pieces flatten (peak excess scales with ref / length).
        wall_ref_length_m: Piece length up to which the Eq. 6 peak keeps its full height.
        wall_sigma_fraction: Eq. 6 width: sigma = fraction * piece length.
        wall_sigma_min_m: Lower bound on the Eq. 6 sigma.
        wall_cap_factor: One piece's wall evidence lifts a cell's log-odds to at most this
            multiple of its own Eq. 6 log-odds (repeated weak evidence stays weak).
        log_odds_min: Clamp for free evidence (keeps the map able to change its mind).
        log_odds_max: Clamp for wall evidence.
        trajectory_gap_max_m: Successive positions closer than this are joined when rasterising
            the trajectory (so rays cannot slip between samples); farther apart, only the cell.
        extend_past_robot: Continue each ray past the robot to the grid's edge, cut at every
            earlier trajectory point beyond it, and update those pieces too.
        outer_bounds_m: Optional ``(xmin, ymin, xmax, ymax)``: cells outside are never updated
            and carry no entropy.
    """

    k_estimator: str = setting("distance_aware", choices=K_ESTIMATORS)
    max_k: int = setting(3, integer=True, ge=1, le=32)
    filter_window: int = setting(3, integer=True, ge=1, le=10_000)
    filter_reset_db: float | None = setting(None, ge=0.0, optional=True)
    path_loss_exponent: float = setting(2.0, gt=0.0)
    min_distance_m: float = setting(1.0, gt=0.0)
    refit_min_samples: int = setting(32, integer=True, ge=2, le=10**9)
    refit_growth: float = setting(1.5, gt=1.0)
    refit_max_interval: int = setting(2000, integer=True, ge=1, le=10**9)
    fit_buffer_size: int = setting(4096, integer=True, ge=16, le=10**8)
    prior_wall_loss_db: float = setting(10.0, gt=0.0)
    k0_level_dbm: float | None = setting(None, optional=True)
    min_cluster_gap_db: float = setting(7.0, ge=0.0)
    min_level_fraction: float = setting(0.02, ge=0.0, lt=0.5)
    router_policy: str = setting("strongest", choices=ROUTER_POLICIES)
    robot_radius_m: float = setting(0.17, ge=0.0)
    free_log_odds: float = setting(-0.4, lt=0.0)
    footprint_log_odds: float = setting(-1.0, lt=0.0)
    bump_log_odds: float = setting(3.0, gt=0.0)
    wall_peak_probability: float = setting(0.8, gt=0.5, lt=1.0)
    wall_ref_length_m: float = setting(0.5, gt=0.0)
    wall_sigma_fraction: float = setting(0.15, gt=0.0)
    wall_sigma_min_m: float = setting(0.05, gt=0.0)
    wall_cap_factor: float = setting(2.0, gt=0.0)
    log_odds_min: float = setting(-4.0, lt=0.0)
    log_odds_max: float = setting(4.0, gt=0.0)
    trajectory_gap_max_m: float = setting(1.0, ge=0.0)
    extend_past_robot: bool = setting(True, choices=(True, False))
    outer_bounds_m: tuple[float, float, float, float] | None = None

    def validate(self) -> None:
        if self.k0_level_dbm is not None and self.k_estimator != "distance_aware":
            raise ConfigError(
                "k0_level_dbm needs k_estimator='distance_aware' (raw RSSI has no fixed "
                f"no-wall level), got k_estimator={self.k_estimator!r}"
            )
        if self.outer_bounds_m is not None:
            b = self.outer_bounds_m
            ok = (
                isinstance(b, (tuple, list))
                and len(b) == 4
                and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in b)
                and all(math.isfinite(v) for v in b)
            )
            if not ok or not (b[2] > b[0] and b[3] > b[1]):
                raise ConfigError(
                    f"outer_bounds_m must be None or (xmin, ymin, xmax, ymax) with max > min, "
                    f"got {b!r}"
                )
            object.__setattr__(self, "outer_bounds_m", tuple(float(v) for v in b))
