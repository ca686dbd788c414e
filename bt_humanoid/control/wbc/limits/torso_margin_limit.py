"""Keep the hands (and wrists) a margin away from the torso's vertical axis."""

from __future__ import annotations

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.limits.base import FREE, Inequality, Limit, gap_bound
from bt_humanoid.control.wbc.maths import along, concat, maximum, norm, stack_rows, where


class TorsoMarginLimit(Limit):
    """Horizontal distance from each frame to the ``torso`` frame's z axis stays ≥ that frame's margin.

    Linearised each step: the distance may shrink by at most ``gain`` times
    its slack above the margin, so the arm slows down as it nears the body.
    """

    def __init__(self, torso: str, margins: dict[str, float], gain: float = 0.5) -> None:
        self.torso = torso
        self.margins = margins  # frame → metres
        self.gain = gain

    def signature(self) -> tuple:
        return (type(self).__qualname__, self.torso, tuple(self.margins.items()), self.gain)

    def inequality(self, kinematics: RobotKinematics, dt: float) -> Inequality:
        torso = kinematics.position(self.torso)[:2]
        torso_jacobian = kinematics.jacobian(self.torso)[:2, :]
        rows, lower = [], []
        for frame, margin in self.margins.items():
            offset = kinematics.position(frame)[:2] - torso  # horizontal
            distance = norm(offset)
            rows.append(along(offset / maximum(distance, 1e-6), kinematics.jacobian(frame)[:2, :] - torso_jacobian))
            # a frame on the axis has no direction to be pushed away in: its row is left free
            lower.append(where(distance > 1e-6, gap_bound(self.gain, margin - distance, dt), FREE))
        return Inequality(stack_rows(rows, len(kinematics.joints)), concat(lower))
