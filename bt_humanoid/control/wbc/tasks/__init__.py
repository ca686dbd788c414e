"""Whole-body tasks: each gives an error and a Jacobian over the controlled joints."""

from bt_humanoid.control.wbc.tasks.base import Task
from bt_humanoid.control.wbc.tasks.damping_task import DampingTask
from bt_humanoid.control.wbc.tasks.frame_task import FrameTask
from bt_humanoid.control.wbc.tasks.gaze_task import GazeTask
from bt_humanoid.control.wbc.tasks.posture_task import PostureTask

__all__ = ["DampingTask", "FrameTask", "GazeTask", "PostureTask", "Task"]
