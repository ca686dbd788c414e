"""Put a robot frame (a hand's grip site) at a target pose in the world."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.maths import Value, concat, log3
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

    def error(self, kinematics: RobotKinematics) -> Value:
        # the target moves along the reach every control step
        target_position = kinematics.parameter(lambda: self.target.translation, (3, 1), moving=True)
        target_rotation = kinematics.parameter(lambda: self.target.rotation, (3, 3), moving=True)
        position = target_position - kinematics.position(self.frame)
        # rotation that takes the current orientation to the target, as a world-frame rotation vector
        orientation = log3(target_rotation @ kinematics.rotation(self.frame).T)
        return concat([position, orientation])

    def _fixed(self) -> tuple:
        return (self.frame,)

    def jacobian(self, kinematics: RobotKinematics) -> Value:
        return kinematics.jacobian(self.frame)
