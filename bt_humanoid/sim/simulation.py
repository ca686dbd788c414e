"""The MuJoCo world: model, data, reset, stepping and name lookups.

Ground-truth queries live in ground_truth.py; the robot's own view of itself
(joint encoders, actuator commands) goes through robot_io.py.
"""

from __future__ import annotations

import math
import os
import zlib
from collections.abc import Callable

# Off-screen rendering without a display needs EGL; set before mujoco loads.
os.environ.setdefault("MUJOCO_GL", "egl")

import cv2
import mujoco
import numpy as np

from bt_humanoid.errors import UserError
from bt_humanoid.sim.assembly import world_spec
from bt_humanoid.sim.holding import CARRY_POSTURE, SQUEEZE, Hold, hold_for
from bt_humanoid.sim.people import PersonDriver
from bt_humanoid.sim.robot_config import RobotConfig, load_robot_config
from bt_humanoid.sim.scene_config import SceneConfig, load_scene, start_pose
from bt_humanoid.sim.scene_objects import PlacedObject, SceneError, place_scene, surface_tops
from bt_humanoid.sim.sensor_models import SensorModels, ideal_sensors_requested
from bt_humanoid.sim.standing import Stance, standing_posture
from bt_humanoid.sim.walkers import WalkerDriver
from bt_humanoid.sim.world_config import WorldConfig, load_world_config

# OpenCV splits its work over the cores the process may use, and its results then differ in the last bits with
# their number (a fetch episode ended otherwise pinned to one core than free on two): one thread, so a run is the
# same run on any machine
cv2.setNumThreads(1)


