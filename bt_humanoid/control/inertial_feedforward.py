"""Holding the upper body still while the base accelerates.

When the base speeds up or brakes, the arms, waist and head feel the inertial
torque of that acceleration and deflect from their references (a few mrad on
soft joints), then swing back once it ends: a stopped robot would keep moving
for another 100 to 200 ms. The joint-space inertia couples each joint to the
base axes, so the torque is known before it acts: ``M[joint, base] × base
acceleration``. Each position actuator gets it as an offset of its target,
torque over its position gain, and the joint stays where its reference is.
"""

from __future__ import annotations

import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.sim.robot_config import RobotConfig
from bt_humanoid.sim.robot_io import MujocoRobotIO


class BaseAccelerationFeedforward:
    """Target offsets that cancel the base's acceleration on the position-controlled joints."""

    def __init__(self, config: RobotConfig, body_io: MujocoRobotIO, base_joints: list[str]) -> None:
        # fingers squeeze what they hold by pressing past it: their targets are left alone
        self.joints = np.array([i for i, j in enumerate(body_io.joints) if j not in config.finger_joints])
        names = [body_io.joints[i] for i in self.joints]
        self.kinematics = RobotKinematics(config, base_joints + names)
        self.gains = np.array([body_io.gain(j) for j in names])
        self.offsets = np.zeros(len(body_io.joints))  # rad (m): added to every joint's target

    def update(self, base_pose: np.ndarray, body_positions: np.ndarray, base_acceleration: np.ndarray) -> np.ndarray:
        """Offsets for the joints now (zero while the base does not accelerate)."""
        if not np.any(base_acceleration):
            self.offsets[:] = 0.0
            return self.offsets
        inertia = self.kinematics.mass_matrix(np.concatenate([base_pose, body_positions[self.joints]]))
        coupling = inertia[3:, :3]
        self.offsets[self.joints] = coupling @ base_acceleration / self.gains
        return self.offsets
