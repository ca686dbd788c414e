"""Drives the omnidirectional base to poses through its velocity actuators.

A goal is a world-frame pose (x, y, yaw). Ruckig plans a straight,
jerk-limited, phase-synchronised motion from the current commanded state to
rest at the goal; each control step the base actuators get the planned
velocity plus a proportional correction of the tracking error. A base that
falls far behind its plan is blocked: the goal fails and the base brakes.
"""

from __future__ import annotations

import math

import numpy as np
from ruckig import Trajectory

from bt_humanoid.control.base_motion import SpeedMonitoring
from bt_humanoid.control.motion import MotionHandle, plan_trajectory
from bt_humanoid.localisation.planar import PlanarLocalisation
from bt_humanoid.sim.robot_config import BaseConfig
from bt_humanoid.sim.robot_io import MujocoRobotIO

POSITION_GAIN = 2.0  # 1/s: velocity correction per metre (radian) of tracking error
BLOCKED_ERROR = 0.3  # m: a tracking error this large means something is in the way
SETTLE_TIMEOUT = 2.0  # s after the plan ends before a goal that has not arrived fails

# Braking is an emergency stop, not a smooth one: 4 × 0.8 m/s² = 3.2 m/s², reached in 50 ms. The robot (72 kg,
# centre of mass 0.42 m up and 6 cm ahead of the base centre, on a 0.3 m base) would tip forward at about
# 5.7 m/s² on a real floor (benchmarks/stop.py braking_margin); the actuators could give 800 N / 72 kg = 11 m/s².
BRAKE_ACCEL = 4.0  # × the base's acceleration limits when braking
BRAKE_JERK = 20.0  # × its jerk limits when braking


