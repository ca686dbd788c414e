"""Handles for motions in progress: skills send a goal, keep the handle and poll it."""

from __future__ import annotations

from collections.abc import Callable
from enum import Enum

import numpy as np
from ruckig import ControlInterface, InputParameter, Result, Ruckig, Synchronization, Trajectory

REST_SPEED = 0.01  # m/s or rad/s: below this everywhere, the robot is at rest; a motion has arrived once its
# joints are on target and this slow (a skill that reports done while its arm still swings leaves a tree that
# finishes moving)


class MotionStatus(Enum):
    RUNNING = "running"
    SUCCEEDED = "succeeded"
    FAILED = "failed"
    CANCELLED = "cancelled"


class MotionHandle:
    """The state of one motion goal, shared between a controller and the skill that sent it."""

    def __init__(self, description: str, on_cancel: Callable[[MotionHandle], None] | None = None) -> None:
        self.description = description
        self.status = MotionStatus.RUNNING
        self.feedback = description
        self.result: str = ""
        self._on_cancel = on_cancel

    @property
    def done(self) -> bool:
        return self.status is not MotionStatus.RUNNING

    def succeed(self, result: str = "") -> None:
        if not self.done:
            self.status, self.result = MotionStatus.SUCCEEDED, result

    def fail(self, reason: str) -> None:
        if not self.done:
            self.status, self.result = MotionStatus.FAILED, reason

    def cancel(self) -> None:
        """Stop this motion; the controller brakes whatever it was moving."""
        if self.done:
            return
        self.status, self.result = MotionStatus.CANCELLED, "cancelled"
        if self._on_cancel is not None:
            self._on_cancel(self)


def plan_trajectory(
    position: np.ndarray,
    velocity: np.ndarray,
    acceleration: np.ndarray,
    target: np.ndarray,
    limits: tuple[np.ndarray, np.ndarray, np.ndarray],
    *,
    brake: bool = False,
    phase_sync: bool = False,
) -> Trajectory:
    """A jerk-limited Ruckig trajectory from a state to rest at ``target`` (or to rest anywhere if ``brake``)."""
    dofs = len(position)
    inp = InputParameter(dofs)
    inp.current_position = position.tolist()
    inp.current_velocity = velocity.tolist()
    inp.current_acceleration = acceleration.tolist()
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = (limit.tolist() for limit in limits)
    if brake:
        inp.control_interface = ControlInterface.Velocity
        inp.target_velocity = [0.0] * dofs
    else:
        inp.target_position = target.tolist()
    if phase_sync:
        inp.synchronization = Synchronization.Phase
    trajectory = Trajectory(dofs)
    result = Ruckig(dofs).calculate(inp, trajectory)
    if result not in (Result.Working, Result.Finished):
        raise ValueError(f"trajectory generation failed: {result}")
    return trajectory
