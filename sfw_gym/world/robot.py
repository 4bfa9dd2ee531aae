"""The robot: a differential-drive disc in a pymunk space whose static shapes are the walls.

The robot has no camera and no range sensor. It reports a bump (contact with a wall during the last
control step) and integrates odometry (its true motion in its own frame, plus optional Gaussian
drift). The walls are plain segments ``[x0, y0, x1, y1]`` in metres, so this module does not depend
on :class:`~sfw_gym.world.Floorplan`.

Physics. Each control step lasts ``control_period_s`` and is split into ``physics_substeps``
pymunk steps. The drive is kinematic: a pymunk velocity callback sets, every substep, the body's
velocity to the commanded forward speed along its current heading and its angular velocity to the
commanded turn rate. pymunk's contact solver then removes the part of that velocity that would push
into a wall (frictionless, inelastic contact), so the robot slides along walls it meets at an angle
and stops at walls it meets head-on; collision impulses never make it spin or bounce. A wall is a
static ``pymunk.Segment`` of radius ``wall_radius_m`` (a thin skin around the wall line). A contact
starts only once the disc overlaps that skin, so the deepest the disc can get before the solver
pushes it back is one substep's travel: the robot's centre stays at least
``radius_m + wall_radius_m - max_linear_speed_m_s * control_period_s / physics_substeps`` from every
wall line (``radius_m`` with the defaults), and it rests ``radius_m + wall_radius_m`` from a wall it
presses against. pymunk's solver acts only after a substep's move, so at the start of each control
step the part of the new command that points into a wall the disc already touches is removed by
hand. When no wall is within reach of the coming step, the same motion is produced without the
Python velocity callback (about twice as fast, identical to the last bit).

Large plans: with more than ``BULK_VERTICES`` walls, pymunk holds only the walls within
``ACTIVE_WALLS_RADIUS_M`` of the robot, chosen again before it could reach past them.

Bump: a pymunk pre-solve handler (a module-level function, so the space pickles) flags every
substep in which the robot's disc touches a wall.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
import pymunk
from numba import njit

from sfw_gym.core.config import Config, setting
from sfw_gym.core.constants import BULK_VERTICES
from sfw_gym.core.errors import ConfigError

__all__ = ["Pose", "Robot", "RobotConfig", "StepResult"]

#: A substep may move the robot at most this far at full speed (a quarter of a 0.1 m wall).
MAX_SUBSTEP_TRAVEL_M = 0.025
#: In a plan of more than ``BULK_VERTICES`` walls, pymunk holds the walls within this distance of
#: where the robot was when they were last chosen, and they are chosen again before the robot
#: could reach beyond them in one control step.
ACTIVE_WALLS_RADIUS_M = 3.0

# Walls keep pymunk's default collision type and filter (setting them cost 5 µs per wall, a
# quarter of a 10,000-wall plan's reset); the robot's disc has its own of each.
_ROBOT_COLLISION_TYPE = 1
_WALL_COLLISION_TYPE = 0  # pymunk's default
_ROBOT_CATEGORY = 0b01
_WALL_CATEGORY = 0b10  # walls carry every category (the default); the disc only its own
_WALL_QUERY = pymunk.ShapeFilter(mask=_WALL_CATEGORY)
# Extra distance at which a wall counts as within reach of the robot in the coming step.
_REACH_MARGIN_M = 1e-3
# How far beyond its reach the robot looks for walls, so that the clearance it finds answers the
# next steps' "a wall within reach?" without asking pymunk again (see Robot._may_touch_wall).
_CLEARANCE_LOOKAHEAD_M = 1.0
# Rounding allowance of that answer: closer calls ask pymunk, so every answer is pymunk's own.
_CLEARANCE_ROUNDING_M = 1e-9
#: A substep's disc this much farther from a wall than touching it cannot start a contact.
_CONTACT_MARGIN_M = 1e-6
# The drive is kinematic and the walls static, so the mass only scales the solver's impulses.
_ROBOT_MASS_KG = 5.0
# Overlap that pymunk leaves uncorrected (its default, 0.1, assumes pixels, not metres).
_COLLISION_SLOP_M = 1e-4
# Fraction of an overlap that the solver removes per substep.
_OVERLAP_CORRECTION_PER_SUBSTEP = 0.3


class Pose(NamedTuple):
    """A planar pose: position in metres, heading in radians in [-π, π] (0 = +x, CCW positive)."""

    x: float
    y: float
    theta: float


@dataclass(frozen=True)
class StepResult:
    """What one control step did.

    Attributes:
        pose: true pose after the step.
        odometry_pose: the robot's odometry estimate after the step.
        bumped: whether the robot touched a wall at any time during the step.
        distance_m: straight-line distance between the true positions before and after the step.
        linear_m_s: forward speed command after clipping to the limits.
        angular_rad_s: turn rate command after clipping to the limits.
    """

    pose: Pose
    odometry_pose: Pose
    bumped: bool
    distance_m: float
    linear_m_s: float
    angular_rad_s: float


@dataclass(frozen=True)
class RobotConfig(Config):
    """Robot geometry, limits, physics resolution and odometry noise.

    Attributes:
        radius_m: radius of the robot's disc (a TurtleBot/Roomba-sized 0.17 m by default).
        max_linear_speed_m_s: forward/backward speed limit; commands are clipped to ± this.
        max_angular_speed_rad_s: turn-rate limit; commands are clipped to ± this.
        control_period_s: duration of one `Robot.step`.
        physics_substeps: pymunk steps per control step. At full speed a substep may move the robot
            at most ``MAX_SUBSTEP_TRAVEL_M`` (2.5 cm); the default moves it 1 cm.
        odometry_translation_std: standard deviation of the odometry's translation error per
            step, as a fraction of the distance travelled in that step (on each axis of the robot
            frame).
        odometry_heading_std_rad: standard deviation of the odometry's heading error, added every
            step (moving or not).
        wall_radius_m: radius of the static wall segments (a skin around each wall line). Keep it at
            least one substep's travel at full speed so that the robot's centre never comes closer
            than ``radius_m`` to a wall line.
    """

    radius_m: float = setting(0.17, ge=0.01, le=5.0)
    max_linear_speed_m_s: float = setting(0.5, gt=0.0, le=20.0)
    max_angular_speed_rad_s: float = setting(1.5, gt=0.0, le=50.0)
    control_period_s: float = setting(0.2, ge=1e-3, le=10.0)
    physics_substeps: int = setting(10, integer=True, ge=1, le=1000)
    odometry_translation_std: float = setting(0.0, ge=0.0, le=10.0)
    odometry_heading_std_rad: float = setting(0.0, ge=0.0, le=10.0)
    wall_radius_m: float = setting(0.01, ge=0.0, le=1.0)

    def validate(self) -> None:
        travel = self.max_substep_travel_m
        if travel > MAX_SUBSTEP_TRAVEL_M:
            need = math.ceil(
                self.max_linear_speed_m_s * self.control_period_s / MAX_SUBSTEP_TRAVEL_M
            )
            raise ConfigError(
                f"RobotConfig.physics_substeps={self.physics_substeps} lets the robot move "
                f"{travel:.4f} m per substep at full speed (limit {MAX_SUBSTEP_TRAVEL_M} m); "
                f"use at least {need}"
            )

    @property
    def substep_s(self) -> float:
        """Duration of one physics substep, seconds."""
        return self.control_period_s / self.physics_substeps

    @property
    def max_substep_travel_m(self) -> float:
        """Distance covered in one substep at full speed, metres."""
        return self.max_linear_speed_m_s * self.substep_s


class _DriveBody(pymunk.Body):
    """A pymunk body that carries its drive command (pickled with it, as public attributes)."""

    linear_m_s: float
    angular_rad_s: float


def _kinematic_drive(body: Any, gravity: Any, damping: float, dt: float) -> None:
    """pymunk velocity callback: drive along the current heading at the commanded rates.

    Called once per substep after positions are integrated and contacts found, before the contact
    solver; the solver then removes any velocity into a wall. A module-level function so that the
    body (and the space) pickle. ``body`` is a :class:`_DriveBody` (typed ``Any``: pymunk types
    the callback's body as a plain ``Body``).
    """
    speed = body.linear_m_s
    angle = body.angle
    body.velocity = (speed * math.cos(angle), speed * math.sin(angle))
    body.angular_velocity = body.angular_rad_s


class _WorldSpace(pymunk.Space):
    """A pymunk space that records whether the robot touched a wall (pickled with it)."""

    robot_touched: bool


def _record_contact(arbiter: pymunk.Arbiter, space: Any, data: Any) -> None:
    """pymunk pre-solve callback: the robot touches a wall during this substep (``space`` is a
    :class:`_WorldSpace`)."""
    space.robot_touched = True


class Robot:
    """A differential-drive disc robot with a bump sensor and odometry, among static walls.

    Args:
        wall_segments: array-like of shape (E, 4), rows ``[x0, y0, x1, y1]`` in metres (E may be 0).
        config: robot parameters; ``None`` for the defaults.
        pose: start pose ``(x, y, theta_rad)``; the disc must not overlap a wall line.
        rng: source of the odometry noise (pass the environment's ``np_random``). May be ``None``
            only when both odometry noise levels are zero.

    Raises:
        ConfigError: walls not of shape (E, 4) or not finite; pose not three finite numbers or
            overlapping a wall; rng missing while odometry noise is on.

    The robot pickles (and deep-copies) with its pymunk space and its rng: a copy continues exactly
    like the original under the same commands.
    """

    def __init__(
        self,
        wall_segments: np.ndarray | Sequence[Sequence[float]],
        config: RobotConfig | None = None,
        pose: Sequence[float] = (0.0, 0.0, 0.0),
        rng: np.random.Generator | None = None,
    ) -> None:
        if config is None:
            config = RobotConfig()
        if not isinstance(config, RobotConfig):
            raise ConfigError(f"config must be a RobotConfig, got {type(config).__name__}")
        noisy = config.odometry_translation_std > 0.0 or config.odometry_heading_std_rad > 0.0
        if rng is None and noisy:
            raise ConfigError("rng is required when odometry noise is on (pass env.np_random)")
        if rng is not None and not isinstance(rng, np.random.Generator):
            raise ConfigError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
        self._config = config
        self._rng = rng
        self._noisy = noisy
        self._walls = _parse_walls(wall_segments)
        self._walls.flags.writeable = False

        dt = config.substep_s
        space = _WorldSpace()
        space.robot_touched = False
        space.gravity = (0.0, 0.0)
        space.collision_slop = _COLLISION_SLOP_M
        # pymunk corrects overlaps by 1 - collision_bias**dt per step.
        self._collision_bias = (1.0 - _OVERLAP_CORRECTION_PER_SUBSTEP) ** (1.0 / dt)
        space.collision_bias = self._collision_bias
        # A plan of more than BULK_VERTICES walls gives pymunk only the walls near the robot
        # (creating a pymunk segment costs ~16 µs: 0.16 s for 10,000 walls at every reset).
        self._active_walls: dict[int, pymunk.Segment] | None = None
        if len(self._walls) > BULK_VERTICES:
            self._active_walls = {}
            self._active_centre = (math.inf, math.inf)
        elif len(self._walls):
            static, radius = space.static_body, config.wall_radius_m
            space.add(  # friction, elasticity, collision type and filter: pymunk's defaults
                *(
                    pymunk.Segment(static, (x0, y0), (x1, y1), radius)
                    for x0, y0, x1, y1 in self._walls.tolist()
                )
            )

        body = _DriveBody(
            _ROBOT_MASS_KG, pymunk.moment_for_circle(_ROBOT_MASS_KG, 0, config.radius_m)
        )
        body.linear_m_s = 0.0
        body.angular_rad_s = 0.0
        body.velocity_func = _kinematic_drive
        self._callback_on = True
        disc = pymunk.Circle(body, config.radius_m)
        disc.friction = 0.0
        disc.elasticity = 0.0
        disc.collision_type = _ROBOT_COLLISION_TYPE
        disc.filter = pymunk.ShapeFilter(categories=_ROBOT_CATEGORY)
        space.add(body, disc)
        space.on_collision(_ROBOT_COLLISION_TYPE, _WALL_COLLISION_TYPE, pre_solve=_record_contact)
        self._space = space
        self._body = body
        self._disc = disc
        self._odometry = (0.0, 0.0, 0.0)
        self._bumped = False
        self.reset(pose)

    # ------------------------------------------------------------------ state

    @property
    def config(self) -> RobotConfig:
        """The robot's configuration."""
        return self._config

    @property
    def wall_segments(self) -> np.ndarray:
        """The walls, shape (E, 4), read-only."""
        return self._walls

    @property
    def pose(self) -> Pose:
        """True pose ``(x, y, theta)``; theta wrapped to [-π, π]."""
        x, y, a = self._xya
        return Pose(x, y, _wrap(a))

    @property
    def odometry_pose(self) -> Pose:
        """Odometry estimate ``(x, y, theta)``; theta wrapped to [-π, π]."""
        x, y, theta = self._odometry
        return Pose(x, y, _wrap(theta))

    @property
    def bumped(self) -> bool:
        """Whether the robot touched a wall during the last step (False after `reset`)."""
        return self._bumped

    def reset(self, pose: Sequence[float]) -> Pose:
        """Teleport the robot to ``pose`` at rest; odometry restarts at the same pose.

        Args:
            pose: ``(x, y, theta_rad)``; the disc must not overlap a wall line.

        Returns:
            The new true pose (theta wrapped).

        Raises:
            ConfigError: pose not three finite numbers, or overlapping a wall.
        """
        x, y, theta = _parse_pose(pose, "pose")
        self._check_clearance(x, y)
        self._unsynced: tuple[float, ...] | None = None  # the body is set here
        body = self._body
        body.position = (x, y)
        body.angle = theta
        body.velocity = (0.0, 0.0)
        body.angular_velocity = 0.0
        body.linear_m_s = 0.0
        body.angular_rad_s = 0.0
        self._space.reindex_shapes_for_body(body)
        x, y = body.position
        self._xya = (x, y, body.angle)  # the body's state, read back once per step
        self._clearance = (x, y, -math.inf)  # nothing known: the next step asks pymunk
        self._refresh_active_walls(x, y)
        self._odometry = (x, y, theta)
        self._bumped = False
        return self.pose

    def carry_to(self, pose: Sequence[float]) -> Pose:
        """Move the robot to ``pose`` at rest as if carried there: its odometry does not see
        the move (a kidnapping). Raises ConfigError as :meth:`reset` does."""
        odometry = self._odometry
        self.reset(pose)
        self._odometry = odometry
        return self.pose

    # ------------------------------------------------------------------ motion

    def step(self, linear_m_s: float, angular_rad_s: float) -> StepResult:
        """Drive for one control period.

        Commands are clipped to ``±max_linear_speed_m_s`` and ``±max_angular_speed_rad_s``
        (infinities clip to the limit; negative speed drives backwards).

        Args:
            linear_m_s: forward speed command, m/s.
            angular_rad_s: turn-rate command, rad/s (counter-clockwise positive).

        Returns:
            The step's outcome (true pose, odometry pose, bump, distance, applied commands).

        Raises:
            ConfigError: a command is NaN or not a number.
        """
        cfg = self._config
        v = _command("linear_m_s", linear_m_s, cfg.max_linear_speed_m_s)
        w = _command("angular_rad_s", angular_rad_s, cfg.max_angular_speed_rad_s)
        body = self._body
        space = self._space
        x0, y0, a0 = self._xya
        self._refresh_active_walls(x0, y0)
        # The velocity callback runs after each substep's position update, so the first substep's
        # velocity is set here, with the part into walls that the robot touches removed.
        vx, vy = v * math.cos(a0), v * math.sin(a0)
        if self._bumped:
            self._sync_body()
            vx, vy = self._slide_along_contacts(vx, vy)
        dt = cfg.substep_s
        substeps = cfg.physics_substeps
        clear = False
        if self._open_space_shortcut:
            far = not self._may_touch_wall(x0, y0, abs(v) * cfg.control_period_s)
            if far or not self._bumped:
                # Without a contact, pymunk's substeps are chipmunk's position update alone
                # (cpBodyUpdatePosition; the velocity as _kinematic_drive sets it): done in the
                # same IEEE operations by drive_substeps, bit for bit what pymunk gives without
                # its cost (tests/world/test_robot.py). Far from walls no contact is possible;
                # nearer, none arises if the disc stays clear of every wall after each substep,
                # where chipmunk looks for contacts. (After a bump the first substep's velocity
                # is the slid one, which the callback would reset: pymunk then.)
                clear, x, y, a, end_vx, end_vy = drive_substeps(
                    x0, y0, a0, v, w, vx, vy, dt, substeps,
                    self._walls[:0] if far else self._walls, cfg.radius_m + cfg.wall_radius_m,
                )  # fmt: skip
        if clear:
            self._drive_by_callback(False)
            # pymunk's body is told only when it next matters (_sync_body): four attribute sets
            # through pymunk's Python layer cost more than the substeps
            self._unsynced = (x, y, a, end_vx, end_vy, w)
            bumped = False
            x1, y1, a1 = x, y, a  # what the body now holds, exactly
        else:
            # Re-insert the disc: pymunk keeps, between steps, cached contact impulses (it
            # warm-starts the next contact solve from them) and the disc's collision pairs in the
            # order they arose, and a pickle carries neither. Near walls every step starts from
            # what a fresh copy has, so a copy continues exactly.
            self._sync_body()
            space.remove(self._disc)
            space.add(self._disc)
            body.linear_m_s = v
            body.angular_rad_s = w
            body.velocity = (vx, vy)
            body.angular_velocity = w
            space.robot_touched = False
            space_step = space.step
            self._drive_by_callback(True)
            space.collision_bias = self._collision_bias
            for _ in range(substeps - 1):
                space_step(dt)
            # No overlap correction in the last substep: pymunk keeps that correction as a hidden
            # "bias velocity" for the next step, which a pickle would lose. Ending every control
            # step with none makes the state between steps complete, so a copy continues exactly.
            space.collision_bias = 1.0
            space_step(dt)
            bumped = space.robot_touched
            x1, y1 = body.position
            a1 = body.angle
        self._bumped = bumped
        self._xya = (x1, y1, a1)

        # Odometry: the true displacement in the robot's frame at the start of the step, plus noise.
        dx, dy = x1 - x0, y1 - y0
        c0, s0 = math.cos(a0), math.sin(a0)
        forward = c0 * dx + s0 * dy
        lateral = -s0 * dx + c0 * dy
        turn = a1 - a0
        distance = math.hypot(dx, dy)
        if self._noisy:
            assert self._rng is not None
            e_f, e_l, e_t = self._rng.standard_normal(3).tolist()
            trans_std = cfg.odometry_translation_std * distance
            forward += trans_std * e_f
            lateral += trans_std * e_l
            turn += cfg.odometry_heading_std_rad * e_t
        ox, oy, ot = self._odometry
        co, so = math.cos(ot), math.sin(ot)
        self._odometry = (
            ox + co * forward - so * lateral,
            oy + so * forward + co * lateral,
            ot + turn,
        )
        return StepResult(
            pose=Pose(x1, y1, _wrap(a1)),
            odometry_pose=self.odometry_pose,
            bumped=bumped,
            distance_m=distance,
            linear_m_s=v,
            angular_rad_s=w,
        )

    # ------------------------------------------------------------------ helpers

    #: Far from walls, integrate the substeps as chipmunk does instead of stepping pymunk (same
    #: result bit for bit, faster).
    _open_space_shortcut = True

    def _refresh_active_walls(self, x: float, y: float) -> None:
        """Bulk plans: once the robot could reach beyond the walls given to pymunk within one
        control step, give it those within ``ACTIVE_WALLS_RADIUS_M`` (or twice that reach) of the
        robot instead."""
        active = self._active_walls
        if active is None:
            return
        cfg = self._config
        reach = cfg.radius_m + cfg.max_linear_speed_m_s * cfg.control_period_s + _REACH_MARGIN_M
        within = max(ACTIVE_WALLS_RADIUS_M, 2.0 * reach)
        cx, cy = self._active_centre
        if math.hypot(x - cx, y - cy) + reach < within:
            return
        near = _point_segment_distances(np.array([x, y]), self._walls) < within
        # All out and the wanted back in index order: pymunk's static tree then depends on the
        # wanted walls alone, as in a copy unpickled from them, so that a copy continues exactly.
        if active:
            self._space.remove(*active.values())
        static, radius = self._space.static_body, cfg.wall_radius_m
        self._active_walls = active = {
            i: active.get(i) or pymunk.Segment(static, tuple(w[:2]), tuple(w[2:]), radius)
            for i, w in zip(np.flatnonzero(near).tolist(), self._walls[near].tolist(), strict=True)
        }
        if active:
            self._space.add(*active.values())
        self._active_centre = (x, y)
        self._clearance = (x, y, -math.inf)  # other walls now: ask pymunk again

    def _may_touch_wall(self, x: float, y: float, travel_m: float) -> bool:
        """Whether a wall lies within ``travel_m`` (plus a margin) of the robot's disc.

        pymunk's answer, asked less often: a query reaches ``_CLEARANCE_LOOKAHEAD_M`` further and
        keeps the nearest wall's distance (the clearance). A distance to a wall changes by at most
        the distance moved, so while the clearance minus the distance moved since exceeds the
        reach, no wall is within reach; closer calls ask pymunk again.
        """
        reach = self._config.radius_m + travel_m + _REACH_MARGIN_M
        qx, qy, clearance = self._clearance
        if clearance - math.hypot(x - qx, y - qy) - _CLEARANCE_ROUNDING_M >= reach:
            return False
        look = reach + _CLEARANCE_LOOKAHEAD_M
        nearest = self._space.point_query_nearest((x, y), look, _WALL_QUERY)
        clearance = look if nearest is None else nearest.distance
        self._clearance = (x, y, clearance)
        return clearance < reach  # pymunk returns walls nearer than its maximum distance

    def _sync_body(self) -> None:
        """Give pymunk's body the state the open-space shortcut left it (position, angle,
        velocities): before anything reads the body or steps pymunk. A copy carries the pending
        state with it and syncs when it needs to."""
        if self._unsynced is not None:
            x, y, a, vx, vy, w = self._unsynced
            body = self._body
            body.position = (x, y)
            body.angle = a
            body.velocity = (vx, vy)
            body.angular_velocity = w
            self._unsynced = None

    def _drive_by_callback(self, on: bool) -> None:
        """Switch the kinematic velocity callback on or off (off: pymunk keeps the velocity)."""
        if on != self._callback_on:
            self._body.velocity_func = _kinematic_drive if on else pymunk.Body.update_velocity
            self._callback_on = on

    def _slide_along_contacts(self, vx: float, vy: float) -> tuple[float, float]:
        """Remove from velocity (vx, vy) the components into the walls the disc overlaps now."""
        normals = []
        for info in self._space.shape_query(self._disc):
            if info.shape is not None and info.shape.collision_type == _WALL_COLLISION_TYPE:
                normals.append(tuple(info.contact_point_set.normal))
        for _ in range(2):
            for nx, ny in normals:
                into = vx * nx + vy * ny
                if into > 0.0:
                    vx, vy = vx - into * nx, vy - into * ny
        if any(vx * nx + vy * ny > 1e-12 for nx, ny in normals):
            return 0.0, 0.0  # wedged into a corner
        return vx, vy

    def _check_clearance(self, x: float, y: float) -> None:
        if len(self._walls) == 0:
            return
        dist = _point_segment_distances(np.array([x, y]), self._walls)
        i = int(np.argmin(dist))
        if dist[i] < self._config.radius_m:
            raise ConfigError(
                f"pose ({x:g}, {y:g}) puts the robot's centre {dist[i]:.4f} m from wall segment "
                f"{i} {self._walls[i].tolist()}, closer than its radius {self._config.radius_m} m"
            )

    def __repr__(self) -> str:
        x, y, theta = self.pose
        return (
            f"Robot(pose=({x:.3f}, {y:.3f}, {theta:.3f}), walls={len(self._walls)}, "
            f"bumped={self._bumped})"
        )


@njit(cache=True)
def nearest_wall_m(walls: np.ndarray, x: float, y: float) -> float:
    """Distance from (x, y) to the nearest wall segment's line (inf without walls)."""
    best = math.inf
    for e in range(walls.shape[0]):
        ax, ay, bx, by = walls[e, 0], walls[e, 1], walls[e, 2], walls[e, 3]
        dx, dy = bx - ax, by - ay
        len2 = dx * dx + dy * dy
        t = ((x - ax) * dx + (y - ay) * dy) / len2 if len2 > 0.0 else 0.0
        t = min(max(t, 0.0), 1.0)
        best = min(best, math.sqrt((x - ax - t * dx) ** 2 + (y - ay - t * dy) ** 2))
    return best


@njit(cache=True)
def drive_substeps(x, y, a, v, w, vx, vy, dt, substeps, walls, radii_m):
    """Chipmunk's position update over ``substeps`` contact-free substeps from pose (x, y, a) at
    velocity (vx, vy, w), the drive resetting (vx, vy) to ``v`` along the heading after each:
    ``(clear, x, y, a, vx, vy)``. ``clear``: after each substep the centre stayed farther than
    ``radii_m`` (the disc's and the walls' radii, where chipmunk finds a contact) plus a margin
    from every one of ``walls`` (only then is the result pymunk's)."""
    contact_m = radii_m + _CONTACT_MARGIN_M
    for i in range(substeps):
        if i and w != 0.0:
            vx, vy = v * math.cos(a), v * math.sin(a)
        x += (vx + 0.0) * dt
        y += (vy + 0.0) * dt
        a += (w + 0.0) * dt
        if walls.shape[0] and nearest_wall_m(walls, x, y) <= contact_m:
            return False, x, y, a, vx, vy
    return True, x, y, a, vx, vy


def _wrap(theta: float) -> float:
    """Wrap an angle to [-π, π]."""
    return math.remainder(theta, math.tau)


def _command(name: str, value: Any, limit: float) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ConfigError(f"{name} must be a real number, got {value!r}") from None
    if math.isnan(v):
        raise ConfigError(f"{name} is NaN")
    return min(max(v, -limit), limit)


def _parse_pose(pose: Any, name: str) -> tuple[float, float, float]:
    try:
        arr = np.asarray(pose, dtype=float)
    except (TypeError, ValueError):
        raise ConfigError(f"{name} must be (x, y, theta_rad) numbers, got {pose!r}") from None
    if arr.shape != (3,):
        raise ConfigError(f"{name} must be (x, y, theta_rad), got shape {arr.shape}")
    if not np.isfinite(arr).all():
        raise ConfigError(f"{name} must be finite, got {arr.tolist()}")
    x, y, theta = arr.tolist()
    return x, y, theta


def _parse_walls(walls: Any) -> np.ndarray:
    try:
        arr = np.array(walls, dtype=float)
    except (TypeError, ValueError):
        raise ConfigError("wall_segments must be a numeric array of shape (E, 4)") from None
    if arr.size == 0:
        return np.zeros((0, 4))
    if arr.ndim != 2 or arr.shape[1] != 4:
        raise ConfigError(
            f"wall_segments must have shape (E, 4) with rows [x0, y0, x1, y1], got {arr.shape}"
        )
    bad = ~np.isfinite(arr).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ConfigError(
            f"wall_segments has {int(bad.sum())} non-finite row(s); first: row {i} = "
            f"{arr[i].tolist()}"
        )
    return arr


def _point_segment_distances(p: np.ndarray, walls: np.ndarray) -> np.ndarray:
    """Distance from point ``p`` (2,) to each segment of ``walls`` (E, 4)."""
    a = walls[:, :2]
    d = walls[:, 2:] - a
    len2 = np.einsum("ij,ij->i", d, d)
    t = np.einsum("ij,ij->i", p - a, d) / np.where(len2 > 0.0, len2, 1.0)
    closest = a + np.clip(t, 0.0, 1.0)[:, None] * d
    return np.hypot(*(p - closest).T)
