"""What every inverse-dynamics task answers: the acceleration it wants, and how v̇ produces acceleration."""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from bt_humanoid.control.wbc.dynamics import RobotDynamics


class AccelerationTask(ABC):
    """A least-squares objective ``weight · ‖J v̇ + J̇v − a*‖²`` of the inverse-dynamics QP.

    ``desired`` is a* — usually a PD law on the task's error plus a feedforward acceleration, so the task's
    error obeys ë + K_d ė + K_p e = 0 when the QP can give it what it asks.
    """

    def __init__(self, weight: float | np.ndarray = 1.0) -> None:
        self.weight = weight

    @abstractmethod
    def jacobian(self, dynamics: RobotDynamics) -> np.ndarray: ...

    @abstractmethod
    def drift(self, dynamics: RobotDynamics) -> np.ndarray: ...

    @abstractmethod
    def desired(self, dynamics: RobotDynamics) -> np.ndarray: ...

    def objective(self, dynamics: RobotDynamics) -> tuple[np.ndarray, np.ndarray]:
        """(H, g) of this task's cost ½ v̇ᵀ H v̇ + gᵀ v̇ (over v̇ only)."""
        jac = self.jacobian(dynamics)
        residual = self.drift(dynamics) - self.desired(dynamics)
        if np.ndim(self.weight) == 0:  # the common case, without broadcasting
            weighted = jac * float(self.weight)  # type: ignore[arg-type]
        else:
            weighted = jac * np.asarray(self.weight, dtype=float)[:, None]
        return jac.T @ weighted, weighted.T @ residual
