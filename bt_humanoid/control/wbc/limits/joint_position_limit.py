"""Stay inside the joints' position ranges, approaching the bounds no faster than a fraction per step."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.maths import Value, maximum, minimum


class JointPositionLimit:
    """Box bounds on Δq from [lower, upper] (± ``margin``), for joints whose range is finite."""

    def __init__(self, lower: np.ndarray, upper: np.ndarray, margin: float = 0.02, gain: float = 0.5) -> None:
        self.lower = lower + margin
        self.upper = upper - margin
        self.gain = gain

    def signature(self) -> tuple:
        return (type(self).__qualname__, self.gain)

    def bounds(self, kinematics: RobotKinematics, dt: float) -> tuple[Value, Value]:
        q = kinematics.positions
        lower = kinematics.parameter(lambda: self.lower, (len(self.lower), 1))
        upper = kinematics.parameter(lambda: self.upper, (len(self.upper), 1))
        # already outside (e.g. started there): allow no motion further out, any motion back in
        low = minimum(self.gain * (lower - q), 0.0)
        high = maximum(self.gain * (upper - q), 0.0)
        return low, high