def wrap_angle(angle: float) -> float:
    """Angle in [-pi, pi)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


class BaseDriver(SpeedMonitoring):
    """Pose goals for the base, executed through velocity actuators (the wheeled robot's BaseMotion)."""

    def __init__(self, io: MujocoRobotIO, config: BaseConfig, localisation: PlanarLocalisation | None = None) -> None:
        self.io = io
        self.config = config
        self.localisation = localisation  # None: the pose is the planar joints' own (exact)
        joints = [config.joints[axis] for axis in ("x", "y", "yaw")]
        self.actuators = np.array([io.actuator(joint) for joint in joints])
        self.lag = np.array([io.velocity_lag(joint) for joint in joints])  # s; commands lead by lag × acceleration
        self.velocity = np.zeros(3)  # commanded (planned) velocity
        self.acceleration = np.zeros(3)
        self.reference = self.pose()
        self.handle: MotionHandle | None = None
        self.trajectory: Trajectory | None = None
        self.target = self.reference.copy()
        self.arrival = config.tolerance.position  # m: the goal counts as reached this near (move_to's tolerance)
        self.braking = False
        self.tracking = False  # following references streamed by the whole-body controller
        self.limiter = None  # slows planned motions near people and things sensed
        self.elapsed = 0.0  # s along the current plan: runs slower than the clock while the limiter slows it
        self.last_step = io.time
        self.planned_velocity = np.zeros(3)  # the plan's velocity at ``elapsed``, before the limiter's share
        self.held_since = None  # when the limiter stopped the plan
        self.speed_cap = config.limits.max_speed  # m/s: the mission's cap (safety: max_base_speed), set per run

    def capped(self, requested: float | None = None) -> float:
        """The speed a motion may plan for: what it asks (None: as fast as allowed) under the mission's cap and
        the base's limit. The one place the cap is applied: skills ask for speeds, the base decides."""
        return min(requested if requested is not None else math.inf, self.speed_cap, self.config.limits.max_speed)

    @property
    def time(self) -> float:
        return self.io.time

    def pose(self) -> np.ndarray:
        """(x, y, yaw) on the map: localisation's belief (or, without it, the planar joints' exact pose)."""
        if self.localisation is not None:
            return self.localisation.pose()
        return self.io.positions().copy()

    def speeds(self) -> np.ndarray:
        if self.localisation is not None:
            return self.localisation.from_wheels(self.io.velocities())
        return self.io.velocities().copy()

    def _drive(self, velocity: np.ndarray) -> None:
        """Command a velocity (vx, vy, yaw rate) on the map: the wheels carry it out in the base's frame."""
        if self.localisation is not None:
            velocity = self.localisation.to_wheels(velocity)
        self.io.command(self.actuators, velocity)

    def settled(self) -> bool:
        return True  # the planar joints stop where they are

    def move_to(
        self,
        x: float,
        y: float,
        yaw: float,
        max_speed: float | None = None,
        shortest_turn: bool = True,
        tolerance: float | None = None,
    ) -> MotionHandle:
        """Start driving to a world pose; returns the handle to poll.

        The base turns the short way to ``yaw`` unless ``shortest_turn`` is
        false: then ``yaw`` is taken literally (yaw + 2π spins a full turn).
        """
        if self.handle is not None:
            self.handle.fail("pre-empted by a newer goal")
        limits = self.config.limits
        speed = self.capped(max_speed)
        start = self.reference.copy()
        target = np.array([x, y, start[2] + wrap_angle(yaw - start[2]) if shortest_turn else yaw])
        distance = float(np.hypot(*(target[:2] - start[:2])))
        # per-axis limits shaped by the direction so the path stays straight and under the speed cap
        direction = np.abs(target[:2] - start[:2]) / distance if distance > 1e-6 else np.array([0.7, 0.7])
        direction = np.maximum(direction, 1e-3)
        linear = (speed, limits.max_accel, limits.max_jerk)
        angular = (limits.max_yaw_rate, limits.max_yaw_accel, limits.max_yaw_jerk)
        plan_limits = tuple(
            np.array([lin * direction[0], lin * direction[1], ang]) for lin, ang in zip(linear, angular, strict=False)
        )
        self.trajectory = plan_trajectory(start, self.velocity, self.acceleration, target, plan_limits, phase_sync=True)
        self._begin_plan()
        self.planned_velocity = self.velocity.copy()
        self.target = target
        self.arrival = self.config.tolerance.position if tolerance is None else tolerance
        self.braking = self.tracking = False
        self.handle = MotionHandle(f"driving {distance:.2f} m", on_cancel=lambda _: self.brake())
        return self.handle

    def track(self, reference: np.ndarray, velocity: np.ndarray) -> None:
        """Follow a streamed reference pose and velocity (one control step's worth); pre-empts any goal."""
        if self.handle is not None:
            self.handle.fail("pre-empted by a whole-body motion")
            self.handle = None
        self.trajectory, self.braking, self.tracking = None, False, True
        self.reference = np.array(reference, dtype=float)
        self.velocity = np.array(velocity, dtype=float)
        self.acceleration = np.zeros(3)

    def brake(self) -> None:
        """Cancel the goal and decelerate to rest under the base limits."""
        if self.handle is not None:
            self.handle.fail("halted: braking")
            self.handle = None
        self.tracking = False
        limits = self.config.limits
        plan_limits = (
            np.array([limits.max_speed, limits.max_speed, limits.max_yaw_rate]) * 1.5,
            np.array([limits.max_accel, limits.max_accel, limits.max_yaw_accel]) * BRAKE_ACCEL,
            np.array([limits.max_jerk, limits.max_jerk, limits.max_yaw_jerk]) * BRAKE_JERK,
        )
        self.reference = self.pose()
        self.trajectory = plan_trajectory(
            self.reference, self.velocity, self.acceleration, None, plan_limits, brake=True
        )
        self._begin_plan()
        self.braking = True

    def _begin_plan(self) -> None:
        self.elapsed, self.held_since, self.last_step = 0.0, None, self.io.time

    def step(self) -> None:
        """Sample the plan, correct the tracking error, command the actuators."""
        if self.localisation is not None:
            self.localisation.step()
        if self.tracking:
            error = self.reference - self.pose()
            error[2] = wrap_angle(error[2])
            self._drive(self.velocity + POSITION_GAIN * error)
            return
        if self.trajectory is None:
            self._drive(np.zeros(3))
            return
        now = self.io.time
        step, self.last_step = now - self.last_step, now
        # plan time runs at the share the limiter allows: the path stays, the pace drops (braking is never slowed)
        share = 1.0 if self.braking else self.allowed_share(self.planned_velocity)
        self.elapsed += share * step
        elapsed = self.elapsed
        position, velocity, acceleration = self.trajectory.at_time(min(elapsed, self.trajectory.duration))
        self.reference = np.array(position)
        self.planned_velocity = np.array(velocity)
        self.velocity = share * self.planned_velocity  # what is commanded: braking starts from it
        self.acceleration = share * np.array(acceleration)
        if self.braking:
            # velocity-only braking: no position correction, just ramp the command to zero
            self._drive(self.velocity + self.lag * self.acceleration)
            if elapsed >= self.trajectory.duration:
                self.trajectory, self.braking = None, False
                self.velocity[:] = 0.0
                self.acceleration[:] = 0.0
            return
        pose = self.pose()
        error = self.reference - pose
        error[2] = wrap_angle(error[2])
        self._drive(self.velocity + self.lag * self.acceleration + POSITION_GAIN * error)
        self._check_progress(pose, elapsed, share)

    def _check_progress(self, pose: np.ndarray, elapsed: float, share: float) -> None:
        handle = self.handle
        if handle is None:
            return
        held = self.held_too_long(share, self.io.time) if elapsed < self.trajectory.duration else None
        if held is not None:
            handle.fail(held)
            self.handle = None
            self.brake()
            return
        tracking = float(np.hypot(*(self.reference[:2] - pose[:2])))
        remaining = float(np.hypot(*(self.target[:2] - pose[:2])))
        yaw_error = abs(wrap_angle(self.target[2] - pose[2]))
        handle.feedback = f"{remaining:.2f} m to go, heading off by {math.degrees(yaw_error):.0f}°"
        if tracking > BLOCKED_ERROR:
            handle.fail(f"base blocked near ({pose[0]:.2f}, {pose[1]:.2f}): {tracking:.2f} m behind its plan")
            self.handle = None
            self.brake()
            return
        if elapsed < self.trajectory.duration:
            return
        if remaining < self.arrival and math.degrees(yaw_error) < self.config.tolerance.yaw_deg:
            handle.succeed(f"arrived within {remaining * 100:.1f} cm, {math.degrees(yaw_error):.1f}°")
            self.handle = None
        elif elapsed > self.trajectory.duration + SETTLE_TIMEOUT:
            handle.fail(f"stopped {remaining:.2f} m and {math.degrees(yaw_error):.0f}° from the goal")
            self.handle = None
            self.brake()
