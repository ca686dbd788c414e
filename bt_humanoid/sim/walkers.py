"""People who walk loops through the scene: each drives their own velocity actuators along a route.

A walker heads for the next corner of their loop at their walking speed and,
like a polite person, stops while the robot stands close in front of them.
This is the scene's script, so it may look at where the robot really is; the
robot itself knows walkers only through its depth camera.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from bt_humanoid.sim.world_config import Walker

CORNER_REACHED = 0.1  # m from a corner before heading for the next
YIELD_DISTANCE = 0.75  # m: a walker waits while the robot's centre is this close ahead (about to bump)
YIELD_ANGLE = math.radians(70)  # half-angle of "ahead"


class WalkerDriver:
    """Commands one walker's actuators every control step."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, name: str, walker: Walker, robot_root: str) -> None:
        self.data = data
        self.walker = walker
        self.route = np.array(walker.route, dtype=float)
        self.joints = [model.joint(f"{name}_{axis}").qposadr[0] for axis in ("x", "y")]
        self.actuators = [model.actuator(f"{name}_{axis}").id for axis in ("x", "y")]
        self.robot = model.body(robot_root).id
        self.target = 1 % len(self.route)
        self.start = self.route[0]

    def position(self) -> np.ndarray:
        # slide joints measure from where the body was built: the route's first corner
        return self.start + self.data.qpos[self.joints]

    def control(self) -> None:
        here = self.position()
        if np.hypot(*(self.route[self.target] - here)) < CORNER_REACHED:
            self.target = (self.target + 1) % len(self.route)
        offset = self.route[self.target] - here
        heading = offset / max(float(np.hypot(*offset)), 1e-6)
        velocity = self.walker.speed * heading
        if self._robot_ahead(here, heading):
            velocity = np.zeros(2)
        self.data.ctrl[self.actuators] = velocity

    def _robot_ahead(self, here: np.ndarray, heading: np.ndarray) -> bool:
        to_robot = self.data.xpos[self.robot][:2] - here
        distance = float(np.hypot(*to_robot))
        return distance < YIELD_DISTANCE and float(to_robot @ heading) > distance * math.cos(YIELD_ANGLE)
