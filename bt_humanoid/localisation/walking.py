"""Localisation of a walking base: the walker's state estimate is its odometry, scans correct it.

A walking controller balances in the frame its state estimator keeps (legged odometry: the IMU, encoders and
foot contacts); that frame drifts, and it must not jump under a balancing robot. So the walker keeps it, and
localisation keeps the correction from it to the map (``correction``, as a map → odometry transform does on
mobile robots): where the base is on the map is the correction composed with the estimate, and a goal on the
map is handed to the walker in its own frame (``to_odometry``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Protocol

import numpy as np

from bt_humanoid.localisation.base import BaseLocalisation, localises
from bt_humanoid.localisation.frames import compose, inverse, place_on_map
from bt_humanoid.localisation.localiser import Localiser
from bt_humanoid.localisation.odometry import body_increment
from bt_humanoid.localisation.scan_map import ScanMap
from bt_humanoid.sim.simulation import Simulation


class OdometryBase(Protocol):
    def odometry_pose(self) -> np.ndarray: ...


class WalkingLocalisation(BaseLocalisation):
    """``odometry_pose``: the walker's estimate of the base (x, y, yaw); ``true_pose``: where the base body is in
    the simulator, for placing what body-mounted sensors measured (``on_map``) only."""

    def __init__(
        self, localiser: Localiser, odometry_pose: Callable[[], np.ndarray], true_pose: Callable[[], np.ndarray]
    ) -> None:
        super().__init__(localiser)
        self._odometry_pose = odometry_pose
        self._true_pose = true_pose
        self._odometry = np.asarray(odometry_pose(), dtype=float).copy()

    def step(self) -> None:
        now = np.asarray(self._odometry_pose(), dtype=float).copy()
        self.localiser.predict(body_increment(self._odometry, now))
        self._odometry = now

    def correction(self) -> np.ndarray:
        """The map pose of the odometry frame's origin: map pose = correction ∘ odometry pose."""
        return compose(self.localiser.pose, inverse(self._odometry))

    def to_odometry(self, pose: np.ndarray) -> np.ndarray:
        """A pose on the map (x, y, yaw) in the walker's odometry frame."""
        return compose(inverse(self.correction()), np.asarray(pose, dtype=float))

    def turn(self) -> float:
        """How far the map's axes are turned from the odometry's (rad)."""
        return float(self.correction()[2])

    def on_map(self, position: np.ndarray, rotation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return place_on_map(position, rotation, self._true_pose(), self.localiser.pose)

    def configuration_on_map(self, q: np.ndarray) -> np.ndarray:
        """A Pinocchio configuration (free flyer first: x, y, z, then the quaternion x, y, z, w) estimated in the
        odometry frame, with its base placed on the map."""
        cx, cy, turn = self.correction()
        c, s = math.cos(turn), math.sin(turn)
        placed = np.array(q, dtype=float)
        placed[0], placed[1] = cx + c * q[0] - s * q[1], cy + s * q[0] + c * q[1]
        hz, hw = math.sin(turn / 2), math.cos(turn / 2)  # the turn about z as a quaternion, composed on the left
        x, y, z, w = q[3:7]
        placed[3:7] = [hw * x - hz * y, hw * y + hz * x, hw * z + hz * w, hw * w - hz * z]
        return placed


def walking_localisation(sim: Simulation, base: OdometryBase) -> WalkingLocalisation | None:
    """A walking base's localisation, from where its estimator starts; None without a scanner to correct the
    odometry with, or with exact sensors (--ideal-sensors: the walker's odometry is then the pose)."""
    if not localises(sim):
        return None
    root = sim.model.body(sim.robot_root).id

    def true_pose() -> np.ndarray:  # where the base body is: for placing body-mounted sensors' poses only
        rotation = sim.data.xmat[root]
        return np.array([sim.data.xpos[root][0], sim.data.xpos[root][1], math.atan2(rotation[3], rotation[0])])

    localiser = Localiser(ScanMap.for_robot(sim), base.odometry_pose())
    localisation = WalkingLocalisation(localiser, base.odometry_pose, true_pose)
    sim.on_map = localisation.on_map  # body-mounted sensors place what they see through the belief
    return localisation
