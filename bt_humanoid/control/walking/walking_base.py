"""A legged robot's base motion: the calls skills and the navigator make of a base, answered with footsteps.

``WalkingBase`` is the biped's ``BaseMotion`` (the wheeled robot's is ``BaseDriver``). It owns the
``WalkingController``, which runs every physics step (``Simulation.physics_controllers``); ``step()``, at the
control rate, turns what was asked into what the walker takes:

- a pose goal (``move_to``) becomes a goal for the middle of the feet (``WalkingController.walk_to``): the
  base frame (the pelvis) stands ``stance_offset`` from it. A turn of more than half a circle
  (``shortest_turn=False``) is fed a quarter turn at a time. The handle succeeds once the robot stands with the
  pelvis within ``base.tolerance`` of the goal;
- a streamed reference (``track``: the route follower's, a whole-body motion's) becomes a body velocity: the
  reference's velocity plus a correction of the error, in the body's frame, under the base's limits;
- ``brake`` stops within two steps.

Odometry (``odometry_pose``) is the state estimator's: the pelvis from the IMU, encoders and foot contacts,
never the simulator's free joint; ``pose`` and ``speeds`` are on the map, the odometry corrected by the base
scanner (``localisation``, set by the robot). Speed and separation monitoring scales every velocity as on the
wheeled base.
"""

from __future__ import annotations

import math

import numpy as np

from bt_humanoid.control.base_motion import SpeedMonitoring
from bt_humanoid.control.motion import MotionHandle
from bt_humanoid.control.walking.walker import SET_OFF_DISTANCE, Phase, WalkingController
from bt_humanoid.localisation.frames import turned
from bt_humanoid.localisation.walking import WalkingLocalisation
from bt_humanoid.sim.simulation import Simulation
from bt_humanoid.sim.standing import standing_posture

POSITION_GAIN = 1.0  # 1/s: body velocity per metre (radian) of error from a streamed reference
LARGEST_TURN = math.pi / 2  # rad of a long turn fed to the walker at once (its goals wrap at half a circle)
GOAL_TIMEOUT = 10.0  # s beyond the time a pose goal should take at the allowed speeds before it fails
SETTLED_SPEED = 0.02  # m/s of the pelvis below which a robot standing after its last step has settled
OFFSET_FILTER = 0.01  # per control step: the pelvis's offset from the centre of mass, averaged over about a second


def wrap(angle: float) -> float:
    return math.remainder(angle, 2 * math.pi)


