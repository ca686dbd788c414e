"""Safety monitors, evaluated once per tick by the supervisor that every Safety guard reads.

Two kinds:

- a **Monitor** guards the whole mission (a stop request, a collision, a joint past its range or speed, the
  workspace, the time budget). Its first violation latches: every guard then halts its branch, the tree
  fails, and the executor brakes the robot to rest.
- a **BranchMonitor** sees a fault in what the robot is doing (an object dropped, a joint straining at its
  torque limit, a skill that makes no progress). The fault watch on each running skill it names halts that
  skill, which fails with the monitor's reason, and the recovery steps above it take over.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import mujoco
import numpy as np
from py_trees.behaviour import Behaviour

from bt_humanoid.control.gripper import GripperController
from bt_humanoid.control.robot import REST_SPEED, RobotController
from bt_humanoid.localisation.base import BaseLocalisation
from bt_humanoid.perception.world_model import WorldModel

OVERSPEED_TIME = 0.5  # s a joint must stay over its speed limit before the guard trips (a knock is shorter)


@dataclass(frozen=True)
class Violation:
    monitor: str
    message: str
    time: float


@dataclass(frozen=True)
class Fault:
    monitor: str
    message: str
    time: float
    leaf: object | None = None  # the leaf it concerns; None: every running leaf

    def concerns(self, leaf: object) -> bool:
        return self.leaf is None or self.leaf is leaf


class Monitor(Protocol):
    name: str

    def check(self, now: float) -> str | None:
        """A message when the monitor fires, else None."""


class BranchMonitor(Protocol):
    name: str

    def faults(self, now: float) -> list[tuple[object | None, str]]:
        """(leaf or None for every running leaf, message) for each fault seen now."""


class StopRequestMonitor:
    """Fires when someone asks the robot to stop (Ctrl-C, a typed or spoken "stop")."""

    name = "stop"

    def __init__(self) -> None:
        self.reason: str | None = None

    def request(self, reason: str = "stop requested") -> None:
        self.reason = self.reason or reason

    def check(self, now: float) -> str | None:
        return self.reason


class FallMonitor:
    """Fires when a walking robot falls: by its own sensors (the IMU's tilt, the pelvis's height over its feet:
    ``fall_reason``), or when anything of it but a foot touches the floor (its skin, as the bumper's).

    The walking controller has already made the robot safe by then (its legs only damp, docs/walking.md); the
    mission stops as for any safety violation.
    """

    name = "fall"

    def __init__(
        self,
        fall_reason: Callable[[], str | None],
        model: mujoco.MjModel,
        data: mujoco.MjData,
        robot: set[int],
        feet: set[int],
    ) -> None:
        self.fall_reason = fall_reason
        self.data = data
        self.model = model
        self.skin = np.isin(model.geom_bodyid, sorted(robot - feet))  # per geom: the robot, not its feet
        self.floor = model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE

    def check(self, now: float) -> str | None:
        reason = self.fall_reason()
        if reason is not None:
            return f"fell: {reason}"
        contacts = self.data.contact
        pairs = np.stack([contacts.geom1, contacts.geom2], axis=1)
        down = self.skin[pairs] & self.floor[pairs[:, ::-1]]
        rows, sides = np.nonzero(down)
        if rows.size:
            geom = int(pairs[rows[0], sides[0]])
            part = self.model.geom(geom).name or self.model.body(self.model.geom_bodyid[geom]).name
            return f"fell: the robot's {part} is on the floor"
        return None


class JointLimitMonitor:
    """Fires when a joint is past its MJCF range by more than the margin, or faster than its speed limit.

    ``speed_factor`` times the joints' velocity limits (robot.yaml) catches a controller gone wrong: the
    trajectories never ask for more than those limits. A joint must stay over its limit for
    ``OVERSPEED_TIME``: a knock (the base bumping into something) swings a wrist fast for an instant.
    """

    name = "joint_limits"

    def __init__(self, robot: RobotController, margin: float, speed_factor: float = np.inf) -> None:
        io = robot.body_io
        self.io = io
        self.lower = np.where(io.limited, io.lower - margin, -np.inf)
        self.upper = np.where(io.limited, io.upper + margin, np.inf)
        velocity_limits = robot.joints.limits[0]  # per joint of io, the order the joint controller keeps
        self.speed_limits = velocity_limits * speed_factor
        self.fast_since = np.full(len(io.joints), np.inf)

    def check(self, now: float) -> str | None:
        q = self.io.positions()
        bad = np.flatnonzero((q < self.lower) | (q > self.upper))
        if bad.size:
            i = int(bad[0])
            return f"joint {self.io.joints[i]} at {q[i]:.3f} outside [{self.lower[i]:.3f}, {self.upper[i]:.3f}]"
        speeds = np.abs(self.io.velocities())
        self.fast_since = np.where(speeds > self.speed_limits, np.minimum(self.fast_since, now), np.inf)
        fast = np.flatnonzero(now - self.fast_since >= OVERSPEED_TIME)
        if fast.size:
            i = int(fast[0])
            return f"joint {self.io.joints[i]} moving at {speeds[i]:.2f}/s, over its limit {self.speed_limits[i]:.2f}/s"
        return None


class BumperMonitor:
    """Fires when the robot's trunk (base, torso, head: not the arms) touches anything but the floor.

    The arms touch tables and objects as their work; the trunk never should. This is the robot's own touch
    sense (a bumper and skin), read from the contacts its geoms make; it does not say what was hit. Its own
    arms, and a loose thing the hands hold at the same time, are the robot and its load, not a collision.
    """

    name = "collision"

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, trunk: set[int], robot: set[int]) -> None:
        self.model, self.data = model, data
        self.on_trunk = np.isin(model.geom_bodyid, sorted(trunk))  # per geom
        self.on_arms = np.isin(model.geom_bodyid, sorted(robot - trunk))  # per geom
        self.own = self.on_trunk | self.on_arms
        self.floor = model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE  # per geom
        free = np.zeros(model.nbody, dtype=bool)
        free[model.jnt_bodyid[model.jnt_type == mujoco.mjtJoint.mjJNT_FREE]] = True
        self.loose = free[model.geom_bodyid]  # per geom: on a free body (an object, a parcel)

    def check(self, now: float) -> str | None:
        contacts = self.data.contact
        pairs = np.stack([contacts.geom1, contacts.geom2], axis=1)  # (contacts, 2)
        mine = self.on_trunk[pairs]
        other = pairs[:, ::-1]
        hit = mine & ~self.own[other] & ~self.floor[other]  # trunk side; the other not the robot nor the floor
        rows, sides = np.nonzero(hit)
        if rows.size == 0:
            return None
        held = self._held_bodies(pairs)
        for row, side in zip(rows, sides, strict=True):
            other = int(pairs[row, 1 - side])
            if self.model.geom_bodyid[other] in held:
                continue
            geom = int(pairs[row, side])
            x, y = contacts.pos[row, :2]
            part = self.model.geom(geom).name or self.model.body(self.model.geom_bodyid[geom]).name
            return f"the robot's {part} touched something at ({x:.2f}, {y:.2f})"
        return None

    def _held_bodies(self, pairs: np.ndarray) -> set[int]:
        """Loose bodies an arm or hand touches now."""
        arm = self.on_arms[pairs]
        loose = self.loose[pairs[:, ::-1]]
        rows, sides = np.nonzero(arm & loose)
        return {int(self.model.geom_bodyid[pairs[r, 1 - s]]) for r, s in zip(rows, sides, strict=True)}


def trunk_bodies(model: mujoco.MjModel, robot: set[int], hand_bodies: list[int]) -> set[int]:
    """The bodies of the ``robot`` that are not on an arm (the chain from a hand to the trunk)."""
    parent = model.body_parentid

    def ancestors(body: int) -> list[int]:
        chain = [body]
        while chain[-1] != 0:
            chain.append(int(parent[chain[-1]]))
        return chain

    shared = set.intersection(*(set(ancestors(h)) for h in hand_bodies)) if hand_bodies else set()
    arm_roots = {next(b for b in reversed(ancestors(h)) if b not in shared) for h in hand_bodies}
    return {b for b in robot if not arm_roots & set(ancestors(b))}


class WorkspaceMonitor:
    """Fires when the base leaves the map (by odometry) or a hand goes down to the floor.

    Goals off the map are refused before they start; this is the net under that check (a push, a skid).
    """

    name = "workspace"

    def __init__(self, robot: RobotController, bounds: np.ndarray, min_hand_height: float) -> None:
        self.robot = robot
        self.low, self.high = np.asarray(bounds[0], dtype=float), np.asarray(bounds[1], dtype=float)
        self.min_hand_height = min_hand_height

    def check(self, now: float) -> str | None:
        x, y, _ = self.robot.base.pose()
        if not (np.all([x, y] >= self.low) and np.all([x, y] <= self.high)):
            return f"the base at ({x:.2f}, {y:.2f}) left the map ({self.low.tolist()} to {self.high.tolist()})"
        for side in self.robot.config.grippers:
            z = float(self.robot.hand_position(side)[2])
            if z < self.min_hand_height:
                return (
                    f"the {side} hand is {z * 100:.0f} cm above the floor (lowest allowed {self.min_hand_height:g} m)"
                )
        return None


class LostMonitor:
    """Fires when localisation has lost the robot's place on the map: no scan fits where it believes it is, and
    a search of the whole map found no clear answer. Driving on a belief nobody trusts is not safe; the robot
    stops and says what would help. It keeps searching, so the next mission may find it again."""

    name = "lost"

    def __init__(self, localisation: BaseLocalisation) -> None:
        self.localisation = localisation

    def check(self, now: float) -> str | None:
        if not self.localisation.localiser.lost:
            return None
        return (
            "I do not know where I am: my scans fit nowhere on the map. Move me where I can see the walls or the "
            "furniture, or clear what surrounds me, and ask again"
        )


class TimeBudgetMonitor:
    """Fires when the mission has used its simulation-time budget."""

    name = "time_budget"

    def __init__(self, budget: float, start: float = 0.0) -> None:
        self.deadline = start + budget
        self.budget = budget

    def check(self, now: float) -> str | None:
        if now > self.deadline:
            return f"time budget of {self.budget:.0f} s used up"
        return None


class DroppedMonitor:
    """Fires when a hand the robot believes holds something has shut on nothing: the object was dropped.

    The fingers are the sensor: what they hold keeps them apart (a hand lets go only after the belief says
    so). The belief is corrected at once (the object is no longer held; where it fell is unknown until it is
    seen), so it fires once per drop.
    """

    name = "dropped"

    def __init__(self, grippers: GripperController, world_model: Callable[[], WorldModel]) -> None:
        self.grippers = grippers
        self.world_model = world_model

    def faults(self, now: float) -> list[tuple[object | None, str]]:
        found = []
        for side in self.grippers.grippers:
            held = self.world_model().held(side)
            if held is None or not self.grippers.shut(side):
                continue
            held.held_by, held.confidence = None, 0.0
            found.append((None, f"the {held.name} fell out of the {side} hand"))
        return found


class StrainMonitor:
    """Fires when a joint has pressed at its actuator's force limit for ``strain_time``: it is pushing
    against something it cannot move (a table edge, a stuck object) or carrying more than it can.

    Base wheels and fingers are left out: drives and grips press at their limits by design.
    """

    name = "strain"

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, actuators: list[int], strain_time: float) -> None:
        self.model, self.data = model, data
        self.actuators = np.asarray(actuators, dtype=int)
        self.limits = np.abs(model.actuator_forcerange[self.actuators]).min(axis=1)
        self.strain_time = strain_time
        self.since = np.full(len(self.actuators), np.inf)  # when each started pressing at its limit

    def faults(self, now: float) -> list[tuple[object | None, str]]:
        pressing = np.abs(self.data.actuator_force[self.actuators]) >= 0.99 * self.limits
        self.since = np.where(pressing, np.minimum(self.since, now), np.inf)
        strained = np.flatnonzero(now - self.since >= self.strain_time)
        if strained.size == 0:
            return []
        i = int(strained[0])
        self.since[i] = np.inf  # once per strain: the leaf it stops brakes, and the force falls
        name = self.model.actuator(int(self.actuators[i])).name
        return [(None, f"{name} pressed at its torque limit ({self.limits[i]:g}) for {self.strain_time:g} s")]


class StuckMonitor:
    """Fires for a running leaf with a motion under way that has made no progress for ``stuck_after``
    seconds: the robot stands still and the leaf's feedback has not changed (a wait that counts down, or a
    navigator that re-plans, is progress)."""

    name = "stuck"

    def __init__(self, robot: RobotController, running: Callable[[], list[Behaviour]], stuck_after: float) -> None:
        self.robot = robot
        self.running = running
        self.stuck_after = stuck_after
        self.last: dict[int, tuple[str, float]] = {}  # per leaf: (feedback, when it last changed or moved)

    def faults(self, now: float) -> list[tuple[object | None, str]]:
        moving = self.robot.max_speed() > REST_SPEED
        found: list[tuple[object | None, str]] = []
        last = {}
        for leaf in self.running():
            motion = getattr(leaf, "motion", None)
            if motion is None or motion.done:
                continue
            feedback, since = self.last.get(id(leaf), (leaf.feedback_message, now))
            if moving or feedback != leaf.feedback_message:
                feedback, since = leaf.feedback_message, now
            if now - since >= self.stuck_after:
                found.append((leaf, f"no progress for {self.stuck_after:g} s ({feedback or 'no feedback'})"))
                since = now
            last[id(leaf)] = (feedback, since)
        self.last = last
        return found


class SafetySupervisor:
    """Runs the monitors once per tick: the first violation latches; branch faults last one tick."""

    def __init__(
        self,
        monitors: list[Monitor],
        clock: Callable[[], float],
        branch_monitors: list[BranchMonitor] | None = None,
    ) -> None:
        self.monitors = monitors
        self.branch_monitors = branch_monitors or []
        self.clock = clock
        self.violation: Violation | None = None
        self.faults: list[Fault] = []  # this tick's

    def update(self) -> Violation | None:
        now = self.clock()
        if self.violation is None:
            for monitor in self.monitors:
                message = monitor.check(now)
                if message is not None:
                    self.violation = Violation(monitor.name, message, now)
                    break
        self.faults = []
        if self.violation is None:
            for branch_monitor in self.branch_monitors:
                for leaf, message in branch_monitor.faults(now):
                    self.faults.append(Fault(branch_monitor.name, message, now, leaf))
        return self.violation

    def fault_for(self, leaf: object) -> Fault | None:
        """This tick's first fault that concerns ``leaf`` and that it does not handle itself."""
        handled = getattr(leaf, "handles_faults", frozenset())
        return next((f for f in self.faults if f.concerns(leaf) and f.monitor not in handled), None)
