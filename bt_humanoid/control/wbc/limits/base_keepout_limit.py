"""Keep the base's footprint out of a box on the floor (the table it reaches over)."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.limits.base import FREE, Inequality, Limit, gap_bound
from bt_humanoid.control.wbc.maths import all_of, along, concat, maximum, minimum, norm, stack_rows, where


class BaseKeepoutLimit(Limit):
    """Distance from the base centre to the axis-aligned box ``region`` stays ≥ ``radius``."""

    def __init__(self, base_frame: str, region: np.ndarray, radius: float, gain: float = 0.5) -> None:
        self.base_frame = base_frame
        self.region = np.asarray(region, dtype=float)
        self.radius = radius
        self.gain = gain

    def signature(self) -> tuple:
        return (type(self).__qualname__, self.base_frame, self.radius, self.gain)

    def inequality(self, kinematics: RobotKinematics, dt: float) -> Inequality:
        centre = kinematics.position(self.base_frame)[:2]
        region = kinematics.parameter(lambda: self.region, (2, 2))  # the table's outline
        closest = minimum(maximum(centre, region[0, :].T), region[1, :].T)
        offset = centre - closest
        distance = norm(offset)
        row = along(offset / maximum(distance, 1e-6), kinematics.jacobian(self.base_frame)[:2, :])
        # inside the box (no direction out) or farther than 0.3 m beyond the radius: the row is left free
        near = all_of(distance >= 1e-6, distance <= self.radius + 0.3)
        lower = where(near, gap_bound(self.gain, self.radius - distance, dt), FREE)
        return Inequality(stack_rows([row], len(kinematics.joints)), concat([lower]))
