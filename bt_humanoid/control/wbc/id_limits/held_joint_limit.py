"""Joints that no controller moves: held by their own position servo (a torso lift at its stop, the fingers)."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.dynamics import RobotDynamics


class HeldJointLimit:
    """v̇ = −gain · v for ``joints``: the QP counts them as still (their servo's and stops' force, whatever it
    is, is theirs to give, so their torques are not bounded); a small speed they have decays."""

    def __init__(self, joints: list[str], gain: float = 10.0) -> None:
        self.joints = list(joints)
        self.gain = gain
        self._columns: np.ndarray | None = None

    def bounds(self, dynamics: RobotDynamics, dt: float) -> tuple[np.ndarray, np.ndarray]:
        if self._columns is None:
            self._columns = np.array([dynamics.joint_index(joint) for joint in self.joints], dtype=int)
        lower, upper = np.full(dynamics.nv, -np.inf), np.full(dynamics.nv, np.inf)
        target = -self.gain * dynamics.v[self._columns]
        lower[self._columns], upper[self._columns] = target, target
        return lower, upper
