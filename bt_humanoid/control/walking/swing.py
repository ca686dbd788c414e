"""The swinging foot's path from lift-off to touchdown: minimum-jerk across, a smooth lift and landing.

Across the floor (x, y, yaw) a quintic with zero velocity and acceleration at both ends; up and down a bump
h · 64 s³ (1 − s)³ of the phase s ∈ [0, 1], which peaks at h half-way and starts and lands with zero velocity
and acceleration. The horizontal move waits for the foot to clear the floor and ends before it lands
(``LIFT_SHARE`` of the phase each side), so the sole neither scuffs nor slides in.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

LIFT_SHARE = 0.15  # of the swing at each end with the foot moving up or down only
# m the path ends below the floor: the foot lands pressing a little rather than hovering over a soft floor
PRESS = 0.003


def _minimum_jerk(s: float) -> tuple[float, float, float]:
    """Position, rate and second rate (per unit phase) of 10s³ − 15s⁴ + 6s⁵."""
    s = min(max(s, 0.0), 1.0)
    return (
        s**3 * (10 - 15 * s + 6 * s**2),
        30 * s**2 * (1 - s) ** 2,
        60 * s * (1 - s) * (1 - 2 * s),
    )


@dataclass
class SwingTrajectory:
    """One swing: from the sole's pose at lift-off to its footstep, over ``duration`` s, ``height`` m high."""

    start: np.ndarray  # x, y, z, yaw at lift-off
    end: np.ndarray  # x, y, z, yaw of the footstep (z: the floor)
    duration: float
    height: float = 0.05

    def at(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(pose, velocity, acceleration) as (x, y, z, yaw) at ``t`` s after lift-off."""
        T = self.duration
        s = min(max(t / T, 0.0), 1.0)
        # across: a minimum-jerk move over the middle of the phase
        span = 1.0 - 2 * LIFT_SHARE
        u = (s - LIFT_SHARE) / span
        position, rate, second = _minimum_jerk(u)
        inside = 0.0 < u < 1.0
        delta = self.end - self.start
        delta[3] = math.remainder(delta[3], 2 * math.pi)
        pose = self.start + position * delta
        velocity = (rate / (span * T) if inside else 0.0) * delta
        acceleration = (second / (span * T) ** 2 if inside else 0.0) * delta
        # up and down: h·64 s³(1 − s)³ above the straight line between the two heights, pressing at the end
        h = self.height
        bump = 64 * h * s**3 * (1 - s) ** 3
        bump_rate = 64 * h * (3 * s**2 * (1 - s) ** 3 - 3 * s**3 * (1 - s) ** 2) / T
        bump_second = 64 * h * (6 * s * (1 - s) ** 3 - 18 * s**2 * (1 - s) ** 2 + 6 * s**3 * (1 - s)) / T**2
        press, press_rate, press_second = _minimum_jerk(s)
        pose[2] = self.start[2] + (delta[2] - PRESS) * press + bump
        velocity[2] = (delta[2] - PRESS) * press_rate / T + bump_rate
        acceleration[2] = (delta[2] - PRESS) * press_second / T**2 + bump_second
        return pose, velocity, acceleration
