"""Safety monitors, evaluated once per tick by the supervisor that every Safety guard reads.

A monitor looks at the robot and the clock and returns a Violation or None.
The first violation latches: every guard then halts its branch, the tree
fails, and the executor brakes the robot to rest.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import mujoco
import numpy as np

from bt_humanoid.control.robot import RobotController


@dataclass(frozen=True)
class Violation:
    monitor: str
    message: str
    time: float


class Monitor(Protocol):
    name: str

    def check(self, now: float) -> str | None:
        """A message when the monitor fires, else None."""


class StopRequestMonitor:
    """Fires when someone asks the robot to stop (Ctrl-C, a typed or spoken "stop")."""

    name = "stop"

    def __init__(self) -> None:
        self.reason: str | None = None

    def request(self, reason: str = "stop requested") -> None:
        self.reason = self.reason or reason

    def check(self, now: float) -> str | None:
        return self.reason


class JointLimitMonitor:
    """Fires when a joint is past its MJCF range by more than the margin."""

    name = "joint_limits"

    def __init__(self, robot: RobotController, margin: float) -> None:
        io = robot.body_io
        self.io = io
        self.lower = np.where(io.limited, io.lower - margin, -np.inf)
        self.upper = np.where(io.limited, io.upper + margin, np.inf)

    def check(self, now: float) -> str | None:
        q = self.io.positions()
        bad = np.flatnonzero((q < self.lower) | (q > self.upper))
        if bad.size == 0:
            return None
        i = int(bad[0])
        return f"joint {self.io.joints[i]} at {q[i]:.3f} outside [{self.lower[i]:.3f}, {self.upper[i]:.3f}]"


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
        whole_body = self.robot.whole_body
        for side in self.robot.config.grippers:
            z = float(whole_body.frame_pose(whole_body.hand_frame(side)).translation[2])
            if z < self.min_hand_height:
                return (
                    f"the {side} hand is {z * 100:.0f} cm above the floor (lowest allowed {self.min_hand_height:g} m)"
                )
        return None


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


class SafetySupervisor:
    """Runs the monitors once per tick; the first violation latches."""

    def __init__(self, monitors: list[Monitor], clock: Callable[[], float]) -> None:
        self.monitors = monitors
        self.clock = clock
        self.violation: Violation | None = None

    def update(self) -> Violation | None:
        if self.violation is None:
            now = self.clock()
            for monitor in self.monitors:
                message = monitor.check(now)
                if message is not None:
                    self.violation = Violation(monitor.name, message, now)
                    break
        return self.violation
