"""Point a camera's optical axis at a point in the world."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.tasks.base import Task


class GazeTask(Task):
    """Align the camera's viewing direction (its -z axis) with the direction to ``target``.

    Rolling about the optical axis does not change what is seen, so that
    component of the error and of the Jacobian is projected out.
    """

    def __init__(self, camera: str, target: np.ndarray, weight: float = 0.5, gain: float = 0.3) -> None:
        super().__init__(weight, gain)
        self.camera = camera
        self.target = np.asarray(target, dtype=float)

    def _axes(self, kinematics: RobotKinematics) -> tuple[np.ndarray, np.ndarray]:
        pose = kinematics.pose(self.camera)
        axis = -pose.rotation[:, 2]
        to_target = self.target - pose.translation
        return axis, to_target / max(float(np.linalg.norm(to_target)), 1e-6)

    def error(self, kinematics: RobotKinematics) -> np.ndarray:
        axis, direction = self._axes(kinematics)
        return pin.skew(axis) @ direction  # axis × direction (np.cross costs ten times more on 3-vectors)

    def off_axis(self, kinematics: RobotKinematics) -> float:
        """Angle (rad) between the optical axis and the direction to the target: 0 centred, π behind."""
        axis, direction = self._axes(kinematics)
        return float(np.arctan2(np.linalg.norm(pin.skew(axis) @ direction), axis @ direction))

    def jacobian(self, kinematics: RobotKinematics) -> np.ndarray:
        axis, _ = self._axes(kinematics)
        across = np.eye(3) - np.outer(axis, axis)
        return across @ kinematics.jacobian(self.camera)[3:]
