"""Whole-body motions: the QP of control/wbc run at the control rate, driving base, waist, arms and head.

A goal (reach a hand pose, look at a point) is a set of tasks whose targets
move along a Ruckig trajectory. Each control step the controller solves the
QP at its reference configuration, integrates the step into new references
and streams them to the joint position controllers and the base driver.
Completion is judged on the measured configuration (the encoders), so a hand
held back by contact does not count as arrived.

On a walking robot the pelvis and legs are the walking controller's: the QP
moves the upper body only (waist, arms, head), from where the state estimator
and the leg encoders put the pelvis, and its references become the posture
targets of the walker's inverse-dynamics QP, where balance weighs more. The
robot steps to where it works (stance planning); its hands do not pull it there.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from ruckig import Trajectory

from bt_humanoid.control.base_motion import BaseMotion
from bt_humanoid.control.joint_motion import JointReferenceController
from bt_humanoid.control.motion import MotionHandle, plan_trajectory
from bt_humanoid.control.wbc import RobotKinematics
from bt_humanoid.control.wbc.compiled import CompiledQp, QpCache
from bt_humanoid.control.wbc.limits import JointPositionLimit, Limit, TorsoMarginLimit, VelocityLimit
from bt_humanoid.control.wbc.solver import BoxLimit
from bt_humanoid.control.wbc.symbolic_kinematics import symbolic_kinematics
from bt_humanoid.control.wbc.tasks import DampingTask, FrameTask, GazeTask, PostureTask, Task
from bt_humanoid.sim.robot_config import RobotConfig

HAND_SPEED = 0.3  # m/s along a reach
HAND_ACCEL = 0.8  # m/s^2
HAND_JERK = 6.0  # m/s^3
HAND_TURN_RATE = 1.2  # rad/s of hand orientation change
POSITION_TOLERANCE = 0.012  # m: measured hand within this of the target counts as arrived
ORIENTATION_TOLERANCE = 0.12  # rad
GAZE_TOLERANCE = 0.03  # rad between the optical axis and the direction to a look_at point
IN_VIEW = 0.35  # rad off the optical axis within which a point the head cannot centre (at a limit) is still seen
SETTLE_TIMEOUT = 1.5  # s after the trajectory ends before an unfinished reach fails
HAND_TORSO_MARGIN = 0.2  # m from the torso's vertical axis that the hands keep out of
ELBOW_TORSO_MARGIN = 0.25  # m for the elbows: keeps the upper arms off the chest
POSTURE_WEIGHT = 0.02  # pull of the working arm towards READY_POSTURE (redundancy resolution)
READY_POSTURE = "ready"
WAIST_WEIGHT = 0.3  # pull of the waist towards straight: it turns only when the arm alone falls short
BASE_WEIGHT = 1.0  # cost of base motion relative to arm motion (higher: the arm does more)
FAILED_SOLVES = 10  # consecutive QP failures before a goal gives up
CONTACT_LAG = 0.008  # m the measured hand lags its reference when something stops it (stop_on_contact)


@dataclass
class WholeBodyGoal:
    """Tasks and limits for one motion, plus where the moving target is along its path."""

    handle: MotionHandle
    tasks: list[Task]
    box_limits: list[BoxLimit]
    limits: list[Limit]
    start: float
    duration: float
    path: Trajectory | None = None  # over the path parameter s ∈ [0, 1]
    frame_task: FrameTask | None = None
    start_pose: pin.SE3 | None = None
    target_pose: pin.SE3 | None = None
    gaze_task: GazeTask | None = None
    tolerance: tuple[float, float] = (POSITION_TOLERANCE, ORIENTATION_TOLERANCE)
    stop_on_contact: bool = False
    touched: Callable[[], bool] | None = None  # senses the contact that stops it; None: the hand's lag
    failures: int = 0  # consecutive unsolved QPs
    position_error: float | None = None  # measured, once the path has ended
    qp: CompiledQp | None = None  # the tasks and limits compiled, when the goal starts


class ReachHandle(MotionHandle):
    """A reach's motion handle, which also says why a reach that failed fell short."""

    def __init__(self, description: str, on_cancel: Callable[[MotionHandle], None] | None = None) -> None:
        super().__init__(description, on_cancel)
        #: the commanded pose itself stopped short of the target: a limit (a joint's range, a keep-out, the
        #: torso's margin) held the hand back, not something it met; standing nearer is what helps
        self.out_of_reach = False


