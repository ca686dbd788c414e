"""Parallel-jaw grippers: open, or close until the fingers stall on something or shut.

Closing drives the finger references towards closed; the position actuators
press with a force bounded by their force range, so an object between the pads
stops the fingers and is held by friction. The result says which happened.
"""

from __future__ import annotations

import math

import numpy as np

from bt_humanoid.control.joint_motion import JointReferenceController
from bt_humanoid.control.motion import MotionHandle
from bt_humanoid.sim.robot_config import GripperConfig

EMPTY_WIDTH = 0.004  # m: a gap below this after closing means nothing is held
STALL_SPEED = 0.004  # m/s: fingers slower than this have stopped closing
MIN_CLOSING_TIME = 0.15  # s before a stall counts (the fingers must get going first)
GRASP_TIMEOUT = 3.0  # s
MIN_PRESSURE = 0.5  # N on all the taxels of a hand together: less is not a grip


class GripperController:
    """Commands one robot's grippers through the joint reference controller."""

    def __init__(self, joints: JointReferenceController, grippers: dict[str, GripperConfig]) -> None:
        self.joints = joints
        self.grippers = grippers
        self._grasps: dict[str, tuple[MotionHandle, float, float | None]] = {}
        # per hand: its pads' taxels (touch sensors), and where each lies across the pads' width (m, the hand's y)
        self._taxels = {
            side: [name for pad in config.tactile_pads for name in joints.io.sensors_named(f"{pad}_taxel")]
            for side, config in grippers.items()
        }
        self._across = {
            side: np.array([joints.io.sensor_offset(name)[1] for name in names]) for side, names in self._taxels.items()
        }

    def grasp(self, side: str, edge: float | None = None) -> MotionHandle:
        """Close until the fingers stall; succeeds holding something, fails having closed on nothing.

        ``edge`` (m): stop closing, and fail, as soon as the pads feel the thing press further than this from
        their middle. A round thing touched by the pads' edges is squeezed out sideways, or over, by closing on.
        """
        self.command(side, "close")
        handle = MotionHandle(f"closing the {side} gripper")
        self._grasps[side] = (handle, self.joints.io.time, edge)
        return handle

    def step(self) -> None:
        """Judge grasps in progress: stalled on something, or shut on nothing (or felt at the pads' edge)."""
        for side, (handle, started, edge) in list(self._grasps.items()):
            if handle.done:
                del self._grasps[side]
                continue
            idx = self.joints.indices(self.grippers[side].joints)
            felt = self.pressure_centre(side) if edge is not None else None
            if felt is not None and abs(felt) > edge:
                # hold the fingers where they are: no harder squeeze on it
                where = self.joints.io.positions()[idx].tolist()
                self.joints.move(dict(zip(self.grippers[side].joints, where, strict=True)))
                handle.fail(f"the {side} pads touched it {abs(felt) * 100:.1f} cm off their middle, at their edge")
                del self._grasps[side]
                continue
            elapsed = self.joints.io.time - started
            stalled = np.all(np.abs(self.joints.io.velocities()[idx]) < STALL_SPEED)
            if elapsed < MIN_CLOSING_TIME or not (stalled or elapsed > GRASP_TIMEOUT):
                continue
            width = self.width(side)
            if width > EMPTY_WIDTH:
                handle.succeed(f"holding something {width * 100:.1f} cm wide")
            else:
                handle.fail(f"missed: the {side} gripper closed on nothing")
            del self._grasps[side]

    def command(self, side: str, action: str) -> MotionHandle:
        """``action`` is "open" or "close"; the handle's result reports held / empty."""
        config = self.grippers[side]
        value = config.open if action == "open" else config.closed
        # closing never "arrives" when something is in the way: skip the settle check, judge the width instead
        return self.joints.move({joint: value for joint in config.joints}, settle_check=(action == "open"))

    def loosen(self, side: str, by: float) -> MotionHandle:
        """Open the fingers ``by`` m wider than they stand now (no wider than open): off a thing, not far."""
        config = self.grippers[side]
        idx = self.joints.indices(config.joints)
        now = self.joints.io.positions()[idx]
        step = math.copysign(by / len(idx), config.open - config.closed)  # each finger's share, towards open
        targets = np.clip(now + step, min(config.open, config.closed), max(config.open, config.closed))
        return self.joints.move(dict(zip(config.joints, targets.tolist(), strict=True)))

    def start_closed(self, side: str) -> None:
        """Initial conditions, before the first step: the hand was closed on something when the run began (a
        scene handed the robot an object), so its fingers' references start shut and press on it at once."""
        config = self.grippers[side]
        self.joints.position[self.joints.indices(config.joints)] = config.closed

    def width(self, side: str) -> float:
        """Distance between the finger pads, from the finger encoders."""
        config = self.grippers[side]
        idx = self.joints.indices(config.joints)
        return float(np.sum(self.joints.io.positions()[idx]))

    def holding(self, side: str) -> bool:
        """Closed on something: the commanded gap is shut but the pads are held apart."""
        config = self.grippers[side]
        idx = self.joints.indices(config.joints)
        commanded_closed = np.allclose(self.joints.position[idx], config.closed, atol=1e-4)
        return bool(commanded_closed and self.width(side) > EMPTY_WIDTH)

    def pressure_centre(self, side: str) -> float | None:
        """Where across the pads' width (m from their middle, along the hand's y axis) what they hold presses on
        them, from the taxels' forces; None for pads that feel nothing (or have no taxels)."""
        forces = np.array([self.joints.io.sensor(name)[0] for name in self._taxels[side]])
        if forces.sum() < MIN_PRESSURE:  # (no taxels: nothing felt)
            return None
        return float(forces @ self._across[side] / forces.sum())

    def shut(self, side: str) -> bool:
        """The pads are together: nothing is between them."""
        return self.width(side) <= EMPTY_WIDTH
