"""Point a camera's optical axis at a point in the world."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.maths import Value, cross, identity, maximum, norm, outer
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

    def _axes(self, kinematics: RobotKinematics) -> tuple[Value, Value]:
        axis = -kinematics.rotation(self.camera)[:, 2]
        to_target = kinematics.parameter(lambda: self.target, (3, 1)) - kinematics.position(self.camera)
        return axis, to_target / maximum(norm(to_target), 1e-6)

    def error(self, kinematics: RobotKinematics) -> Value:
        axis, direction = self._axes(kinematics)
        return cross(axis, direction)

    def off_axis(self, kinematics: RobotKinematics) -> float:
        """Angle (rad) between the optical axis and the direction to the target: 0 centred, π behind."""
        axis, direction = self._axes(kinematics)
        return float(np.arctan2(np.linalg.norm(cross(axis, direction)), axis @ direction))

    def _fixed(self) -> tuple:
        return (self.camera,)

    def jacobian(self, kinematics: RobotKinematics) -> Value:
        axis, _ = self._axes(kinematics)
        across = identity(3, axis) - outer(axis, axis)
        return across @ kinematics.jacobian(self.camera)[3:, :]
