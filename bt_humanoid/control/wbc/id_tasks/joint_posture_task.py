"""Keep joints near a posture: the upper body's references, and the legs' redundancy."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.dynamics import RobotDynamics
from bt_humanoid.control.wbc.id_tasks.base import AccelerationTask


class JointPostureTask(AccelerationTask):
    """q̈* = q̈_ref + K_p (q_ref − q) + K_d (q̇_ref − q̇) for the joints ``posture`` names."""

    def __init__(self, posture: dict[str, float], weight: float = 1.0, kp: float = 100.0, kd: float = 20.0) -> None:
        super().__init__(weight)
        self.joints = list(posture)
        self.kp = kp
        self.kd = kd
        self.position = np.array(list(posture.values()), dtype=float)
        self.velocity = np.zeros(len(self.joints))
        self.acceleration = np.zeros(len(self.joints))
        self._columns: np.ndarray | None = None
        self._selection: np.ndarray | None = None  # constant: built on first use
        self._zero = np.zeros(len(self.joints))

    def set_target(
        self, position: np.ndarray, velocity: np.ndarray | None = None, acceleration: np.ndarray | None = None
    ) -> None:
        """References in ``joints`` order (a streamed trajectory: position, velocity, acceleration)."""
        n = len(self.joints)
        self.position = np.asarray(position, dtype=float).copy()
        self.velocity = np.zeros(n) if velocity is None else np.asarray(velocity, dtype=float).copy()
        self.acceleration = np.zeros(n) if acceleration is None else np.asarray(acceleration, dtype=float).copy()

    def columns(self, dynamics: RobotDynamics) -> np.ndarray:
        if self._columns is None:
            self._columns = np.array([dynamics.joint_index(joint) for joint in self.joints])
        return self._columns

    def jacobian(self, dynamics: RobotDynamics) -> np.ndarray:
        if self._selection is None:
            self._selection = np.eye(dynamics.nv)[self.columns(dynamics)]
        return self._selection

    def drift(self, dynamics: RobotDynamics) -> np.ndarray:
        return self._zero

    def desired(self, dynamics: RobotDynamics) -> np.ndarray:
        columns = self.columns(dynamics)
        q = dynamics.q[columns + 1]  # the free-flyer has one more coordinate (its quaternion) than rates
        v = dynamics.v[columns]
        return self.acceleration + self.kp * (self.position - q) + self.kd * (self.velocity - v)
