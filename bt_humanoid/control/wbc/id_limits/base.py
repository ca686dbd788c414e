"""What a box limit of the inverse-dynamics QP answers: lower and upper bounds on v̇."""

from __future__ import annotations

from typing import Protocol

import numpy as np

from bt_humanoid.control.wbc.dynamics import RobotDynamics


class AccelerationBounds(Protocol):
    def bounds(self, dynamics: RobotDynamics, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper), each of length nv; ±inf where this limit says nothing."""
        ...
