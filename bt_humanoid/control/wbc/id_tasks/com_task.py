"""Move the centre of mass: the balance task, through which the whole body's weight is carried and shifted."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.dynamics import RobotDynamics
from bt_humanoid.control.wbc.id_tasks.base import AccelerationTask


class ComTask(AccelerationTask):
    """c̈* = c̈_ref + K_p (c_ref − c) + K_d (ċ_ref − ċ), gains per axis (x, y, z).

    A balance law that asks for a centre-of-mass acceleration directly (the LIPM's ω² (c − p_cmd) for a commanded
    ZMP) sets the reference acceleration and zero gains.
    """

    def __init__(
        self,
        weight: float | np.ndarray = 100.0,
        kp: float | np.ndarray = 0.0,
        kd: float | np.ndarray = 0.0,
    ) -> None:
        super().__init__(weight)
        self.kp = np.broadcast_to(np.asarray(kp, dtype=float), (3,)).copy()
        self.kd = np.broadcast_to(np.asarray(kd, dtype=float), (3,)).copy()
        self.position = np.zeros(3)
        self.velocity = np.zeros(3)
        self.acceleration = np.zeros(3)

    def set_target(
        self, position: np.ndarray, velocity: np.ndarray | None = None, acceleration: np.ndarray | None = None
    ) -> None:
        self.position = np.asarray(position, dtype=float).copy()
        self.velocity = np.zeros(3) if velocity is None else np.asarray(velocity, dtype=float).copy()
        self.acceleration = np.zeros(3) if acceleration is None else np.asarray(acceleration, dtype=float).copy()

    def jacobian(self, dynamics: RobotDynamics) -> np.ndarray:
        return dynamics.com_jacobian

    def drift(self, dynamics: RobotDynamics) -> np.ndarray:
        return dynamics.com_drift

    def desired(self, dynamics: RobotDynamics) -> np.ndarray:
        return (
            self.acceleration
            + self.kp * (self.position - dynamics.com)
            + self.kd * (self.velocity - dynamics.com_velocity)
        )
