"""Joint ranges and speed limits as bounds on the joint accelerations."""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.dynamics import RobotDynamics

HORIZON = 0.1  # s: a joint must be able to stop inside its range within this, given its speed now
# s over which a joint faster than its limit is brought back under it: within one 2 ms step the deceleration
# (and its reaction on the floating base) would be more than the feet's contact can take, and the QP infeasible
SPEED_HORIZON = 0.05


class JointLimit:
    """Position and speed bounds for ``joints``: v̇ keeps the position reached under constant acceleration over
    ``horizon`` inside [lower + margin, upper − margin], and brings the speed within ±max_velocity over
    ``SPEED_HORIZON`` (at once, if that is under a step).

    Bounds that cannot both hold (a joint already outside, or too fast to stop in time) give way to the
    position one's direction: any acceleration back inside is allowed."""

    def __init__(
        self,
        joints: list[str],
        lower: np.ndarray,
        upper: np.ndarray,
        max_velocity: np.ndarray,
        margin: float = 0.01,
        horizon: float = HORIZON,
    ) -> None:
        self.joints = list(joints)
        self.lower = np.asarray(lower, dtype=float) + margin
        self.upper = np.asarray(upper, dtype=float) - margin
        self.max_velocity = np.asarray(max_velocity, dtype=float)
        self.horizon = horizon
        self._columns: np.ndarray | None = None

    def bounds(self, dynamics: RobotDynamics, dt: float) -> tuple[np.ndarray, np.ndarray]:
        if self._columns is None:
            self._columns = np.array([dynamics.joint_index(joint) for joint in self.joints])
        columns = self._columns
        q, v = dynamics.q[columns + 1], dynamics.v[columns]
        t = self.horizon
        # q + v t + ½ v̇ t² within the range
        low = 2.0 * (self.lower - q - v * t) / t**2
        high = 2.0 * (self.upper - q - v * t) / t**2
        slowing = max(dt, SPEED_HORIZON)
        low = np.maximum(low, (-self.max_velocity - v) / slowing)
        high = np.minimum(high, (self.max_velocity - v) / slowing)
        low = np.minimum(low, high)  # conflicting: the range's side wins (any acceleration back in)
        lower, upper = np.full(dynamics.nv, -np.inf), np.full(dynamics.nv, np.inf)
        lower[columns], upper[columns] = low, high
        return lower, upper
