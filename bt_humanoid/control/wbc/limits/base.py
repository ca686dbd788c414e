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


class Limit(ABC):
    """A hard constraint of the whole-body QP."""

    @abstractmethod
    def inequality(self, kinematics: RobotKinematics, dt: float) -> Inequality: ...