class WalkingBase(SpeedMonitoring):
    """``BaseMotion`` for a robot that walks (robot.yaml ``base.kind: floating`` with ``legs``)."""

    def __init__(self, sim: Simulation, posture: str = "home") -> None:
        self.sim = sim
        self.config = sim.robot.base
        self.walker = WalkingController(sim, posture)
        sim.physics_controllers.append(self.walker.step)
        self.walker.observe()  # odometry from the first instant, before any physics step
        #: the map's correction of the walker's odometry (none: the odometry is the pose, --ideal-sensors)
        self.localisation: WalkingLocalisation | None = None
        stance = standing_posture(sim.robot, posture=posture)
        #: the pelvis from the centre of mass, which stands over the middle of the feet, in the body's frame: the
        #: stance's to start with, then as measured (``step``)
        self.stance_offset = stance.qpos[:2] - stance.com[:2]
        self.speed_cap = self.config.limits.max_speed
        self.handle: MotionHandle | None = None
        self.target: np.ndarray | None = None  # a pose goal's base pose (yaw unwrapped)
        self.goal_speed = 0.0
        self.arrival = self.config.tolerance.position  # m: the goal counts as reached this near
        self.deadline = 0.0
        self.reference: np.ndarray | None = None  # a streamed reference (track)
        self.reference_velocity = np.zeros(3)
        self.acceleration = np.zeros(3)  # what the inertial feedforward reads on a wheeled base; a biped's is its own
        self._yaw = self.pose()[2]  # unwrapped, for turns of more than half a circle
        self._last_yaw = self._yaw

    # --- odometry ------------------------------------------------------------------------------------------------

    @property
    def time(self) -> float:
        return self.sim.time

    def odometry_pose(self) -> np.ndarray:
        """(x, y, yaw) of the pelvis in the state estimator's own frame (legged odometry: it drifts)."""
        state = self.walker.state
        assert state is not None
        return np.array([state.position[0], state.position[1], state.yaw])

    def pose(self) -> np.ndarray:
        """(x, y, yaw) of the pelvis on the map: the odometry, corrected by localisation where there is one."""
        if self.localisation is not None:
            return self.localisation.pose()
        return self.odometry_pose()

    def configuration(self) -> np.ndarray:
        """The whole robot's configuration as the walker estimates it (Pinocchio's q), its pelvis on the map: what
        the upper body's motions stand on."""
        q = self.walker.dynamics.q
        return self.localisation.configuration_on_map(q) if self.localisation is not None else q

    def speeds(self) -> np.ndarray:
        state = self.walker.state
        assert state is not None
        speeds = np.array([state.linear_velocity[0], state.linear_velocity[1], state.angular_velocity[2]])
        if self.localisation is not None:  # the odometry's axes turned onto the map's
            return turned(speeds, self.localisation.turn())
        return speeds

    def settled(self) -> bool:
        """Standing after the last step, the centre of mass come to rest over the middle of the feet."""
        return self.walker.phase is Phase.STANDING and float(np.hypot(*self.speeds()[:2])) < SETTLED_SPEED

    def capped(self, requested: float | None = None) -> float:
        return min(requested if requested is not None else math.inf, self.speed_cap, self.config.limits.max_speed)

    # --- motions -------------------------------------------------------------------------------------------------

    def move_to(
        self,
        x: float,
        y: float,
        yaw: float,
        max_speed: float | None = None,
        shortest_turn: bool = True,
        tolerance: float | None = None,
    ) -> MotionHandle:
        if self.handle is not None:
            self.handle.fail("pre-empted by a newer goal")
        start = self.pose()
        turn = wrap(yaw - start[2]) if shortest_turn else yaw - start[2]
        self.target = np.array([x, y, self._yaw + turn])
        # finer than the walker's set-off distance, a standing robot would never step to arrive
        self.arrival = max(self.config.tolerance.position if tolerance is None else tolerance, SET_OFF_DISTANCE)
        self.goal_speed = self.capped(max_speed)
        self.reference = None
        distance = float(np.hypot(x - start[0], y - start[1]))
        limits = self.config.limits
        # straight there, turning as it goes, at what the legs can do along the slowest axis (sideways, mostly)
        forward, _, sideways, turning = self.walker.capabilities()
        c, s = math.cos(start[2]), math.sin(start[2])
        along, across = abs(c * (x - start[0]) + s * (y - start[1])), abs(-s * (x - start[0]) + c * (y - start[1]))
        expected = max(
            along / min(forward, self.goal_speed), across / sideways, abs(turn) / min(turning, limits.max_yaw_rate)
        )
        self.deadline = self.time + 2 * expected + GOAL_TIMEOUT
        self.reset_hold()
        self.handle = MotionHandle(f"walking {distance:.2f} m", on_cancel=lambda _: self.brake())
        return self.handle

    def track(self, reference: np.ndarray, velocity: np.ndarray) -> None:
        if self.handle is not None:
            self.handle.fail("pre-empted by a whole-body motion")
            self.handle = None
        self.target = None
        self.reference = np.array(reference, dtype=float)
        self.reference_velocity = np.array(velocity, dtype=float)

    def brake(self) -> None:
        if self.handle is not None:
            self.handle.fail("halted: braking")
            self.handle = None
        self.target = self.reference = None
        self.walker.brake()

    # --- the control step ----------------------------------------------------------------------------------------

    def step(self) -> None:
        """Turn the goal or the streamed reference into the walker's command (at the control rate)."""
        if self.localisation is not None:
            self.localisation.step()
        pose = self.pose()
        self._yaw += wrap(pose[2] - self._last_yaw)
        self._last_yaw = pose[2]
        # the pelvis from the centre of mass, which the walker stands over the middle of the feet: it moves when
        # the arms do (tucked, holding something), and a goal for the pelvis is one for the feet offset by it
        com, odometry = self.walker.dynamics.com, self.odometry_pose()  # both in the estimator's frame
        c, s = math.cos(odometry[2]), math.sin(odometry[2])
        dx, dy = odometry[0] - com[0], odometry[1] - com[1]
        measured = np.array([c * dx + s * dy, -s * dx + c * dy])
        self.stance_offset += OFFSET_FILTER * (measured - self.stance_offset)
        if self.target is not None:
            self._towards_goal(pose)
        elif self.reference is not None:
            self._follow_reference(pose)

    def _towards_goal(self, pose: np.ndarray) -> None:
        assert self.target is not None
        x, y, yaw = self.target
        remaining_turn = yaw - self._yaw
        heading = self._yaw + float(np.clip(remaining_turn, -LARGEST_TURN, LARGEST_TURN))
        share = self.allowed_share(np.array([self.goal_speed, self.goal_speed, self.config.limits.max_yaw_rate]))
        held = self.held_too_long(share, self.time)
        handle = self.handle
        if held is not None and handle is not None:
            handle.fail(held)
            self.brake()
            return
        self._walk_to(x, y, heading, share * self.goal_speed, share * self.config.limits.max_yaw_rate)
        if handle is None:
            return
        error = float(np.hypot(x - pose[0], y - pose[1]))
        yaw_error = abs(math.degrees(remaining_turn))
        handle.feedback = f"{error:.2f} m to go, heading off by {yaw_error:.0f}°"
        # standing, and settled: the centre of mass comes to rest over the middle of the feet after the last step
        if self.settled() and error < self.arrival and yaw_error < self.config.tolerance.yaw_deg:
            handle.succeed(f"arrived within {error * 100:.1f} cm, {yaw_error:.1f}°")
            self.handle = None
            self.target = None
            self.walker.brake()  # arrived: stand here, whatever the arms do next
        elif self.time > self.deadline:
            handle.fail(f"stopped {error:.2f} m and {yaw_error:.0f}° from the goal")
            self.brake()

    def _walk_to(self, x: float, y: float, yaw: float, speed: float, yaw_rate: float) -> None:
        """Have the walker put the pelvis on (x, y, yaw): the middle of the feet ``stance_offset`` from it."""
        c, s = math.cos(yaw), math.sin(yaw)
        ox, oy = self.stance_offset
        feet = np.array([x - (c * ox - s * oy), y - (s * ox + c * oy), yaw])
        if self.localisation is not None:  # the walker steps in its own odometry's frame
            feet = self.localisation.to_odometry(feet)
        self.walker.walk_to(float(feet[0]), float(feet[1]), float(feet[2]), speed, yaw_rate)

    def _follow_reference(self, pose: np.ndarray) -> None:
        assert self.reference is not None
        if not np.any(np.abs(self.reference_velocity) > 1e-3):  # a reference at rest: stand on it, precisely
            self._walk_to(*self.reference, self.capped(), self.config.limits.max_yaw_rate)
            return
        error = self.reference - pose
        error[2] = wrap(error[2])
        world = self.reference_velocity + POSITION_GAIN * error
        share = self.allowed_share(world)
        c, s = math.cos(pose[2]), math.sin(pose[2])
        body = np.array([c * world[0] + s * world[1], -s * world[0] + c * world[1], world[2]]) * share
        limits = self.config.limits
        speed = float(np.hypot(body[0], body[1]))
        if speed > self.capped():
            body[:2] *= self.capped() / speed
        body[1] = float(np.clip(body[1], -limits.sideways_speed, limits.sideways_speed))
        body[2] = float(np.clip(body[2], -limits.max_yaw_rate, limits.max_yaw_rate))
        self.walker.command(*body)
