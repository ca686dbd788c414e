"""Actuator torque limits: |τ_j| ≤ τ_max,j for the joints a controller drives."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.dynamics import RobotDynamics


class TorqueLimit:
    """Joint → its actuator's torque (N·m) or force (N) limit; the QP bounds τ = M_a v̇ + h_a − J_aᵀ w by it."""

    def __init__(self, limits: dict[str, float]) -> None:
        self.limits = dict(limits)
        self.joints = list(limits)
        self.maximum = np.array(list(limits.values()), dtype=float)
        self._columns: np.ndarray | None = None

    def columns(self, dynamics: RobotDynamics) -> np.ndarray:
        """Their columns in v (rows of the equations of motion)."""
        if self._columns is None:
            self._columns = np.array([dynamics.joint_index(joint) for joint in self.joints], dtype=int)
        return self._columns
