"""Put a robot frame (a hand's grip site) at a target pose in the world."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.tasks.base import Task


class FrameTask(Task):
    """Position and orientation of ``frame``; weights are [position ×3, orientation ×3]."""

    def __init__(
        self,
        frame: str,
        target: pin.SE3,
        position_weight: float = 1.0,
        orientation_weight: float = 0.3,
        gain: float = 0.5,
    ) -> None:
        super().__init__(np.array([position_weight] * 3 + [orientation_weight] * 3), gain)
        self.frame = frame
        self.target = target

    def error(self, kinematics: RobotKinematics) -> np.ndarray:
        current = kinematics.pose(self.frame)
        position = self.target.translation - current.translation
        # rotation that takes the current orientation to the target, as a world-frame rotation vector
        orientation = pin.log3(self.target.rotation @ current.rotation.T)
        return np.concatenate([position, orientation])

    def jacobian(self, kinematics: RobotKinematics) -> np.ndarray:
        return kinematics.jacobian(self.frame)
