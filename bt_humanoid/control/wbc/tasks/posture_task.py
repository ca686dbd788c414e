"""Keep joints near a posture: a low-weight pull that resolves redundancy."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.maths import Value
from bt_humanoid.control.wbc.tasks.base import Task


class PostureTask(Task):
    """Joint-space target ``posture`` (joint → position) for the joints it names."""

    def __init__(self, posture: dict[str, float], weight: float = 1e-2, gain: float = 0.1) -> None:
        super().__init__(weight, gain)
        self.posture = posture
        self.target = np.array(list(posture.values()), dtype=float)
        # constant: built on first use, the control loop reuses them
        self._columns: np.ndarray | None = None  # the posture's joints among the controlled ones
        self._selection: np.ndarray | None = None  # its Jacobian: one row per joint, a 1 in that joint's column

    def _select(self, kinematics: RobotKinematics) -> tuple[np.ndarray, np.ndarray]:
        if self._columns is None or self._selection is None:
            self._columns = np.array([kinematics.index(joint) for joint in self.posture], dtype=int)
            self._selection = np.eye(len(kinematics.joints))[self._columns]
        return self._columns, self._selection

    def error(self, kinematics: RobotKinematics) -> Value:
        target = kinematics.parameter(lambda: self.target, (len(self.target), 1))
        return target - kinematics.positions[self._select(kinematics)[0]]

    def _fixed(self) -> tuple:
        return tuple(self.posture)

    def jacobian(self, kinematics: RobotKinematics) -> np.ndarray:
        return self._select(kinematics)[1]
