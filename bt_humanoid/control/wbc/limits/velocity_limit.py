"""Joint speed limits: how far each joint may move in one control step."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics


class VelocityLimit:
    """Box bounds |Δq| ≤ v_max · dt."""

    def __init__(self, max_velocity: np.ndarray) -> None:
        self.max_velocity = np.asarray(max_velocity, dtype=float)

    def bounds(self, kinematics: RobotKinematics, dt: float) -> tuple[np.ndarray, np.ndarray]:
        return -self.max_velocity * dt, self.max_velocity * dt