class Simulation:
    """One robot in one world, stepped on simulation time."""

    def __init__(self, world: WorldConfig, robot: RobotConfig, scene: SceneConfig | None = None) -> None:
        self.world = world
        self.robot = robot
        #: what the robot's sensors add to the truth: robot.yaml's models, or none (--ideal-sensors)
        self.sensors = SensorModels.ideal() if ideal_sensors_requested() else robot.sensors
        self._random_streams: dict[str, np.random.Generator] = {}
        #: places a pose a body-mounted sensor measured in the world (MuJoCo's frame) on the robot's map: through
        #: where the robot believes its base is (set by localisation; exact where there is none)
        self.on_map: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]] = _exact_pose
        if scene is None and world.scene is not None:
            scene = load_scene(world, world.scene)
        self.scene = scene
        try:
            placed = place_scene(world, scene, surface_tops(world)) if scene is not None else []
        except SceneError as error:  # a scene made in code (a random draw); files are checked when loaded
            raise UserError(error.message, where=scene.where(*error.path) if scene is not None else None) from None
        #: the object the robot holds at the start (a scene's holding:), and how its hand holds it
        self.held: PlacedObject | None = next((p for p in placed if p.hand is not None), None)
        self.hold: Hold | None = None
        if self.held is not None:
            self.hold = self._check_hold(self.held)
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
        root = int(self.model.body_rootid[self.model.joint(robot.base.root_joint).bodyid[0]])
        #: every body of the robot: the tree under the body its base joints move
        self.robot_bodies = {b for b in range(self.model.nbody) if self.model.body_rootid[b] == root}
        self.robot_root = self.model.body(root).name  # that body's name ("base" on wheels, "pelvis" on legs)
        #: called before every physics step: controllers that must run at the physics rate (a biped's balance
        #: controller: its legs are torque-controlled, and a torque holds only until the next command)
        self.physics_controllers: list[Callable[[], None]] = []
        self.walkers = [
            WalkerDriver(self.model, self.data, name, walker, self.robot_bodies)
            for name, walker in world.walkers.items()
        ]
        #: the people who take what the robot hands them (their arms' scripts)
        self.people = {
            name: PersonDriver(self.model, self.data, person.body, person.takes, self.object_bodies, self.robot_bodies)
            for name, person in world.people.items()
        }
        #: a legged robot starts standing: its neutral stance, placed at the start pose
        self.stance: Stance | None = standing_posture(robot) if robot.legs is not None else None
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
        if self.stance is not None:  # feet flat on the floor, centred on the start; the motors start off
            free = self.model.joint(self.robot.base.root_joint).qposadr[0]
            self.data.qpos[free : free + 7] = self.stance.base_pose(x, y, math.radians(yaw_deg))
            for joint, value in self.stance.joints.items():
                self.set_initial_joint(joint, value)
        else:
            base = self.robot.base.joints
            self.set_initial_joint(base["x"], x)
            self.set_initial_joint(base["y"], y)
            self.set_initial_joint(base["yaw"], math.radians(yaw_deg))
        for joint, value in self.robot.postures.get("home", {}).items():
            self.set_initial_joint(joint, value)
        if self.held is not None:
            self._hand_over(self.held)
        for joint in self.robot.actuated_joints:
            actuator = self.actuator_for_joint(joint)
            self.data.ctrl[actuator] = self.data.qpos[self.model.joint(joint).qposadr[0]]
        if self.held is not None:  # the hand closed on what it was handed: its fingers press on it
            gripper = self.robot.grippers[self.held.hand]  # type: ignore[index]
            for joint in gripper.joints:
                self.data.ctrl[self.actuator_for_joint(joint)] = gripper.closed
        self.seed = seed  # the run's seed: whatever draws random numbers (route planning) starts from it
        self.rng = np.random.default_rng(seed)
        self._random_streams.clear()
        for walker in self.walkers:
            walker.reset(self.random_stream(f"walker {walker.name}"))
        for person in self.people.values():
            person.reset()
        mujoco.mj_forward(self.model, self.data)

    def random_stream(self, name: str) -> np.random.Generator:
        """A named random stream (a sensor's noise, a walker's choices) from the run's seed: the same seed gives the
        same draws, and one stream's draws do not shift another's (or route planning's)."""
        if name not in self._random_streams:
            self._random_streams[name] = np.random.default_rng([self.seed, zlib.crc32(name.encode())])
        return self._random_streams[name]

    def _check_hold(self, held: PlacedObject) -> Hold:
        """How the hand holds the scene's object; a UserError when this robot cannot hold it so."""
        model = self.world.objects[held.object].model
        assert model is not None and held.hand is not None  # checked when the scene was loaded
        where = self.scene.where("holding") if self.scene is not None else None
        if held.hand not in self.robot.grippers:
            raise UserError(
                f"holding: robot '{self.robot.name}' has no {held.hand} hand",
                where=where,
                hint=f"valid: {', '.join(self.robot.grippers)}",
            )
        if CARRY_POSTURE not in self.robot.postures:
            raise UserError(
                f"holding: robot '{self.robot.name}' has no '{CARRY_POSTURE}' posture to hold things in (robot.yaml)",
                where=where,
            )
        hold = hold_for(model)
        gripper = self.robot.grippers[held.hand]
        opening = 2 * (gripper.open - gripper.closed)
        if hold.width >= opening:
            raise UserError(
                f"holding: the {held.object} is {hold.width * 100:.1f} cm across; "
                f"the {held.hand} gripper opens {opening * 100:.1f} cm",
                where=where,
            )
        return hold

    def _hand_over(self, held: PlacedObject) -> None:
        """Initial conditions: the arm in its carrying posture, the object between the pads, the fingers on it.

        Nothing holds it there but the fingers' squeeze and friction, from the first step on.
        """
        assert self.hold is not None and held.hand is not None
        arm = set(self.robot.groups.get(f"{held.hand}_arm", []))
        for joint, value in self.robot.postures[CARRY_POSTURE].items():
            if joint in arm or joint in self.robot.groups.get("lift", []):
                self.set_initial_joint(joint, value)
        gripper = self.robot.grippers[held.hand]
        for joint in gripper.joints:  # each finger's pad at the object's side, pressed in a little
            self.set_initial_joint(joint, self.hold.width / 2 - SQUEEZE)
        mujoco.mj_kinematics(self.model, self.data)
        site = self.model.site(gripper.grip_site).id
        hand = self.data.site_xmat[site].reshape(3, 3)  # pointing down: its z axis is up, the pads close along x
        turn = self.hold.turn
        turned = hand @ np.array([[math.cos(turn), -math.sin(turn), 0], [math.sin(turn), math.cos(turn), 0], [0, 0, 1]])
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, turned.flatten())
        position = self.data.site_xpos[site] - self.hold.grip_height * hand[:, 2]
        body = self.model.body(held.body).id
        address = self.model.jnt_qposadr[self.model.body_jntadr[body]]
        self.data.qpos[address : address + 7] = np.concatenate([position, quat])

    def head_angles_towards(self, point: np.ndarray) -> tuple[float, float]:
        """Head pan and tilt (rad, unclipped) that would point the head at ``point`` from the current state.

        For set-up (a test or benchmark view); a running robot aims its camera through its controllers.
        """
        tilt_joint = self.robot.head_tilt
        if tilt_joint is None:
            raise ValueError(f"robot '{self.robot.name}' has no head to aim")
        head = self.data.xpos[self.model.jnt_bodyid[self.model.joint(tilt_joint).id]]
        base_yaw = float(self.data.qpos[self.model.joint(self.robot.base.joints["yaw"]).qposadr[0]])
        offset = np.asarray(point) - head
        pan = math.remainder(math.atan2(offset[1], offset[0]) - base_yaw, 2 * math.pi)
        return pan, math.atan2(-offset[2], math.hypot(offset[0], offset[1]))

    def set_initial_joint(self, joint: str, value: float) -> None:
        """Initial conditions only (reset and test set-up), never to move things."""
        self.data.qpos[self.model.joint(joint).qposadr[0]] = value

    def step(self, n: int = 1) -> None:
        for walker in self.walkers:  # the scene's people act at the caller's rate (the control period)
            walker.control()
        for person in self.people.values():
            person.control()
        if not self.physics_controllers:
            mujoco.mj_step(self.model, self.data, nstep=n)
            return
        for _ in range(n):  # a legged robot's balance runs every physics step, inside the caller's period
            for control in self.physics_controllers:
                control()
            mujoco.mj_step(self.model, self.data)

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


def _exact_pose(position: np.ndarray, rotation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return position, rotation
