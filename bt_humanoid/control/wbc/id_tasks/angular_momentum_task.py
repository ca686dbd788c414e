"""Damp the whole body's angular momentum about its centre of mass: what the hip strategy builds, it gives back."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.dynamics import RobotDynamics
from bt_humanoid.control.wbc.id_tasks.base import AccelerationTask


class AngularMomentumTask(AccelerationTask):
    """L̇* = −K_L L (world axes, about the centre of mass)."""

    def __init__(self, weight: float | np.ndarray = 1.0, gain: float = 10.0) -> None:
        super().__init__(weight)
        self.gain = gain

    def jacobian(self, dynamics: RobotDynamics) -> np.ndarray:
        return dynamics.centroidal_map[3:]

    def drift(self, dynamics: RobotDynamics) -> np.ndarray:
        return dynamics.centroidal_drift[3:]

    def desired(self, dynamics: RobotDynamics) -> np.ndarray:
        return -self.gain * dynamics.centroidal_momentum[3:]
