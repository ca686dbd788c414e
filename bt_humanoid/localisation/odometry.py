"""What the wheels of a planar base say it moved: the true motion with the errors wheels make.

A real base counts wheel turns and turns them into a motion of the base in its own frame; how far that is
from the truth is ``OdometryModel``'s (a scale error per axis drawn once a run, and noise that grows with the
distance moved). The truth comes from the simulated base's planar joints: the wheels' own measurement of the
floor moving under them, not anything the robot may read directly.
"""

from __future__ import annotations

import math

import numpy as np

from bt_humanoid.sim.sensor_models import OdometryModel


def body_increment(before: np.ndarray, after: np.ndarray) -> np.ndarray:
    """(forward, left, turn) that takes pose ``before`` (x, y, yaw) to ``after``, in ``before``'s frame at the
    middle of the turn (the wheels measure along the path, which turns meanwhile)."""
    turn = math.remainder(float(after[2] - before[2]), 2 * math.pi)
    heading = float(before[2]) + 0.5 * turn
    c, s = math.cos(heading), math.sin(heading)
    dx, dy = float(after[0] - before[0]), float(after[1] - before[1])
    return np.array([c * dx + s * dy, -s * dx + c * dy, turn])


def apply_increment(pose: np.ndarray, increment: np.ndarray) -> np.ndarray:
    """``pose`` moved by a ``body_increment``."""
    heading = float(pose[2]) + 0.5 * float(increment[2])
    c, s = math.cos(heading), math.sin(heading)
    return np.array(
        [
            pose[0] + c * increment[0] - s * increment[1],
            pose[1] + s * increment[0] + c * increment[1],
            pose[2] + increment[2],
        ]
    )


class WheelOdometry:
    """Turns the base's true motion into what its wheels report, one control step at a time."""

    def __init__(self, model: OdometryModel, rng: np.random.Generator) -> None:
        self.model = model
        self.rng = rng
        self.scale = 1.0 + (rng.standard_normal(3) * model.scale if model.enabled else np.zeros(3))

    def measure(self, increment: np.ndarray) -> np.ndarray:
        """The reported ``body_increment`` for a true one."""
        if not self.model.enabled:
            return np.asarray(increment, dtype=float).copy()
        moved = math.hypot(increment[0], increment[1])
        noise = self.rng.standard_normal(3) * np.array(
            [self.model.noise * math.sqrt(moved)] * 2 + [self.model.yaw_noise * math.sqrt(abs(increment[2]))]
        )
        return increment * self.scale + noise
