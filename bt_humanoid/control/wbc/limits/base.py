"""What every whole-body limit answers: linear inequalities on the joint step Δq."""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics


@dataclass
class Inequality:
    """``lower ≤ G Δq`` (row-wise); an empty G means no constraint this step."""

    G: np.ndarray
    lower: np.ndarray

    @classmethod
    def none(cls, n: int) -> Inequality:
        return cls(np.zeros((0, n)), np.zeros(0))


RECOVERY_SPEED = 0.1  # m/s at most that a violated limit demands to be made good: keeps the QP feasible


def gap_bound(gain: float, gap: float, dt: float) -> float:
    """Lower bound on the change of a distance that must stay ≥ its limit, ``gap`` = limit − distance.

    Satisfied (gap ≤ 0): the distance may shrink by ``gain`` times its slack
    per step, so motion slows as it nears the limit. Violated (a push, a
    target that started inside): it must grow, but no faster than
    RECOVERY_SPEED, which the joints can always deliver.
    """
    return min(gain * gap, RECOVERY_SPEED * dt) if gap > 0 else gain * gap


class Limit(ABC):
    """A hard constraint of the whole-body QP."""

    @abstractmethod
    def inequality(self, kinematics: RobotKinematics, dt: float) -> Inequality: ...
