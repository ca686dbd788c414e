"""Move a frame along a path in position and orientation: the swinging foot."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from bt_humanoid.control.wbc.dynamics import RobotDynamics
from bt_humanoid.control.wbc.id_tasks.base import AccelerationTask


class FrameTask(AccelerationTask):
    """a* = a_ref + K_p e + K_d (v_ref − v) for ``frame``'s origin and orientation, world axes.

    e is the position error and the rotation vector log(R_ref Rᵀ); the reference is a pose (an ``SE3``) with its
    twist and acceleration (linear; angular, 6-vectors).
    """

    def __init__(
        self,
        frame: str,
        weight: float | np.ndarray = 30.0,
        kp: float | np.ndarray = 400.0,
        kd: float | np.ndarray = 40.0,
    ) -> None:
        super().__init__(weight)
        self.frame = frame
        self.kp = np.broadcast_to(np.asarray(kp, dtype=float), (6,)).copy()
        self.kd = np.broadcast_to(np.asarray(kd, dtype=float), (6,)).copy()
        self.target = pin.SE3.Identity()
        self.velocity = np.zeros(6)
        self.acceleration = np.zeros(6)

    def set_target(
        self, pose: pin.SE3, velocity: np.ndarray | None = None, acceleration: np.ndarray | None = None
    ) -> None:
        self.target = pose
        self.velocity = np.zeros(6) if velocity is None else np.asarray(velocity, dtype=float)
        self.acceleration = np.zeros(6) if acceleration is None else np.asarray(acceleration, dtype=float)

    def jacobian(self, dynamics: RobotDynamics) -> np.ndarray:
        return dynamics.jacobian(self.frame)

    def drift(self, dynamics: RobotDynamics) -> np.ndarray:
        return dynamics.drift(self.frame)

    def error(self, dynamics: RobotDynamics) -> np.ndarray:
        """(position; rotation vector), world axes: what moves the frame onto its target."""
        pose = dynamics.pose(self.frame)
        return np.concatenate(
            [self.target.translation - pose.translation, pin.log3(self.target.rotation @ pose.rotation.T)]
        )

    def desired(self, dynamics: RobotDynamics) -> np.ndarray:
        twist = self.jacobian(dynamics) @ dynamics.v
        return self.acceleration + self.kp * self.error(dynamics) + self.kd * (self.velocity - twist)
