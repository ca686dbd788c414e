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

    def residual(self, kinematics: RobotKinematics) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(J, gain · e, per-row weight): the rows this task adds to the stacked least-squares problem."""
        err = self.gain * self.error(kinematics)
        weight = self.weight if isinstance(self.weight, np.ndarray) else np.full(len(err), float(self.weight))
        return self.jacobian(kinematics), err, weight

    def objective(self, kinematics: RobotKinematics) -> tuple[np.ndarray, np.ndarray]:
        """(H, g) of this task's quadratic cost ½ Δqᵀ H Δq + gᵀ Δq."""
        return stacked_objective([self.residual(kinematics)])


def stacked_objective(residuals: list[tuple[np.ndarray, np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """(H, g) of the sum of several tasks' costs, from their rows stacked into one Jacobian: two matrix products
    for all of them rather than two each."""
    jac = np.vstack([r[0] for r in residuals])
    err = np.concatenate([r[1] for r in residuals])
    weighted = jac * np.concatenate([r[2] for r in residuals])[:, None]
    return jac.T @ weighted, -weighted.T @ err
