"""What every whole-body task answers: how far off it is, and how joint motion changes that."""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.maths import Value, concat, scale_rows, stack_rows


class Task(ABC):
    """A least-squares objective ``weight · ‖J Δq − gain · e‖²`` of the whole-body QP.

    ``error`` is target minus current, so a step of ``Δq`` with ``J Δq = e``
    would close the gap in one control step; ``gain`` (0, 1] closes a fraction
    of it per step, which keeps motion smooth.

    Both are written with ``maths``' operations, so they work on a
    ``RobotKinematics`` (numbers) and on a ``SymbolicKinematics`` (CasADi
    symbols, from which the whole-body controller compiles its QP once per
    kind of goal). The numbers that differ between goals of one signature, or
    move during one, are read through ``kinematics.parameter``.
    """

    def __init__(self, weight: float | np.ndarray = 1.0, gain: float = 1.0) -> None:
        self.weight = weight
        self.gain = gain

    @abstractmethod
    def error(self, kinematics: RobotKinematics) -> Value: ...

    @abstractmethod
    def jacobian(self, kinematics: RobotKinematics) -> Value: ...

    def residual(self, kinematics: RobotKinematics) -> tuple[Value, Value, np.ndarray]:
        """(J, gain · e, per-row weight): the rows this task adds to the stacked least-squares problem."""
        err = self.gain * self.error(kinematics)
        weight = self.weight if isinstance(self.weight, np.ndarray) else np.full(err.shape[0], float(self.weight))
        return self.jacobian(kinematics), err, weight

    def signature(self) -> tuple:
        """What a compiled QP fixes of this task: two tasks of one signature differ only in the numbers they
        read through ``kinematics.parameter`` (a goal like an earlier one reuses its compiled QP)."""
        return (type(self).__name__, tuple(np.atleast_1d(self.weight).tolist()), self.gain, *self._fixed())

    def _fixed(self) -> tuple:
        """The task's own part of its signature: its frames and joints."""
        return ()

    def objective(self, kinematics: RobotKinematics) -> tuple[Value, Value]:
        """(H, g) of this task's quadratic cost ½ Δqᵀ H Δq + gᵀ Δq."""
        return stacked_objective([self.residual(kinematics)])


def stacked_objective(residuals: list[tuple[Value, Value, np.ndarray]]) -> tuple[Value, Value]:
    """(H, g) of the sum of several tasks' costs, from their rows stacked into one Jacobian: two matrix products
    for all of them rather than two each."""
    jac = stack_rows([r[0] for r in residuals], 0)
    err = concat([r[1] for r in residuals])
    weighted = scale_rows(jac, np.concatenate([r[2] for r in residuals]))
    return jac.T @ weighted, -weighted.T @ err
