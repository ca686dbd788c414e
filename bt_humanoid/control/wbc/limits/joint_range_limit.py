"""Keep some joints inside narrower ranges than their own for one motion (an open hand clear of its forearm)."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.limits.base import Inequality, Limit, gap_bound
from bt_humanoid.control.wbc.maths import concat, stack_rows


class JointRangeLimit(Limit):
    """Each named joint stays within its [lower, upper] (rad or m), approaching a bound by ``gain`` of the slack.

    Unlike the joints' own ranges (box bounds on every motion) these hold for the motions that ask for them,
    and a joint that starts outside is brought back in, no faster than the recovery speed.
    """

    def __init__(self, ranges: dict[str, tuple[float, float]], gain: float = 0.5) -> None:
        self.ranges = dict(ranges)
        self.gain = gain

    def signature(self) -> tuple:
        return (type(self).__qualname__, tuple(self.ranges.items()), self.gain)

    def inequality(self, kinematics: RobotKinematics, dt: float) -> Inequality:
        n = len(kinematics.joints)
        rows, lower = [], []
        for joint, (low, high) in self.ranges.items():
            if joint not in kinematics.joints:
                continue
            i = kinematics.joints.index(joint)
            q = kinematics.positions[i]
            for sign, distance in ((1.0, q - low), (-1.0, high - q)):  # each distance to a bound stays ≥ 0
                row = np.zeros((1, n))
                row[0, i] = sign
                rows.append(row)
                lower.append(gap_bound(self.gain, -distance, dt))
        if not rows:
            return Inequality.none(n)
        return Inequality(stack_rows(rows, n), concat(lower))
