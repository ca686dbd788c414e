"""Keep the base's footprint out of a box on the floor (the table it reaches over)."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.limits.base import Inequality, Limit, gap_bound


class BaseKeepoutLimit(Limit):
    """Distance from the base centre to the axis-aligned box ``region`` stays ≥ ``radius``."""

    def __init__(self, base_frame: str, region: np.ndarray, radius: float, gain: float = 0.5) -> None:
        self.base_frame = base_frame
        self.region = np.asarray(region, dtype=float)
        self.radius = radius
        self.gain = gain

    def inequality(self, kinematics: RobotKinematics, dt: float) -> Inequality:
        centre = kinematics.pose(self.base_frame).translation[:2]
        closest = np.clip(centre, self.region[0], self.region[1])
        offset = centre - closest
        distance = float(np.linalg.norm(offset))
        if distance < 1e-6 or distance > self.radius + 0.3:
            return Inequality.none(len(kinematics.joints))
        normal = offset / distance
        row = normal @ kinematics.jacobian(self.base_frame)[:2]
        return Inequality(row[None, :], np.array([gap_bound(self.gain, self.radius - distance, dt)]))
