"""Whole-body limits: box bounds on the joint step, and linear inequalities."""

from bt_humanoid.control.wbc.limits.base import Inequality, Limit
from bt_humanoid.control.wbc.limits.base_bounds_limit import BaseBoundsLimit
from bt_humanoid.control.wbc.limits.base_keepout_limit import BaseKeepoutLimit
from bt_humanoid.control.wbc.limits.clearance_limit import ClearanceLimit
from bt_humanoid.control.wbc.limits.joint_position_limit import JointPositionLimit
from bt_humanoid.control.wbc.limits.joint_range_limit import JointRangeLimit
from bt_humanoid.control.wbc.limits.torso_margin_limit import TorsoMarginLimit
from bt_humanoid.control.wbc.limits.velocity_limit import VelocityLimit

__all__ = [
    "BaseBoundsLimit",
    "BaseKeepoutLimit",
    "ClearanceLimit",
    "Inequality",
    "JointPositionLimit",
    "JointRangeLimit",
    "Limit",
    "TorsoMarginLimit",
    "VelocityLimit",
]
