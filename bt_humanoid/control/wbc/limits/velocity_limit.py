"""Joint speed limits: how far each joint may move in one control step."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.maths import Value


class VelocityLimit:
    """Box bounds |Δq| ≤ v_max · dt."""

    def __init__(self, max_velocity: np.ndarray) -> None:
        self.max_velocity = np.asarray(max_velocity, dtype=float)

    def signature(self) -> tuple:
        return (type(self).__qualname__,)

    def bounds(self, kinematics: RobotKinematics, dt: float) -> tuple[Value, Value]:
        speed = kinematics.parameter(lambda: self.max_velocity, (len(self.max_velocity), 1))  # frozen joints: 0
        return -speed * dt, speed * dt
