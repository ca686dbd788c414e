"""Localisation of a planar (wheeled) base: wheel odometry, the localiser, and the base's frame on the map.

The simulated base moves on three planar joints. What its wheels measure is those joints' motion, as the base
saw it, with ``WheelOdometry``'s errors; where the robot believes it is comes only from that and the scans.
Two things stay physics rather than belief, and live here so nothing else needs the truth:

- the wheels turn in the base's own frame: a velocity the controller wants on its map is turned into the
  base's frame through the belief, and the wheels carry it out along where the base truly faces;
- a sensor on the robot measures relative to the robot: a pose measured in the world (a camera's, from
  MuJoCo) is placed on the robot's map through where the robot believes its base is (``on_map``).
"""

from __future__ import annotations

import math

import numpy as np

from bt_humanoid.localisation.base import BaseLocalisation, localises
from bt_humanoid.localisation.frames import place_on_map, turned
from bt_humanoid.localisation.localiser import ODOMETRY_SHARE, Localiser
from bt_humanoid.localisation.odometry import WheelOdometry, body_increment
from bt_humanoid.localisation.scan_map import ScanMap
from bt_humanoid.sim.robot_io import MujocoRobotIO
from bt_humanoid.sim.simulation import Simulation


class PlanarLocalisation(BaseLocalisation):
    """Belief of where a planar base is, kept up to date from its wheels (``step``) and scans (``scan``)."""

    def __init__(self, io: MujocoRobotIO, odometry: WheelOdometry, localiser: Localiser) -> None:
        super().__init__(localiser)
        self.io = io
        self.odometry = odometry
        self._wheels = io.positions().copy()  # what the wheels turned through, as of the last step

    def step(self) -> None:
        """Move the belief by what the wheels turned through since the last step."""
        now = self.io.positions().copy()
        self.localiser.predict(self.odometry.measure(body_increment(self._wheels, now)))
        self._wheels = now

    def _heading_error(self) -> float:
        """How far the belief's heading is from the base's true one (rad)."""
        return math.remainder(float(self.localiser.pose[2] - self.io.positions()[2]), 2 * math.pi)

    def to_wheels(self, velocity: np.ndarray) -> np.ndarray:
        """A velocity (vx, vy, yaw rate) wanted on the map → what the planar joints carry out: the same
        velocity in the base's frame, wherever the base truly faces."""
        return turned(velocity, -self._heading_error())

    def from_wheels(self, velocity: np.ndarray) -> np.ndarray:
        """The base's true velocity as the robot places it on its map (the inverse of ``to_wheels``)."""
        return turned(velocity, self._heading_error())

    def on_map(self, position: np.ndarray, rotation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A world pose measured by a sensor on the robot (MuJoCo's), placed on the map through the belief."""
        return place_on_map(position, rotation, self.io.positions(), self.localiser.pose)


def planar_localisation(sim: Simulation, io: MujocoRobotIO) -> PlanarLocalisation | None:
    """The planar base's localisation, starting where the robot was put down (it is told where it starts, as a
    real robot is given its initial pose); None where the base's pose is exact: odometry off (--ideal-sensors),
    or no scanner to correct it with."""
    if not localises(sim):
        return None
    scan_map = ScanMap.for_robot(sim)
    odometry = WheelOdometry(sim.sensors.odometry, sim.random_stream("odometry"))
    # the filter allows 2.5 σ of the wheels' scale error (their calibration's spec)
    share = max(ODOMETRY_SHARE, 2.5 * sim.sensors.odometry.scale)
    localisation = PlanarLocalisation(io, odometry, Localiser(scan_map, io.positions(), odometry_share=share))
    sim.on_map = localisation.on_map  # body-mounted sensors place what they see through the belief
    return localisation
