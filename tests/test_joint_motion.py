"""Joint references: a move arrives when its joints are within its tolerance of their targets, else it fails."""

import numpy as np
import pytest

from bt_humanoid.control.joint_motion import SETTLE_TIMEOUT, JointReferenceController
from bt_humanoid.control.motion import MotionStatus
from bt_humanoid.sim.robot_config import load_robot_config


class BlockedWristIO:
    """The wheeled robot's right wrist pitch, held 0.04 rad short of wherever it is sent (a hand resting on a
    thing); the clock is the test's."""

    def __init__(self) -> None:
        self.joints = ["r_wrist_pitch"]
        self.lower, self.upper = np.array([-2.0]), np.array([2.0])
        self.time = 0.0
        self.sent = np.zeros(1)

    def index(self, joint: str) -> int:
        return self.joints.index(joint)

    def actuator(self, joint: str) -> int:
        return 0

    def positions(self) -> np.ndarray:
        return self.sent - 0.04

    def velocities(self) -> np.ndarray:
        return np.zeros(1)

    def command(self, actuators: np.ndarray, values: np.ndarray) -> None:
        self.sent = np.array(values, dtype=float)


def _settle(tolerance: float | None) -> MotionStatus:
    io = BlockedWristIO()
    joints = JointReferenceController(io, load_robot_config("wheeled_humanoid"))  # type: ignore[arg-type]
    options = {} if tolerance is None else {"tolerance": tolerance}
    handle = joints.move({"r_wrist_pitch": 0.5}, **options)
    while not handle.done and io.time < 10.0:
        io.time += 0.01
        joints.step()
    assert io.time < 10.0 - SETTLE_TIMEOUT
    return handle.status


def test_a_joint_held_short_of_its_target_fails_as_blocked():
    assert _settle(None) is MotionStatus.FAILED


@pytest.mark.parametrize("tolerance", [0.05, 0.1])
def test_a_move_told_a_wider_tolerance_arrives_near_its_target(tolerance: float):
    assert _settle(tolerance) is MotionStatus.SUCCEEDED
