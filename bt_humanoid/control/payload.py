"""Weighing what a hand holds with the wrist's force sensor, so that a legged robot balances with it.

The sensor sits between the wrist and the hand and reads the force the wrist exerts on the hand, its fingers and
whatever they hold: upwards in the world, m (g + a) for their mass m moving up at acceleration a. Held still,
that is their weight; a hand that has just lifted something is still slowing down (0.4 m/s² read as a quarter
less of a 0.1 kg cube), so the hand's acceleration, from its velocity by the robot's own kinematics (encoders
and the estimated pelvis, as on a real robot), divides it out. Both are low-passed over a tenth of a second.
Less the hand's own mass (the robot's model knows it), what is left is the load.

The weight found is put into the dynamics model (``RobotDynamics.set_payload``) at the grip point, so that the
balance QP counts it in the centre of mass and in the arm's torques, and taken out again when the hand lets go.
"""

from __future__ import annotations

import pinocchio as pin

from bt_humanoid.control.wbc.dynamics import RobotDynamics
from bt_humanoid.sim.robot_config import RobotConfig
from bt_humanoid.sim.robot_io import MujocoRobotIO

TIME_CONSTANT = 0.1  # s: the reading's low-pass filter


class WristScale:
    """Each hand's load (kg) from its wrist force sensor, for the grippers that have one (robot.yaml
    ``grippers.SIDE.wrist_force``)."""

    def __init__(self, config: RobotConfig, io: MujocoRobotIO, dynamics: RobotDynamics) -> None:
        self.io = io
        self.dynamics = dynamics
        #: side -> (force sensor, the frame it measures in, the grip site)
        self.sensors = {
            side: (
                gripper.wrist_force,
                io.sensor_site(gripper.wrist_force),
                gripper.grip_site,
            )
            for side, gripper in config.grippers.items()
            if gripper.wrist_force is not None
        }
        # the hand's own mass: everything below the joint the sensor's frame is on (before any payload)
        subtree = dynamics.model.createData()
        pin.computeSubtreeMasses(dynamics.model, subtree)
        self.hand_mass = {
            side: float(subtree.mass[dynamics.model.frames[dynamics.frame_id(frame)].parentJoint])
            for side, (_, frame, _) in self.sensors.items()
        }
        gravity = dynamics.gravity
        self.lifted = {side: self.hand_mass[side] * gravity for side in self.sensors}  # N up on each hand, filtered
        self.felt = {side: gravity for side in self.sensors}  # m/s²: g plus each hand's upward acceleration, filtered
        self._rising: dict[str, float | None] = {side: None for side in self.sensors}  # m/s: last upward speed

    def update(self, dt: float) -> None:
        """Read the sensors (every control step, ``dt`` s apart)."""
        share = min(dt / TIME_CONSTANT, 1.0)
        for side, (sensor, frame, _) in self.sensors.items():
            upward = float(self.dynamics.pose(frame).rotation[2] @ self.io.sensor(sensor))
            self.lifted[side] += share * (upward - self.lifted[side])
            rising, last = float(self.dynamics.velocity(frame)[2]), self._rising[side]
            felt = self.dynamics.gravity + (0.0 if last is None else (rising - last) / dt)
            self.felt[side] += share * (felt - self.felt[side])
            self._rising[side] = rising

    def weigh(self, side: str) -> float:
        """The mass (kg) the ``side`` hand holds, by its wrist sensor now (0 for nothing, or a hand pressed
        down on something)."""
        return max(self.lifted[side] / self.felt[side] - self.hand_mass[side], 0.0)

    def carry(self, side: str, mass: float) -> None:
        """Balance with ``mass`` kg in the ``side`` hand, at its grip point (0: it holds nothing)."""
        self.dynamics.set_payload(self.sensors[side][2], mass)

    def carried(self, side: str) -> float:
        """The mass the dynamics counts in the ``side`` hand."""
        return self.dynamics.payloads.get(self.sensors[side][2], 0.0)
