"""Penalise moving some joints at all: how "expensive" the base is compared with the arm."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.tasks.base import Task


class DampingTask(Task):
    """Zero-velocity target for ``joints`` with weight ``weight``; the arm then does what it can first."""

    def __init__(self, joints: list[str], weight: float = 1.0) -> None:
        super().__init__(weight, gain=1.0)
        self.joints = joints
        self._zero = np.zeros(len(joints))
        self._selection: np.ndarray | None = None  # constant: built on first use

    def error(self, kinematics: RobotKinematics) -> np.ndarray:
        return self._zero

    def _fixed(self) -> tuple:
        return tuple(self.joints)

    def jacobian(self, kinematics: RobotKinematics) -> np.ndarray:
        if self._selection is None:
            self._selection = np.eye(len(kinematics.joints))[[kinematics.index(j) for j in self.joints]]
        return self._selection
