"""The MuJoCo world: model, data, reset, stepping and name lookups.

Ground-truth queries live in ground_truth.py; the robot's own view of itself
(joint encoders, actuator commands) goes through robot_io.py.
"""

from __future__ import annotations

import math
import os

# Off-screen rendering without a display needs EGL; set before mujoco loads.
os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco
import numpy as np

from bt_humanoid.sim.assembly import world_spec
from bt_humanoid.sim.robot_config import RobotConfig, load_robot_config
from bt_humanoid.sim.scene_config import SceneConfig, load_scene, start_pose
from bt_humanoid.sim.scene_objects import place_scene, surface_tops
from bt_humanoid.sim.walkers import WalkerDriver
from bt_humanoid.sim.world_config import WorldConfig, load_world_config


class Simulation:
    """One robot in one world, stepped on simulation time."""

    def __init__(self, world: WorldConfig, robot: RobotConfig, scene: SceneConfig | None = None) -> None:
        self.world = world
        self.robot = robot
        if scene is None and world.scene is not None:
            scene = load_scene(world, world.scene)
        self.scene = scene
        placed = place_scene(world, scene, surface_tops(world)) if scene is not None else []
        #: every object of the run by its name ("coke 2") → its body; the world's fixed objects and the scene's
        self.object_bodies = {name: o.body for name, o in world.objects.items() if o.body is not None}
        self.object_bodies |= {p.name: p.body for p in placed}
        #: and → the world object it is one of ("coke 2" → "coke"; a fixed object is itself)
        self.object_kinds = {name: name for name, o in world.objects.items() if o.body is not None}
        self.object_kinds |= {p.name: p.object for p in placed}
        self.spec = world_spec(world, robot, placed)
        self.model = self.spec.compile()
        self.data = mujoco.MjData(self.model)
        self.timestep = float(self.model.opt.timestep)
        root = int(self.model.body_rootid[self.model.joint(robot.base.joints["x"]).bodyid[0]])
        #: every body of the robot: the tree under the body its base joints move
        self.robot_bodies = {b for b in range(self.model.nbody) if self.model.body_rootid[b] == root}
        self.walkers = [
            WalkerDriver(self.model, self.data, name, walker, root, self.robot_bodies)
            for name, walker in world.walkers.items()
        ]
        self.reset()

    @classmethod
    def load(cls, world: str, robot: str, scene: str | None = None) -> Simulation:
        """By names (and a scene by name or path; none: the world's own scene, if it has one)."""
        config = load_world_config(world)
        return cls(config, load_robot_config(robot), load_scene(config, scene) if scene is not None else None)

    @property
    def time(self) -> float:
        return float(self.data.time)

    def reset(self, seed: int = 0) -> None:
        """Initial state: robot at the world's start pose in its home posture, actuators holding it."""
        mujoco.mj_resetData(self.model, self.data)
        x, y, yaw_deg = start_pose(self.scene, self.world)
        base = self.robot.base.joints
        self.set_initial_joint(base["x"], x)
        self.set_initial_joint(base["y"], y)
        self.set_initial_joint(base["yaw"], math.radians(yaw_deg))
        for joint, value in self.robot.postures.get("home", {}).items():
            self.set_initial_joint(joint, value)
        for joint in self.robot.actuated_joints:
            actuator = self.actuator_for_joint(joint)
            self.data.ctrl[actuator] = self.data.qpos[self.model.joint(joint).qposadr[0]]
        self.seed = seed  # the run's seed: whatever draws random numbers (route planning) starts from it
        self.rng = np.random.default_rng(seed)
        mujoco.mj_forward(self.model, self.data)

    def set_initial_joint(self, joint: str, value: float) -> None:
        """Initial conditions only (reset and test set-up), never to move things."""
        self.data.qpos[self.model.joint(joint).qposadr[0]] = value

    def step(self, n: int = 1) -> None:
        for walker in self.walkers:  # the scene's people act at the caller's rate (the control period)
            walker.control()
        mujoco.mj_step(self.model, self.data, nstep=n)

    def actuator_for_joint(self, joint: str) -> int:
        """Index of the actuator that drives ``joint``."""
        joint_id = self.model.joint(joint).id
        for i in range(self.model.nu):
            if (
                self.model.actuator_trntype[i] == mujoco.mjtTrn.mjTRN_JOINT
                and self.model.actuator_trnid[i, 0] == joint_id
            ):
                return i
        raise KeyError(f"no actuator drives joint '{joint}'")
