"""The swinging foot's path from lift-off to touchdown: minimum-jerk across, a smooth lift and landing.

Up and down, a bump h · 64 s³ (1 − s)³ of the phase s ∈ [0, 1] over the line between the two heights, which
peaks at h half-way and starts and lands with zero velocity and acceleration. Across the floor (x, y, yaw), a
quintic from rest to rest; it waits for the foot to clear the floor and ends before it lands (``LIFT_SHARE`` of
the phase each side), so the sole neither scuffs nor slides in. ``retarget`` moves the footstep mid-swing (step
adjustment): a new quintic from where the path is now, with its velocity and acceleration, to the new footstep
by the same time, so the reference stays smooth. A new landing time re-plans the height as well: up to the full
step height by half the new swing if the foot is not that high yet, then down to the floor.
"""

from __future__ import annotations

import math

import numpy as np

LIFT_SHARE = 0.15  # of the swing at each end with the foot moving up or down only
# m the path ends below the floor: the foot lands pressing a little rather than hovering over a soft floor
PRESS = 0.003


def _minimum_jerk(s: float) -> tuple[float, float, float]:
    """Position, rate and second rate (per unit phase) of 10s³ − 15s⁴ + 6s⁵."""
    s = min(max(s, 0.0), 1.0)
    return s**3 * (10 - 15 * s + 6 * s**2), 30 * s**2 * (1 - s) ** 2, 60 * s * (1 - s) * (1 - 2 * s)


