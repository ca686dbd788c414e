"""Keep a frame above a height: the hand clears the support surface while approaching."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.limits.base import FREE, Inequality, Limit, gap_bound
from bt_humanoid.control.wbc.maths import Value, all_of, concat, where


class ClearanceLimit(Limit):
    """``frame`` stays at or above ``height`` (world z) whenever it is over ``region`` [[x0, y0], [x1, y1]].

    Outside the region (beside the table) the hand may go lower, so it can
    come up from below the edge height only once it is clear of the edge.
    """

    def __init__(self, frame: str, height: float, region: np.ndarray, gain: float = 0.5) -> None:
        self.frame = frame
        self.height = height
        self.region = np.asarray(region, dtype=float)
        self.gain = gain

    def covers(self, xy: np.ndarray) -> bool:
        """Whether the limit holds at ``xy`` (world x, y)."""
        return bool(_within(self.region, xy))

    def signature(self) -> tuple:
        return (type(self).__qualname__, self.frame, self.gain)

    def inequality(self, kinematics: RobotKinematics, dt: float) -> Inequality:
        position = kinematics.position(self.frame)
        region = kinematics.parameter(lambda: self.region, (2, 2))
        height = kinematics.parameter(lambda: np.array([self.height]), (1, 1))[0]
        lower = where(_within(region, position), gap_bound(self.gain, height - position[2], dt), FREE)
        return Inequality(kinematics.jacobian(self.frame)[2:3, :], concat([lower]))


def _within(region: Value, xy: Value) -> Value:
    """Whether ``xy`` lies in the rectangle ``region`` [[x0, y0], [x1, y1]]."""
    return all_of(region[0, 0] <= xy[0], xy[0] <= region[1, 0], region[0, 1] <= xy[1], xy[1] <= region[1, 1])
