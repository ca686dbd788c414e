"""Keep the hands (and wrists) a margin away from the torso's vertical axis."""

from __future__ import annotations

import math

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.limits.base import Inequality, Limit, gap_bound


class TorsoMarginLimit(Limit):
    """Horizontal distance from each frame to the ``torso`` frame's z axis stays ≥ that frame's margin.

    Linearised each step: the distance may shrink by at most ``gain`` times
    its slack above the margin, so the arm slows down as it nears the body.
    """

    def __init__(self, torso: str, margins: dict[str, float], gain: float = 0.5) -> None:
        self.torso = torso
        self.margins = margins  # frame → metres
        self.gain = gain

    def inequality(self, kinematics: RobotKinematics, dt: float) -> Inequality:
        torso = kinematics.pose(self.torso).translation
        torso_jac = kinematics.jacobian(self.torso)[:2]
        rows, lower = [], []
        for frame, margin in self.margins.items():
            offset = kinematics.pose(frame).translation[:2] - torso[:2]  # horizontal
            distance = math.hypot(offset[0], offset[1])
            if distance < 1e-6:
                continue
            rows.append((offset / distance) @ (kinematics.jacobian(frame)[:2] - torso_jac))
            lower.append(gap_bound(self.gain, margin - distance, dt))
        if not rows:
            return Inequality.none(len(kinematics.joints))
        return Inequality(np.array(rows), np.array(lower))
