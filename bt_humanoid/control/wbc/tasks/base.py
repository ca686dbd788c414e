"""What every whole-body task answers: how far off it is, and how joint motion changes that."""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics


class Task(ABC):
    """A least-squares objective ``weight · ‖J Δq − gain · e‖²`` of the whole-body QP.

    ``error`` is target minus current, so a step of ``Δq`` with ``J Δq = e``
    would close the gap in one control step; ``gain`` (0, 1] closes a fraction
    of it per step, which keeps motion smooth.
    """

    def __init__(self, weight: float | np.ndarray = 1.0, gain: float = 1.0) -> None:
        self.weight = weight
        self.gain = gain

    @abstractmethod
    def error(self, kinematics: RobotKinematics) -> np.ndarray: ...

    @abstractmethod
    def jacobian(self, kinematics: RobotKinematics) -> np.ndarray: ...

    def objective(self, kinematics: RobotKinematics) -> tuple[np.ndarray, np.ndarray]:
        """(H, g) of this task's quadratic cost ½ Δqᵀ H Δq + gᵀ Δq."""
        jac = self.jacobian(kinematics)
        err = self.gain * self.error(kinematics)
        weight = np.broadcast_to(np.asarray(self.weight, dtype=float), err.shape)
        weighted = jac * weight[:, None]
        return jac.T @ weighted, -weighted.T @ err
