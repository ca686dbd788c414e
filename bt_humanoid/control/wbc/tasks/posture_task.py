"""Keep joints near a posture: a low-weight pull that resolves redundancy."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.tasks.base import Task


class PostureTask(Task):
    """Joint-space target ``posture`` (joint → position) for the joints it names."""

    def __init__(self, posture: dict[str, float], weight: float = 1e-2, gain: float = 0.1) -> None:
        super().__init__(weight, gain)
        self.posture = posture

    def _rows(self, kinematics: RobotKinematics) -> np.ndarray:
        return np.array([kinematics.index(joint) for joint in self.posture], dtype=int)

    def error(self, kinematics: RobotKinematics) -> np.ndarray:
        current = kinematics.positions[self._rows(kinematics)]
        return np.array(list(self.posture.values())) - current

    def jacobian(self, kinematics: RobotKinematics) -> np.ndarray:
        return np.eye(len(kinematics.joints))[self._rows(kinematics)]
