"""People who walk loops through the scene: each drives their own velocity actuators along a route.

A walker heads for the next corner of their loop at their walking speed and,
like a polite person, stops while the robot (its base, or an arm that reaches
out) is close in front of them; when the robot stays in the way, they turn
back and walk their loop the other way round. This is the scene's script, so
it may look at where the robot really is; the robot itself knows walkers only
through its sensors.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from bt_humanoid.sim.world_config import Walker

CORNER_REACHED = 0.1  # m from a corner before heading for the next
YIELD_DISTANCE = 0.75  # m: a walker waits while the robot's centre is this close ahead (about to bump)
YIELD_ANGLE = math.radians(70)  # half-angle of "ahead"
PART_AHEAD = 0.6  # m: a walker also waits for any part of the robot this far ahead of them ...
PART_SIDEWAYS = 0.35  # m ... and this close to their line (their half-width and an arm's)
PATIENCE = 3.0  # s a walker waits for the robot before turning back


class WalkerDriver:
    """Commands one walker's actuators every control step."""

    def __init__(
        self, model: mujoco.MjModel, data: mujoco.MjData, name: str, walker: Walker, robot_root: int, robot: set[int]
    ) -> None:
        self.data = data
        self.walker = walker
        self.route = np.array(walker.route, dtype=float)
        self.joints = [model.joint(f"{name}_{axis}").qposadr[0] for axis in ("x", "y")]
        self.actuators = [model.actuator(f"{name}_{axis}").id for axis in ("x", "y")]
        self.robot = robot_root  # the body the robot's base joints move
        self.robot_parts = np.array(sorted(robot))  # every body of the robot
        self.target = 1 % len(self.route)
        self.direction = 1  # along the route's corners, or -1 the other way round
        self.start = self.route[0]
        self.waiting_since: float | None = None

    def position(self) -> np.ndarray:
        # slide joints measure from where the body was built: the route's first corner
        return self.start + self.data.qpos[self.joints]

    def control(self) -> None:
        here = self.position()
        if np.hypot(*(self.route[self.target] - here)) < CORNER_REACHED:
            self.target = (self.target + self.direction) % len(self.route)
        heading = self._heading(here)
        if not self._robot_ahead(here, heading):
            self.waiting_since = None
            self.data.ctrl[self.actuators] = self.walker.speed * heading
            return
        self.data.ctrl[self.actuators] = 0.0
        now = self.data.time
        self.waiting_since = now if self.waiting_since is None else self.waiting_since
        if now - self.waiting_since > PATIENCE:  # the robot stays in the way: walk the loop the other way
            self.direction = -self.direction
            self.target = (self.target + self.direction) % len(self.route)
            self.waiting_since = None

    def _heading(self, here: np.ndarray) -> np.ndarray:
        offset = self.route[self.target] - here
        return offset / max(float(np.hypot(*offset)), 1e-6)

    def _robot_ahead(self, here: np.ndarray, heading: np.ndarray) -> bool:
        to_robot = self.data.xpos[self.robot][:2] - here
        distance = float(np.hypot(*to_robot))
        if distance < YIELD_DISTANCE and float(to_robot @ heading) > distance * math.cos(YIELD_ANGLE):
            return True
        to_parts = self.data.xpos[self.robot_parts][:, :2] - here
        ahead = to_parts @ heading
        sideways = np.abs(to_parts[:, 0] * heading[1] - to_parts[:, 1] * heading[0])
        return bool(np.any((ahead > 0) & (ahead < PART_AHEAD) & (sideways < PART_SIDEWAYS)))