class WholeBodyController:
    """Runs one whole-body goal at a time over base, waist, arms and head."""

    def __init__(
        self,
        config: RobotConfig,
        base: BaseMotion,
        joints: JointReferenceController,
        joint_ranges: dict[str, tuple[float, float]],
        floating_state: Callable[[], np.ndarray] | None = None,
    ) -> None:
        self.config = config
        self.base = base
        self.joints = joints
        #: the planar base's x, y and yaw, which the QP moves with the body; none on a walking robot
        self.base_joints = config.base.planar_joints
        #: a walking robot's whole configuration as its walker estimates it (Pinocchio's q): the pelvis and legs
        #: the upper body stands on
        self.floating_state = floating_state
        if config.base.floating and floating_state is None:
            raise ValueError(f"robot '{config.name}' walks: give its walker's estimated configuration")
        body_joints = [j for group in config.groups.values() for j in group]
        self.names = self.base_joints + body_joints
        self.kinematics = RobotKinematics(config, self.names)  # at the reference configuration
        self.measured = RobotKinematics(config, self.names)  # at the encoder readings
        self._body_index = joints.indices(body_joints)
        lower = np.array([joint_ranges.get(j, (-np.inf, np.inf))[0] for j in self.names])
        upper = np.array([joint_ranges.get(j, (-np.inf, np.inf))[1] for j in self.names])
        limits = config.base.limits
        base_speeds = [limits.max_speed, limits.max_speed, limits.max_yaw_rate] if self.base_joints else []
        max_velocity = np.array(base_speeds + [config.motion_limits(j).velocity for j in body_joints])
        self.position_limit = JointPositionLimit(lower, upper)
        self.max_velocity = max_velocity
        margins = {g.grip_site: HAND_TORSO_MARGIN for g in config.grippers.values()}
        margins.update(
            {config.frames[f][1]: ELBOW_TORSO_MARGIN for f in ("left_elbow", "right_elbow") if f in config.frames}
        )
        self.torso_limit = TorsoMarginLimit(config.frames["torso"][1], margins)
        self.goal: WholeBodyGoal | None = None
        self.reference = np.zeros(len(self.names))
        self.base_target = np.zeros(3)  # pose the base holds during and after a whole-body goal
        self.solve_times: deque[float] = deque(maxlen=100_000)  # wall seconds per QP, for benchmarks
        self.conic_times: deque[float] = deque(maxlen=100_000)  # of which in the conic solver
        self.dt = 0.01
        # each kind of goal's QP is compiled once per process, from the kinematics in symbols
        self.qps = QpCache(symbolic_kinematics(config, self.names), self.kinematics)

    # ------------------------------------------------------------------ queries

    def measured_positions(self) -> np.ndarray:
        return np.concatenate([self._base_pose(), self.joints.io.positions()[self._body_index]])

    def frame_pose(self, frame: str) -> pin.SE3:
        """Where a frame is now, from the encoders."""
        self._update(self.measured, self.measured_positions())
        return self.measured.pose(frame).copy()

    def hand_frame(self, side: str) -> str:
        return self.config.grippers[side].grip_site

    # ------------------------------------------------------------------ goals

    def reach(
        self,
        side: str,
        target: pin.SE3,
        *,
        speed: float = HAND_SPEED,
        gaze: np.ndarray | None = None,
        move_base: bool = True,
        limits: list[Limit] | None = None,
        tolerance: tuple[float, float] = (POSITION_TOLERANCE, ORIENTATION_TOLERANCE),
        stop_on_contact: bool = False,
        touched: Callable[[], bool] | None = None,
    ) -> MotionHandle:
        """Move ``side``'s hand to ``target`` in a straight line, the rest of the body helping.

        With ``stop_on_contact`` the motion ends (successfully) as soon as
        whatever the hand holds has touched something, as when lowering an
        object onto a table: when ``touched()`` says so (a force sensor's
        reading), or else when the measured hand lags its reference by
        ``CONTACT_LAG`` (stiff arms only: a balancing robot's arm lags that
        much just moving).
        """
        self._begin()
        frame = self.hand_frame(side)
        self._update(self.kinematics, self.reference)
        start = self.kinematics.pose(frame).copy()
        distance = float(np.linalg.norm(target.translation - start.translation))
        angle = float(np.linalg.norm(pin.log3(target.rotation @ start.rotation.T)))
        # one path parameter for position and orientation: a straight line and a slerp, in step
        scale = max(distance / max(speed, 1e-3), angle / HAND_TURN_RATE, 1e-3)
        limits_s = (
            np.array([1.0 / scale]),
            np.array([HAND_ACCEL / max(distance, 0.05)]),
            np.array([HAND_JERK / max(distance, 0.05)]),
        )
        path = plan_trajectory(np.zeros(1), np.zeros(1), np.zeros(1), np.ones(1), limits_s)
        frame_task = FrameTask(frame, start.copy(), position_weight=1.0, orientation_weight=0.3, gain=0.6)
        tasks: list[Task] = [frame_task]
        other = [s for s in self.config.grippers if s != side]
        held = {j: self.reference[self.names.index(j)] for s in other for j in self._arm_joints(s)}
        tasks.append(PostureTask(held, weight=1.0, gain=0.5))
        # redundancy: pull the working arm and the lift towards the "ready" posture, and keep the waist straight
        # (a turned chest swings into the forearm of a hand held in front of it)
        ready = self.config.postures.get(READY_POSTURE, {})
        arm = [*self.config.groups.get("lift", []), *self._arm_joints(side)]
        preferred = {j: ready.get(j, self.reference[self.names.index(j)]) for j in arm}
        tasks.append(PostureTask(preferred, weight=POSTURE_WEIGHT, gain=0.05))
        tasks.append(PostureTask({j: 0.0 for j in self.config.groups.get("waist", [])}, WAIST_WEIGHT, gain=0.2))
        gaze_task = None
        if gaze is not None:
            gaze_task = GazeTask(self.config.frames["head_camera"][1], gaze)
            tasks.append(gaze_task)
        else:
            tasks.append(PostureTask({j: self.reference[self.names.index(j)] for j in self._head_joints()}, 1.0))
        if self.base_joints:
            tasks.append(DampingTask(self.base_joints, BASE_WEIGHT))
        frozen = [] if move_base else self.base_joints
        handle = ReachHandle(f"reaching {distance * 100:.0f} cm with the {side} hand", on_cancel=self._cancelled)
        self.goal = WholeBodyGoal(
            handle,
            tasks,
            self._box_limits(frozen),
            [self.torso_limit, *(limits or [])],
            self.joints.io.time,
            path.duration,
            path=path,
            frame_task=frame_task,
            start_pose=start,
            target_pose=target,
            gaze_task=gaze_task,
            tolerance=tolerance,
            stop_on_contact=stop_on_contact,
            touched=touched,
        )
        return handle

    def look_at(self, point: np.ndarray) -> MotionHandle:
        """Turn the head (only) so the camera looks at ``point``."""
        self._begin()
        camera = self.config.frames["head_camera"][1]
        gaze = GazeTask(camera, np.asarray(point, dtype=float), weight=1.0, gain=0.3)
        head = set(self._head_joints())
        hold = {j: self.reference[i] for i, j in enumerate(self.names) if j not in head}
        handle = MotionHandle("turning the head", on_cancel=self._cancelled)
        tasks = [gaze, PostureTask(hold, 1.0)]
        self.goal = WholeBodyGoal(
            handle, tasks, self._box_limits(list(hold)), [], self.joints.io.time, 0.0, gaze_task=gaze
        )
        return handle

    def cancel(self) -> None:
        """Drop the goal; references stop where they are (the joint controllers then hold them)."""
        if self.goal is not None:
            self.goal.handle.fail("halted")
            self.goal = None

    # ------------------------------------------------------------------ control step

    def step(self) -> None:
        goal = self.goal
        if goal is None:
            return
        elapsed = self.joints.io.time - goal.start
        if goal.path is not None:
            s = float(goal.path.at_time(min(elapsed, goal.duration))[0][0])
            goal.frame_task.target = pin.SE3.Interpolate(goal.start_pose, goal.target_pose, s)
        # the base is velocity-controlled and gets pushed by the arms' reactions: solve at its measured pose
        # (odometry) so the hand lands where it should in the world; the base itself tracks base_target
        base = len(self.base_joints)
        self.reference[:base] = self._base_pose()
        self._update(self.kinematics, self.reference)
        if goal.qp is None:
            goal.qp = self.qps.for_goal(goal.tasks, goal.box_limits, goal.limits, self.dt)
        solution = goal.qp.solve(self.reference, self.kinematics.q)
        self.solve_times.append(solution.solve_time)
        self.conic_times.append(solution.conic_time)
        goal.failures = 0 if solution.solved else goal.failures + 1
        if goal.failures >= FAILED_SOLVES:
            self._finish(goal, False, "whole-body QP has no solution: the target breaks a joint or safety limit")
            return
        self.reference = self.reference + solution.step
        velocity = solution.step / self.dt
        if self.base_joints:
            self.base_target = self.base_target + solution.step[:3]
            self.base.track(self.base_target, velocity[:3])
        self.joints.track(self._body_index, self.reference[base:], velocity[base:])
        self._check_done(goal, elapsed)

    # ------------------------------------------------------------------ internals

    def _begin(self) -> None:
        if self.goal is not None:
            self.goal.handle.fail("pre-empted by a newer goal")
            self.goal = None
        self.reference = np.concatenate([self._base_pose(), self.joints.position[self._body_index]])
        self.base_target = self.base.pose()

    def _box_limits(self, frozen: list[str]) -> list[BoxLimit]:
        """Position and velocity bounds for one goal; ``frozen`` joints get a zero speed limit."""
        speed = np.array([0.0 if name in frozen else v for name, v in zip(self.names, self.max_velocity, strict=True)])
        return [self.position_limit, VelocityLimit(speed)]

    def _check_done(self, goal: WholeBodyGoal, elapsed: float) -> None:
        if goal.stop_on_contact and goal.frame_task is not None:
            self._update(self.measured, self.measured_positions())
            frame = goal.frame_task.frame
            lag = self.kinematics.pose(frame).translation - self.measured.pose(frame).translation
            if goal.touched() if goal.touched is not None else np.linalg.norm(lag) > CONTACT_LAG:
                self.reference = self.measured_positions()  # stop pressing
                self.base_target = self.base.pose()
                self._finish(goal, True, "stopped on contact")
                return
        if elapsed < goal.duration:
            goal.handle.feedback = f"{goal.handle.description}: {elapsed:.1f}/{goal.duration:.1f} s"
            return
        self._update(self.measured, self.measured_positions())
        if goal.frame_task is not None:
            error = goal.frame_task.error(self.measured)
            goal.position_error = float(np.linalg.norm(error[:3]))
            arrived = goal.position_error <= goal.tolerance[0] and np.linalg.norm(error[3:]) <= goal.tolerance[1]
        else:  # look_at: only the gaze
            off = goal.gaze_task.off_axis(self.measured)
            arrived = off < GAZE_TOLERANCE
            if not arrived and off < IN_VIEW and elapsed > goal.duration + SETTLE_TIMEOUT:
                self._finish(goal, True, f"in view {np.degrees(off):.0f}° off centre (the head is at a limit)")
                return
        miss = goal.position_error
        if arrived:
            self._finish(goal, True, "arrived" if miss is None else f"arrived within {miss * 100:.1f} cm")
        elif elapsed > goal.duration + SETTLE_TIMEOUT:
            self._finish(goal, False, self._why_short(goal))

    def _why_short(self, goal: WholeBodyGoal) -> str:
        """Why a goal's hand did not arrive: it lags the pose it was sent to (blocked: something holds it), or
        that commanded pose itself stopped short (out of reach: a limit held the QP's answer back)."""
        if goal.frame_task is None or goal.position_error is None:
            return "blocked or out of reach"
        miss = f"hand stopped {goal.position_error * 100:.1f} cm from its target"
        self._update(self.kinematics, self.reference)
        frame = goal.frame_task.frame
        lag = float(np.linalg.norm(self.kinematics.pose(frame).translation - self.measured.pose(frame).translation))
        commanded = float(np.linalg.norm(goal.frame_task.error(self.kinematics)[:3]))
        if lag <= goal.tolerance[0] and commanded > goal.tolerance[0]:
            if isinstance(goal.handle, ReachHandle):
                goal.handle.out_of_reach = True
            return f"{miss}: out of reach (the joints' limits hold it {commanded * 100:.1f} cm short)"
        return f"{miss}: blocked ({lag * 100:.1f} cm behind where it was sent)"

    def _finish(self, goal: WholeBodyGoal, success: bool, message: str) -> None:
        self.goal = None
        if self.base_joints:
            self.base.track(self.base_target, np.zeros(3))
        if success:
            goal.handle.succeed(message)
        else:
            goal.handle.fail(message)

    def _cancelled(self, handle: MotionHandle) -> None:
        if self.goal is not None and self.goal.handle is handle:
            self.goal = None
            if self.base_joints:  # the base moved with the goal (a walking robot's steps are the walker's)
                self.base.brake()
            self.joints.brake(self._body_index)

    def _base_pose(self) -> np.ndarray:
        """The planar base's x, y, yaw by odometry; nothing on a walking robot."""
        return self.base.pose() if self.base_joints else np.zeros(0)

    def _update(self, kinematics: RobotKinematics, positions: np.ndarray) -> None:
        """Kinematics at ``positions`` of the controlled joints; on a walking robot, standing where its walker
        estimates the pelvis and its legs are."""
        if self.floating_state is not None:
            kinematics.q[:] = self.floating_state()
        kinematics.update(positions)

    def _arm_joints(self, side: str) -> list[str]:
        group = f"{side}_arm"
        return list(self.config.groups.get(group, []))

    def _head_joints(self) -> list[str]:
        return list(self.config.groups.get("head", []))


def yaw_rotation(yaw: float) -> np.ndarray:
    """Rotation about world z; a hand at this orientation points its fingers down, closing along x rotated by yaw."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
