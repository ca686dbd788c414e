"""Inverse-dynamics tasks: each asks for an acceleration a* of some quantity, J v̇ + J̇v, and answers J and J̇v."""

from bt_humanoid.control.wbc.id_tasks.angular_momentum_task import AngularMomentumTask
from bt_humanoid.control.wbc.id_tasks.base import AccelerationTask
from bt_humanoid.control.wbc.id_tasks.com_task import ComTask
from bt_humanoid.control.wbc.id_tasks.frame_task import FrameTask
from bt_humanoid.control.wbc.id_tasks.joint_posture_task import JointPostureTask
from bt_humanoid.control.wbc.id_tasks.orientation_task import OrientationTask

__all__ = ["AccelerationTask", "AngularMomentumTask", "ComTask", "FrameTask", "JointPostureTask", "OrientationTask"]
