"""Inverse-dynamics limits: bounds on the joint accelerations, and the joints' torque limits."""

from bt_humanoid.control.wbc.id_limits.base import AccelerationBounds
from bt_humanoid.control.wbc.id_limits.held_joint_limit import HeldJointLimit
from bt_humanoid.control.wbc.id_limits.joint_limit import JointLimit
from bt_humanoid.control.wbc.id_limits.torque_limit import TorqueLimit

__all__ = ["AccelerationBounds", "HeldJointLimit", "JointLimit", "TorqueLimit"]
