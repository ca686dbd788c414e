"""Keep the base's footprint inside a rectangle of the floor (the walls of the map)."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.limits.base import FREE, Inequality, Limit, gap_bound
from bt_humanoid.control.wbc.maths import concat, stack_rows, where

NEAR = 0.3  # m beyond the radius from which a wall is considered at all


class BaseBoundsLimit(Limit):
    """The base centre stays ≥ ``radius`` inside the axis-aligned ``bounds`` [[x0, y0], [x1, y1]]."""

    def __init__(self, base_frame: str, bounds: np.ndarray, radius: float, gain: float = 0.5) -> None:
        self.base_frame = base_frame
        self.bounds = np.asarray(bounds, dtype=float)
        self.radius = radius
        self.gain = gain

    def signature(self) -> tuple:
        return (type(self).__qualname__, self.base_frame, self.radius, self.gain)

    def inequality(self, kinematics: RobotKinematics, dt: float) -> Inequality:
        centre = kinematics.position(self.base_frame)[:2]
        jacobian = kinematics.jacobian(self.base_frame)[:2, :]
        bounds = kinematics.parameter(lambda: self.bounds, (2, 2))  # the map's walls
        rows, lower = [], []
        for axis in (0, 1):
            for sign, wall in ((1.0, bounds[0, axis]), (-1.0, bounds[1, axis])):
                distance = sign * (centre[axis] - wall)  # from the wall, inwards
                rows.append(sign * jacobian[axis, :])
                bound = gap_bound(self.gain, self.radius - distance, dt)
                lower.append(where(distance > self.radius + NEAR, FREE, bound))  # a far wall is not considered
        return Inequality(stack_rows(rows, len(kinematics.joints)), concat(lower))
