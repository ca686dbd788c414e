"""Joint position references for every position-controlled joint.

One reference state (position, velocity, acceleration) per joint feeds the
MuJoCo position actuators. Goals move subsets of joints along Ruckig
trajectories; a new goal on a joint pre-empts the older one; braking brings
every reference to rest under the joints' limits.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from ruckig import Trajectory

from bt_humanoid.control.motion import MotionHandle, plan_trajectory
from bt_humanoid.sim.robot_config import RobotConfig
from bt_humanoid.sim.robot_io import MujocoRobotIO

SETTLE_TOLERANCE = 0.03  # rad (or m for fingers): tracking error that counts as arrived
SETTLE_TIMEOUT = 1.0  # s after the trajectory ends before a goal fails

BRAKE_SCALE = (1.0, 3.0, 8.0)  # velocity, acceleration, jerk limits × this when braking: stop fast, not smooth


@dataclass
class _Goal:
    handle: MotionHandle
    joints: np.ndarray  # indices into the controller's joint list
    trajectory: Trajectory
    start: float
    target: np.ndarray | None  # None when braking
    settle_check: bool = True
    stall: dict = field(default_factory=dict)
    tolerance: float = SETTLE_TOLERANCE  # rad (m) of tracking error that counts as arrived


class JointReferenceController:
    """Jerk-limited joint references for the arms, waist, head and fingers."""

    def __init__(self, io: MujocoRobotIO, config: RobotConfig, driven: list[str] | None = None) -> None:
        self.io = io
        self.joints = io.joints
        self.actuators = np.array([io.actuator(j) for j in self.joints])
        # the joints whose servos take these references; the others' (a walking robot's upper body) take the
        # balance controller's targets, which follow these references as its posture task
        self._driven = np.arange(len(self.joints)) if driven is None else self.indices(list(driven))
        self.limits = tuple(
            np.array([getattr(config.motion_limits(j), kind) for j in self.joints])
            for kind in ("velocity", "acceleration", "jerk")
        )
        self.position = io.positions().copy()
        self.velocity = np.zeros(len(self.joints))
        self.acceleration = np.zeros(len(self.joints))
        self.goals: list[_Goal] = []
        self.feedforward = np.zeros(len(self.joints))  # rad (m) added to the targets sent (inertial_feedforward)
        # fingers squeeze what they hold by pressing past it: braking them to where they are would let go
        self._arm_like = np.array([j not in config.finger_joints for j in self.joints])

    def indices(self, joints: list[str]) -> np.ndarray:
        return np.array([self.io.index(j) for j in joints], dtype=int)

    def move(
        self,
        targets: dict[str, float],
        speed_scale: float = 1.0,
        settle_check: bool = True,
        tolerance: float = SETTLE_TOLERANCE,
    ) -> MotionHandle:
        """Start moving ``targets`` (joint → position); returns the handle to poll. It arrives when every joint
        is within ``tolerance`` (rad, or m) of its target."""
        idx = self.indices(list(targets))
        goal_q = np.clip(np.array(list(targets.values()), dtype=float), self.io.lower[idx], self.io.upper[idx])
        handle = MotionHandle(f"moving {len(idx)} joint{'s' if len(idx) != 1 else ''}", on_cancel=self._cancelled)
        self._preempt(idx, "pre-empted by a newer goal")
        scales = (speed_scale, speed_scale, 1.0)  # velocity and acceleration scale; jerk stays
        limits = tuple(limit[idx] * scale for limit, scale in zip(self.limits, scales, strict=True))
        trajectory = plan_trajectory(
            self.position[idx], self.velocity[idx], self.acceleration[idx], goal_q, limits, phase_sync=False
        )
        self.goals.append(_Goal(handle, idx, trajectory, self.io.time, goal_q, settle_check, tolerance=tolerance))
        return handle

    def track(self, joints: np.ndarray, position: np.ndarray, velocity: np.ndarray) -> None:
        """Set references for ``joints`` directly (streamed each control step); pre-empts their goals."""
        self._preempt(joints, "pre-empted by a whole-body motion")
        self.position[joints] = np.clip(position, self.io.lower[joints], self.io.upper[joints])
        self.velocity[joints] = velocity
        self.acceleration[joints] = 0.0

    def brake(self, joints: np.ndarray | None = None) -> None:
        """Cancel goals and bring references (all, or ``joints``) to rest as fast as the limits allow."""
        idx = np.arange(len(self.joints)) if joints is None else joints
        self._preempt(idx, "halted: braking")
        velocities = self.io.velocities()
        commanded = np.abs(self.velocity[idx]) + np.abs(self.acceleration[idx]) > 1e-9
        moving = idx[commanded | (self._arm_like[idx] & (np.abs(velocities[idx]) > 1e-3))]
        if len(moving) == 0:
            return
        # from where the joints are, not where their references were: a lagging joint then stops where it is
        # instead of catching up with a reference that stopped ahead of it (fingers keep their reference)
        measured = self._arm_like[moving]
        trajectory = plan_trajectory(
            np.where(measured, self.io.positions()[moving], self.position[moving]),
            np.where(measured, velocities[moving], self.velocity[moving]),
            np.where(measured, 0.0, self.acceleration[moving]),
            None,
            tuple(limit[moving] * scale for limit, scale in zip(self.limits, BRAKE_SCALE, strict=True)),
            brake=True,
        )
        self.goals.append(_Goal(MotionHandle("braking"), moving, trajectory, self.io.time, None, False))

    def step(self) -> None:
        """Advance every goal to the current time and command the actuators."""
        now = self.io.time
        measured = self.io.positions()
        for goal in list(self.goals):
            elapsed = now - goal.start
            position, velocity, acceleration = goal.trajectory.at_time(min(elapsed, goal.trajectory.duration))
            self.position[goal.joints] = position
            self.velocity[goal.joints] = velocity
            self.acceleration[goal.joints] = acceleration
            if elapsed < goal.trajectory.duration:
                goal.handle.feedback = f"{goal.handle.description}: {elapsed:.1f}/{goal.trajectory.duration:.1f} s"
                continue
            self.velocity[goal.joints] = 0.0
            self.acceleration[goal.joints] = 0.0
            self._finish(goal, measured, elapsed)
        driven = self._driven
        self.io.command(self.actuators[driven], (self.position + self.feedforward)[driven])

    def _finish(self, goal: _Goal, measured: np.ndarray, elapsed: float) -> None:
        if goal.target is None or not goal.settle_check:
            goal.handle.succeed("at rest" if goal.target is None else "reference reached")
            self.goals.remove(goal)
            return
        error = np.abs(measured[goal.joints] - goal.target)
        if np.all(error < goal.tolerance):
            goal.handle.succeed("arrived")
            self.goals.remove(goal)
        elif elapsed > goal.trajectory.duration + SETTLE_TIMEOUT:
            worst = int(np.argmax(error))
            joint = self.joints[goal.joints[worst]]
            goal.handle.fail(
                f"joint {joint} stuck at {measured[goal.joints[worst]]:.3f} (target {goal.target[worst]:.3f}); blocked?"
            )
            self.goals.remove(goal)
            self.brake(goal.joints)

    def _preempt(self, idx: np.ndarray, reason: str) -> None:
        for goal in list(self.goals):
            if np.intersect1d(goal.joints, idx).size:
                goal.handle.fail(reason)
                self.goals.remove(goal)

    def _cancelled(self, handle: MotionHandle) -> None:
        for goal in list(self.goals):
            if goal.handle is handle:
                self.goals.remove(goal)
                self.brake(goal.joints)
