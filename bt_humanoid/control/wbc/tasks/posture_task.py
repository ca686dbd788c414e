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
        self.target = np.array(list(posture.values()), dtype=float)
        self._selection: np.ndarray | None = None  # constant: built on first use, the control loop reuses it

    def _select(self, kinematics: RobotKinematics) -> np.ndarray:
        if self._selection is None:
            rows = [kinematics.index(joint) for joint in self.posture]
            self._selection = np.eye(len(kinematics.joints))[rows]
        return self._selection

    def error(self, kinematics: RobotKinematics) -> np.ndarray:
        return self.target - self._select(kinematics) @ kinematics.positions

    def jacobian(self, kinematics: RobotKinematics) -> np.ndarray:
        return self._select(kinematics)
