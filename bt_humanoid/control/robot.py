"""The robot as skills see it: one object owning every controller.

The executor calls ``step()`` at the control rate; skills send goals through
``base``, ``joints`` and ``grippers`` and poll the returned handles;
``brake()`` halts every motion so the robot comes to rest.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from bt_humanoid.control.base_driver import BaseDriver
from bt_humanoid.control.base_motion import BaseMotion, SpeedLimiter
from bt_humanoid.control.gripper import GripperController
from bt_humanoid.control.inertial_feedforward import BaseAccelerationFeedforward
from bt_humanoid.control.joint_motion import JointReferenceController
from bt_humanoid.control.motion import REST_SPEED
from bt_humanoid.control.payload import WristScale
from bt_humanoid.control.walking.walking_base import WalkingBase
from bt_humanoid.control.whole_body import WholeBodyController
from bt_humanoid.localisation.base import BaseLocalisation
from bt_humanoid.localisation.planar import planar_localisation
from bt_humanoid.localisation.walking import walking_localisation
from bt_humanoid.sim.robot_config import RobotConfig
from bt_humanoid.sim.robot_io import MujocoRobotIO
from bt_humanoid.sim.simulation import Simulation


class Planner(Protocol):
    """Something that streams goals to the controllers every control step (the navigator does)."""

    def step(self) -> None: ...

    def halt(self) -> None: ...


class Separation(SpeedLimiter, Protocol):
    """Speed and separation monitoring: updated every control step, before anything moves."""

    def update(self, base_pose: np.ndarray) -> None: ...

    @property
    def near_points(self) -> np.ndarray:
        """(N, 2) floor points the scanner sensed near the robot, not furniture, as of the last scan."""
        ...


class RobotController:
    """Base driver, joint references and grippers of one robot."""

    def __init__(self, sim: Simulation) -> None:
        self.config: RobotConfig = sim.robot
        self.walking: WalkingBase | None = None
        self.localisation: BaseLocalisation | None = None
        if self.config.base.floating:  # legs: the walking controller drives them, and the upper body's servos
            self.walking = WalkingBase(sim)
            self.walking.localisation = self.localisation = walking_localisation(sim, self.walking)
            legs = self.config.legs
            assert legs is not None
            self.body_io = MujocoRobotIO(sim, [j for j in self.config.actuated_joints if j not in legs.joints])
            self.base: BaseMotion = self.walking  # skills see its BaseMotion
            driven = [j for j in self.walking.walker.held if j in self.body_io.joints]  # the fingers
            self.joints = JointReferenceController(self.body_io, self.config, driven=driven)
            self._upper_body = self.joints.indices(self.walking.walker.upper_body.joints)
        else:
            base_io = MujocoRobotIO(sim, self.config.base.planar_joints)
            self.body_io = MujocoRobotIO(sim, self.config.actuated_joints)
            #: where the base believes it is: wheel odometry corrected by the scanner (none: exact, --ideal-sensors)
            self.localisation = planar_localisation(sim, base_io)
            self.base = BaseDriver(base_io, self.config.base, self.localisation)  # skills see its BaseMotion
            self.joints = JointReferenceController(self.body_io, self.config)
        self.grippers = GripperController(self.joints, self.config.grippers)
        io = self.body_io
        ranges = {j: (io.lower[i], io.upper[i]) for i, j in enumerate(io.joints) if io.limited[i]}
        #: whole-body motions (reaching, gaze): over a planar base, or a walking robot's upper body
        self.feedforward: BaseAccelerationFeedforward | None = None
        walker = self.walking.walker if self.walking is not None else None
        estimated = self.walking.configuration if self.walking is not None else None
        self.whole_body = WholeBodyController(self.config, self.base, self.joints, ranges, estimated)
        if walker is None:
            self.feedforward = BaseAccelerationFeedforward(self.config, self.body_io, self.config.base.planar_joints)
        #: a legged robot's wrist sensors weigh what it lifts, and its balance counts that mass (``weigh``)
        self.scale = WristScale(self.config, walker.io, walker.dynamics) if walker is not None else None
        self.planners: list[Planner] = []  # run before the controllers each step (the navigator)
        self.separation: Separation | None = None  # set with monitor_separation()
        self.control_period = 0.01  # s between step() calls; the executor sets it

    def wrist_force(self, side: str, in_world: bool = False) -> np.ndarray | None:
        """What the wrist's force sensor reads (N): the force the wrist exerts on the hand and what it holds, in
        the sensor's frame, or turned into the world's by the arm's pose from the encoders (``in_world``); None
        for a hand without one (robot.yaml)."""
        sensor = self.config.grippers[side].wrist_force
        if sensor is None:
            return None
        reading = self.body_io.sensor(sensor).copy()
        if not in_world:
            return reading
        return self.whole_body.frame_pose(self.body_io.sensor_site(sensor)).rotation @ reading

    def set_control_period(self, period: float) -> None:
        """Seconds between ``step()`` calls: the whole-body QP integrates its step over this."""
        self.control_period = period
        self.whole_body.dt = period

    def monitor_separation(self, separation: Separation) -> None:
        """Slow the base near people and things it senses (``separation.share`` limits every base motion)."""
        self.separation = separation
        self.base.limiter = separation

    def step(self) -> None:
        base_pose = self.base.pose()  # the encoders of this instant: nothing moves until the physics steps
        if self.separation is not None:
            self.separation.update(base_pose)
        for planner in self.planners:
            planner.step()
        self.whole_body.step()  # streams references first, the controllers below then track them
        self.base.step()
        if self.feedforward is not None:
            acceleration = self.base.acceleration  # type: ignore[attr-defined]
            self.joints.feedforward = self.feedforward.update(base_pose, self.body_io.positions(), acceleration)
        self.joints.step()
        if self.walking is not None:  # the upper body's references become the balance QP's posture targets
            joints, upper = self.joints, self._upper_body
            self.walking.walker.upper_body.set_target(
                joints.position[upper], joints.velocity[upper], joints.acceleration[upper]
            )
        self.grippers.step()
        if self.scale is not None:
            self.scale.update(self.control_period)
            for side in self.scale.sensors:  # a hand that let go (or lost its hold) carries nothing
                if self.scale.carried(side) > 0.0 and not self.grippers.holding(side):
                    self.scale.carry(side, 0.0)

    def weighs(self, side: str) -> bool:
        """Whether ``weigh`` tells the ``side`` hand's load: a wrist sensor, and a balance that needs it."""
        return self.scale is not None and side in self.scale.sensors

    def load(self, side: str) -> float | None:
        """What the ``side`` hand's wrist sensor reads it holds now (kg), without balancing with it; None
        where ``weighs`` is false."""
        return self.scale.weigh(side) if self.scale is not None and self.weighs(side) else None

    def weigh(self, side: str) -> float | None:
        """Weigh what the ``side`` hand holds (kg) and, on legs, balance with it from now until it lets go; None
        for a robot without a wrist sensor on that hand, or with no balance to tell (a wheeled base)."""
        mass = self.load(side)
        if mass is None or self.scale is None:
            return None
        self.scale.carry(side, mass)
        return mass

    def brake(self) -> None:
        """Halt every motion: base and joints decelerate to rest under their limits."""
        for planner in self.planners:
            planner.halt()
        self.whole_body.cancel()
        self.base.brake()
        self.joints.brake()

    def frame_position(self, frame: str) -> np.ndarray:
        """Where a frame of the robot's model is (world), from the encoders and odometry."""
        return self.whole_body.frame_pose(frame).translation.copy()

    def hand_position(self, side: str) -> np.ndarray:
        """Where the ``side`` gripper's grip point is (world)."""
        return self.frame_position(self.config.grippers[side].grip_site)

    def joint_positions(self) -> dict[str, float]:
        return dict(zip(self.body_io.joints, self.body_io.positions().tolist(), strict=False))

    def max_speed(self) -> float:
        """Fastest joint or base speed now (m/s or rad/s)."""
        return float(max(np.max(np.abs(self.base.speeds())), np.max(np.abs(self.body_io.velocities()))))

    def at_rest(self) -> bool:
        return self.max_speed() < REST_SPEED
