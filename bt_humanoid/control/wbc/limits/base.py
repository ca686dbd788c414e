"""What every whole-body limit answers: linear inequalities on the joint step Δq."""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.maths import Value, minimum, where


@dataclass
class Inequality:
    """``lower ≤ G Δq`` (row-wise); an empty G means no constraint."""

    G: Value
    lower: Value

    @classmethod
    def none(cls, n: int) -> Inequality:
        return cls(np.zeros((0, n)), np.zeros(0))


RECOVERY_SPEED = 0.1  # m/s at most that a violated limit demands to be made good: keeps the QP feasible


def gap_bound(gain: float, gap: Value, dt: float) -> Value:
    """Lower bound on the change of a distance that must stay ≥ its limit, ``gap`` = limit − distance.

    Satisfied (gap ≤ 0): the distance may shrink by ``gain`` times its slack
    per step, so motion slows as it nears the limit. Violated (a push, a
    target that started inside): it must grow, but no faster than
    RECOVERY_SPEED, which the joints can always deliver.
    """
    return where(gap > 0, minimum(gain * gap, RECOVERY_SPEED * dt), gain * gap)


FREE = -np.inf  # the lower bound of a row that does not hold this step (a wall too far away to matter)


class Limit(ABC):
    """A hard constraint of the whole-body QP.

    Its rows are the same every step (the compiled QP has a fixed shape); a
    row that does not apply now gets the lower bound ``FREE``. Written with
    ``maths``' operations, like the tasks.
    """

    @abstractmethod
    def inequality(self, kinematics: RobotKinematics, dt: float) -> Inequality: ...

    @abstractmethod
    def signature(self) -> tuple:
        """What a compiled QP fixes of this limit (its frames, gains); the rest it reads through
        ``kinematics.parameter``."""