class Quintic:
    """p(t) on [0, T] from (p0, v0, a0) to (p1, 0, 0), per coordinate; held at the ends outside."""

    def __init__(self, duration: float, p0: np.ndarray, v0: np.ndarray, a0: np.ndarray, p1: np.ndarray) -> None:
        T = max(duration, 1e-6)
        self.duration = T
        d = p1 - p0 - v0 * T - a0 * T**2 / 2  # what the cubic and higher terms must add by T
        e = -v0 - a0 * T  # … to the velocity
        f = -a0  # … and to the acceleration
        # c3 T³ + c4 T⁴ + c5 T⁵ = d,  3c3 T² + 4c4 T³ + 5c5 T⁴ = e,  6c3 T + 12c4 T² + 20c5 T³ = f
        c3 = (10 * d - 4 * e * T + f * T**2 / 2) / T**3
        c4 = (-15 * d + 7 * e * T - f * T**2) / T**4
        c5 = (6 * d - 3 * e * T + f * T**2 / 2) / T**5
        self.coefficients = np.array([p0, v0, a0 / 2, c3, c4, c5])

    def at(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        c = self.coefficients
        if t >= self.duration:
            return self.at_end()
        t = max(t, 0.0)
        position = c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * (c[4] + t * c[5]))))
        velocity = c[1] + t * (2 * c[2] + t * (3 * c[3] + t * (4 * c[4] + t * 5 * c[5])))
        acceleration = 2 * c[2] + t * (6 * c[3] + t * (12 * c[4] + t * 20 * c[5]))
        return position, velocity, acceleration

    def at_end(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        T, c = self.duration, self.coefficients
        return c[0] + c[1] * T + c[2] * T**2 + c[3] * T**3 + c[4] * T**4 + c[5] * T**5, c[1] * 0, c[1] * 0


class SwingTrajectory:
    """One swing: from the sole's pose at lift-off (x, y, z, yaw) to its footstep (z: the floor) in ``duration``
    s, ``height`` m high."""

    def __init__(self, start: np.ndarray, end: np.ndarray, duration: float, height: float = 0.05) -> None:
        self.start = np.asarray(start, dtype=float)
        self.end = np.asarray(end, dtype=float).copy()
        self.end[3] = self.start[3] + math.remainder(self.end[3] - self.start[3], 2 * math.pi)
        self.duration = duration
        self.height = height
        self._across_start = LIFT_SHARE * duration  # s when the move across begins
        self._vertical: list[tuple[float, Quintic]] = []  # once retimed: the height's path, (from when, quintic)
        zero = np.zeros(3)
        self._across = Quintic((1 - 2 * LIFT_SHARE) * duration, self.start[[0, 1, 3]], zero, zero, self.end[[0, 1, 3]])

    def retarget(self, t: float, end: np.ndarray, duration: float | None = None) -> None:
        """Land at ``end`` (x, y, yaw; the height stays) instead, after ``duration`` s in all (the same if None),
        from the path's state at ``t`` s after lift-off: the reference stays smooth (position, velocity and
        acceleration carry on)."""
        self.end[[0, 1]] = end[:2]
        self.end[3] = self.start[3] + math.remainder(float(end[2]) - self.start[3], 2 * math.pi)
        if duration is not None and abs(duration - self.duration) > 1e-9:
            self._retime_height(t, duration)
            if t <= self._across_start:  # a shorter swing clears the floor sooner: it may move across sooner too
                self._across_start = max(t, LIFT_SHARE * duration)
        finish = self.duration - min(LIFT_SHARE * self.duration, (self.duration - t) / 3)
        if t <= self._across_start:  # not moving across yet: the same path, to the new place
            zero = np.zeros(3)
            self._across = Quintic(finish - self._across_start, self.start[[0, 1, 3]], zero, zero, self.end[[0, 1, 3]])
            return
        if t >= finish:
            return  # landing: too late to move the foot
        p, v, a = self._across.at(t - self._across_start)
        self._across = Quintic(finish - t, p, v, a, self.end[[0, 1, 3]])
        self._across_start = t

    def at(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(pose, velocity, acceleration) as (x, y, z, yaw) at ``t`` s after lift-off."""
        T = self.duration
        s = min(max(t / T, 0.0), 1.0)
        across = self._across.at(t - self._across_start)
        pose, velocity, acceleration = (np.array([q[0], q[1], 0.0, q[2]]) for q in across)
        if self._vertical and t >= self._vertical[0][0]:  # retimed: the height's own path
            start, segment = next((s, q) for s, q in reversed(self._vertical) if t >= s)
            z = segment.at(t - start)
            pose[2], velocity[2], acceleration[2] = z[0][0], z[1][0], z[2][0]
            return pose, velocity, acceleration
        # up and down: h·64 s³(1 − s)³ above the line between the two heights, pressing a little at the end
        h, rise = self.height, self.end[2] - PRESS - self.start[2]
        press, press_rate, press_second = _minimum_jerk(s)
        pose[2] = self.start[2] + rise * press + 64 * h * s**3 * (1 - s) ** 3
        velocity[2] = (rise * press_rate + 64 * h * 3 * s**2 * (1 - s) ** 2 * (1 - 2 * s)) / T
        acceleration[2] = (
            rise * press_second + 64 * h * (6 * s * (1 - s) ** 3 - 18 * s**2 * (1 - s) ** 2 + 6 * s**3 * (1 - s))
        ) / T**2
        return pose, velocity, acceleration

    def _retime_height(self, t: float, duration: float) -> None:
        """The height's path from ``t`` for a swing that now lands ``duration`` s after lift-off: a foot that has
        not yet risen to the step height does (by half the new swing, at the soonest now) before coming down;
        going straight down from just after lift-off dragged the sole across the floor, and the step fell short."""
        z, vz, az = (np.array([float(value[2])]) for value in self.at(t))
        floor = np.array([self.end[2] - PRESS])
        top = np.array([max(self.start[2], self.end[2]) + self.height])
        apex = max(duration / 2, t)
        if z[0] < top[0] - 1e-3 and vz[0] >= 0.0 and apex - t > 1e-3 and duration - apex > 1e-3:
            self._vertical = [
                (t, Quintic(apex - t, z, vz, az, top)),
                (apex, Quintic(duration - apex, top, *[np.zeros(1)] * 2, floor)),
            ]
        else:
            self._vertical = [(t, Quintic(max(duration - t, 1e-3), z, vz, az, floor))]
        self.duration = duration
