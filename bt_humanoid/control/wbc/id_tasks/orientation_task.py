"""Hold a body upright (or turned to a heading): the pelvis and the torso."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from bt_humanoid.control.wbc.dynamics import RobotDynamics
from bt_humanoid.control.wbc.id_tasks.base import AccelerationTask


class OrientationTask(AccelerationTask):
    """ω̇* = K_p log(R_ref Rᵀ) + K_d (ω_ref − ω) for ``frame``, world axes; ``target`` is R_ref."""

    def __init__(self, frame: str, weight: float | np.ndarray = 10.0, kp: float = 100.0, kd: float = 20.0) -> None:
        super().__init__(weight)
        self.frame = frame
        self.kp = kp
        self.kd = kd
        self.target = np.eye(3)
        self.angular_velocity = np.zeros(3)

    def jacobian(self, dynamics: RobotDynamics) -> np.ndarray:
        return dynamics.jacobian(self.frame)[3:]

    def drift(self, dynamics: RobotDynamics) -> np.ndarray:
        return dynamics.drift(self.frame)[3:]

    def error(self, dynamics: RobotDynamics) -> np.ndarray:
        """The world-frame rotation vector that turns the frame onto its target."""
        return pin.log3(self.target @ dynamics.pose(self.frame).rotation.T)

    def desired(self, dynamics: RobotDynamics) -> np.ndarray:
        omega = self.jacobian(dynamics) @ dynamics.v
        return self.kp * self.error(dynamics) + self.kd * (self.angular_velocity - omega)
