"""What every base's localisation offers the rest of the robot: the belief, fed by odometry and scans."""

from __future__ import annotations

import math
from abc import ABC, abstractmethod

import numpy as np

from bt_humanoid.localisation.localiser import Localiser
from bt_humanoid.sim.simulation import Simulation

MATCH_PERIOD = 0.1  # s between scans matched to the map (the scanner gives more; 10 Hz keeps up with 1 m/s)


def localises(sim: Simulation) -> bool:
    """Whether the robot localises itself: its odometry is modelled (not --ideal-sensors) and it has a base
    scanner to correct it with; otherwise its base pose is its odometry's."""
    return sim.sensors.odometry.enabled and sim.robot.scanner is not None


class BaseLocalisation(ABC):
    """Where the base believes it is on the map (``pose``): ``step`` each control step moves the belief by the
    odometry, ``scan`` each scan corrects it, ``on_map`` places what body-mounted sensors measured."""

    def __init__(self, localiser: Localiser) -> None:
        self.localiser = localiser
        self._matched_at = -math.inf

    def pose(self) -> np.ndarray:
        """(x, y, yaw) of the base on the map, as the robot believes."""
        return self.localiser.pose.copy()

    def scan(self, points: np.ndarray, time: float) -> None:
        """A scan (the base's frame, N × 2): matched to the map every ``MATCH_PERIOD``."""
        if time - self._matched_at >= MATCH_PERIOD - 1e-9:
            self._matched_at = time
            self.localiser.correct(points, time)

    @abstractmethod
    def step(self) -> None:
        """Move the belief by what the odometry measured since the last step."""

    @abstractmethod
    def on_map(self, position: np.ndarray, rotation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A world pose measured by a sensor on the robot (MuJoCo's), placed on the map through the belief."""
