"""Keep the base's footprint inside a rectangle of the floor (the walls of the map)."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.limits.base import Inequality, Limit, gap_bound

NEAR = 0.3  # m beyond the radius from which a wall is considered at all


class BaseBoundsLimit(Limit):
    """The base centre stays ≥ ``radius`` inside the axis-aligned ``bounds`` [[x0, y0], [x1, y1]]."""

    def __init__(self, base_frame: str, bounds: np.ndarray, radius: float, gain: float = 0.5) -> None:
        self.base_frame = base_frame
        self.bounds = np.asarray(bounds, dtype=float)
        self.radius = radius
        self.gain = gain

    def inequality(self, kinematics: RobotKinematics, dt: float) -> Inequality:
        centre = kinematics.pose(self.base_frame).translation[:2]
        jacobian = kinematics.jacobian(self.base_frame)[:2]
        rows, lower = [], []
        for axis in (0, 1):
            for sign, wall in ((1.0, self.bounds[0, axis]), (-1.0, self.bounds[1, axis])):
                distance = sign * (centre[axis] - wall)  # from the wall, inwards
                if distance > self.radius + NEAR:
                    continue
                rows.append(sign * jacobian[axis])
                lower.append(gap_bound(self.gain, self.radius - distance, dt))
        if not rows:
            return Inequality.none(len(kinematics.joints))
        return Inequality(np.array(rows), np.array(lower))
