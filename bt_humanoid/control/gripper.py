"""Parallel-jaw grippers: open, or close until the fingers stall on something or shut.

Closing drives the finger references towards closed; the position actuators
press with a force bounded by their force range, so an object between the pads
stops the fingers and is held by friction. The result says which happened.
"""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.joint_motion import JointReferenceController
from bt_humanoid.control.motion import MotionHandle
from bt_humanoid.sim.robot_config import GripperConfig

EMPTY_WIDTH = 0.004  # m: a gap below this after closing means nothing is held


class GripperController:
    """Commands one robot's grippers through the joint reference controller."""

    def __init__(self, joints: JointReferenceController, grippers: dict[str, GripperConfig]) -> None:
        self.joints = joints
        self.grippers = grippers

    def command(self, side: str, action: str) -> MotionHandle:
        """``action`` is "open" or "close"; the handle's result reports held / empty."""
        config = self.grippers[side]
        value = config.open if action == "open" else config.closed
        # closing never "arrives" when something is in the way: skip the settle check, judge the width instead
        return self.joints.move({joint: value for joint in config.joints}, settle_check=(action == "open"))

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
