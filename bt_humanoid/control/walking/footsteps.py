"""Footsteps from a walking command: where each foot lands next, inside what the legs can reach.

A virtual body pose B (x, y, yaw), the middle between the feet, advances by the commanded velocity over each
step's period; each footstep is B at its step, offset by half the stance width to the foot's side. Each step is
then clipped to a kinematic box relative to the stance foot, in the stance foot's frame (``StepLimits``), and B is
taken back from the clipped foot, so that a command the legs cannot follow gives the largest steps they can make
rather than a plan that runs away from the feet.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

LEFT, RIGHT = 0, 1
SIDE_SIGN = (1.0, -1.0)  # +y is the left foot's outward side


@dataclass(frozen=True)
class Footstep:
    """Where a sole lands: its centre on the floor (x, y) and its heading, world frame."""

    side: int  # LEFT or RIGHT
    x: float
    y: float
    yaw: float

    @property
    def position(self) -> np.ndarray:
        return np.array([self.x, self.y])

    def relative_to(self, other: Footstep) -> tuple[float, float, float]:
        """(dx, dy, dyaw) of this footstep in ``other``'s frame."""
        c, s = math.cos(other.yaw), math.sin(other.yaw)
        dx, dy = self.x - other.x, self.y - other.y
        return c * dx + s * dy, -s * dx + c * dy, _wrap(self.yaw - other.yaw)

    def moved(self, dx: float, dy: float, dyaw: float, side: int) -> Footstep:
        """The footstep at (dx, dy, dyaw) in this one's frame, for ``side``."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return Footstep(side, self.x + c * dx - s * dy, self.y + s * dx + c * dy, _wrap(self.yaw + dyaw))


@dataclass(frozen=True)
class StepLimits:
    """How far a foot may land from the stance foot, in the stance foot's frame (docs/walking.md, Footsteps).

    Sideways distances are outward of the stance foot (the swing foot's side): the feet never cross, and their
    inner edges keep ``sideways[0]`` minus the sole's width apart. Yaw is outward too: turning opens the leading
    foot first (the hips' yaw range is ±0.43 rad).
    """

    forward: tuple[float, float] = (-0.15, 0.25)  # m
    sideways: tuple[float, float] = (0.14, 0.30)  # m
    yaw: tuple[float, float] = (-0.1, 0.4)  # rad
    #: m of extra sideways distance per radian the feet are turned apart: a turned sole sweeps its heel (or toe)
    #: inwards by about half its length times the angle, towards the other foot
    turned_clearance: float = 0.11

    def narrowest(self, dyaw: float) -> float:
        """The least sideways distance between the soles' centres when they are turned ``dyaw`` apart."""
        return self.sideways[0] + self.turned_clearance * abs(dyaw)

    def clip(self, step: Footstep, stance: Footstep) -> Footstep:
        dx, dy, dyaw = step.relative_to(stance)
        sign = SIDE_SIGN[step.side]
        dx = float(np.clip(dx, *self.forward))
        dyaw = sign * float(np.clip(sign * dyaw, *self.yaw))
        dy = sign * float(np.clip(sign * dy, self.narrowest(dyaw), self.sideways[1]))
        return stance.moved(dx, dy, dyaw, step.side)

    def contains(self, step: Footstep, stance: Footstep, tolerance: float = 1e-9) -> bool:
        dx, dy, dyaw = step.relative_to(stance)
        sign = SIDE_SIGN[step.side]
        return (
            self.forward[0] - tolerance <= dx <= self.forward[1] + tolerance
            and self.narrowest(dyaw) - tolerance <= sign * dy <= self.sideways[1] + tolerance
            and self.yaw[0] - tolerance <= sign * dyaw <= self.yaw[1] + tolerance
        )


@dataclass
class FootstepPlanner:
    """Plans the next footsteps for a body velocity command (forward, leftward m/s; turning rad/s, body frame)."""

    width: float  # m between the sole centres standing
    period: float  # s from one touchdown to the next
    limits: StepLimits

    def body(self, step: Footstep) -> Footstep:
        """The virtual body pose that puts ``step`` at its side's place."""
        return step.moved(0.0, -SIDE_SIGN[step.side] * self.width / 2, 0.0, step.side)

    def next_step(self, stance: Footstep, velocity: np.ndarray) -> Footstep:
        """The other foot's next footstep, for ``velocity`` held over one period, from the body over ``stance``."""
        side = 1 - stance.side
        body = self.body(stance)
        vx, vy, wz = (float(v) for v in velocity)
        dyaw = wz * self.period
        # the body moves along an arc's chord: the velocity taken in the frame half-way through the turn
        c, s = math.cos(dyaw / 2), math.sin(dyaw / 2)
        dx, dy = (c * vx - s * vy) * self.period, (s * vx + c * vy) * self.period
        # sideways and turning, the leading foot opens by two steps' worth and the other closes onto it: the feet
        # never come closer than they stand, nor turn inwards (the box allows little of either), and a pair of
        # steps still moves by 2 vy T and turns by 2 wz T
        sideways = vy * self.period * (1.0 if vy * SIDE_SIGN[side] > 0.0 else -1.0)
        target = body.moved(dx, dy, dyaw, side).moved(0.0, SIDE_SIGN[side] * self.width / 2 + sideways, 0.0, side)
        opening = wz * SIDE_SIGN[side] > 0.0
        turned = stance.moved(0.0, 0.0, 2 * dyaw if opening else 0.0, side)
        target = Footstep(side, target.x, target.y, turned.yaw)
        return self.limits.clip(target, stance)

    def plan(self, stance: Footstep, velocity: np.ndarray, count: int) -> list[Footstep]:
        """``count`` footsteps, alternating from the foot that is not ``stance``."""
        steps: list[Footstep] = []
        for _ in range(count):
            stance = self.next_step(stance, velocity)
            steps.append(stance)
        return steps

    def closing_step(self, stance: Footstep) -> Footstep:
        """The step that brings the other foot beside ``stance``, the feet side by side: a stop."""
        return self.next_step(stance, np.zeros(3))

    def together(self, left: Footstep, right: Footstep, tolerance: float = 0.01) -> bool:
        """Whether the feet stand side by side at the stance width (within ``tolerance`` m and rad)."""
        dx, dy, dyaw = left.relative_to(right)
        return abs(dx) < tolerance and abs(dy - self.width) < tolerance and abs(dyaw) < tolerance


def _wrap(angle: float) -> float:
    return (angle + math.pi) % (2 * math.pi) - math.pi
