"""The robot's interface to its body: encoders in, actuator commands out.

Controllers see only this: joint positions and velocities by name (what the
encoders report) and actuator commands. They never touch the simulator's
state directly, so the same controllers could drive other hardware.
"""

from __future__ import annotations

import mujoco
import numpy as np

from bt_humanoid.sim.sensor_models import encoder_steps, quantise
from bt_humanoid.sim.simulation import Simulation


class MujocoRobotIO:
    """Encoder reads and actuator writes for one robot in a Simulation."""

    def __init__(self, sim: Simulation, joints: list[str]) -> None:
        self.sim = sim
        model = sim.model
        self.joints = list(joints)
        self._qpos = np.array([model.joint(j).qposadr[0] for j in joints])
        self._qvel = np.array([model.joint(j).dofadr[0] for j in joints])
        self._index = {j: i for i, j in enumerate(joints)}
        self.lower = np.array([model.jnt_range[model.joint(j).id][0] for j in joints])
        self.upper = np.array([model.jnt_range[model.joint(j).id][1] for j in joints])
        self.limited = np.array([bool(model.jnt_limited[model.joint(j).id]) for j in joints])
        # encoders count whole steps; the base's planar joints are not encoders (localisation tells where it is)
        rotary = np.array([model.jnt_type[model.joint(j).id] == mujoco.mjtJoint.mjJNT_HINGE for j in joints])
        base = set(sim.robot.base.joints.values())
        self._encoder = np.array([j not in base for j in joints], dtype=bool)
        self._steps = encoder_steps(sim.sensors.encoders, rotary[self._encoder]) if self._encoder.any() else None
        imu = sim.robot.imu
        self._imu_noise = {}  # sensor name → σ per axis of its white noise
        if imu is not None and sim.sensors.imu.enabled:
            self._imu_noise = {imu.gyro: sim.sensors.imu.gyro, imu.accelerometer: sim.sensors.imu.accelerometer}

    def index(self, joint: str) -> int:
        return self._index[joint]

    def positions(self) -> np.ndarray:
        """What the encoders read: joint positions in whole counts."""
        positions = self.sim.data.qpos[self._qpos]
        if self._steps is not None:
            positions[self._encoder] = quantise(positions[self._encoder], self._steps)
        return positions

    def velocities(self) -> np.ndarray:
        return self.sim.data.qvel[self._qvel]

    def actuator(self, joint: str) -> int:
        return self.sim.actuator_for_joint(joint)

    def velocity_lag(self, joint: str) -> float:
        """Time constant (s) of a joint's velocity actuator: its inertia now over the actuator's gain.

        A velocity actuator pushes with ``kv × (commanded − actual velocity)``, so the joint follows a
        commanded velocity one time constant late; a controller leads its command by this much acceleration.
        """
        model = self.sim.model
        inertia = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, self.sim.data, inertia)
        dof = model.joint(joint).dofadr[0]
        return float(inertia[dof, dof] / self.gain(joint))

    def gain(self, joint: str) -> float:
        """The gain of a joint's actuator: N·m (N) per radian (metre) of position error for a position actuator,
        per rad/s (m/s) of velocity error for a velocity actuator."""
        return float(self.sim.model.actuator_gainprm[self.actuator(joint), 0])

    def servo(self, joint: str) -> tuple[float, float, float]:
        """A position servo's stiffness kp, damping kv and force limit: its force is kp (target − q) − kv q̇,
        clipped to ± the limit (inf when it has none)."""
        model = self.sim.model
        actuator = self.actuator(joint)
        limit = float(np.max(np.abs(model.actuator_forcerange[actuator])))
        if not model.actuator_forcelimited[actuator]:
            limit = np.inf
        return float(model.actuator_gainprm[actuator, 0]), float(-model.actuator_biasprm[actuator, 2]), limit

    def sensor_site(self, name: str) -> str:
        """The site a sensor measures at (a force sensor's frame: its readings are in that site's axes)."""
        model = self.sim.model
        return model.site(int(model.sensor(name).objid[0])).name

    def sensors_named(self, prefix: str) -> list[str]:
        """The sensors whose names are ``prefix`` followed by 0, 1, 2, … (a pad's taxels), in that order."""
        names, model = [], self.sim.model
        while mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, f"{prefix}{len(names)}") >= 0:
            names.append(f"{prefix}{len(names)}")
        return names

    def sensor_offset(self, name: str) -> np.ndarray:
        """Where a site sensor measures, in the frame of the body it is on (the robot's own geometry)."""
        model = self.sim.model
        return model.site_pos[int(model.sensor(name).objid[0])].copy()

    def sensor(self, name: str) -> np.ndarray:
        """A sensor's reading (the robot's IMU, foot force and touch sensors), as of the last physics step; the IMU's
        rates and specific force with its white noise."""
        reading = self.sim.data.sensor(name).data
        if name in self._imu_noise:
            return reading + self.sim.random_stream(name).standard_normal(reading.shape) * self._imu_noise[name]
        return reading

    def command(self, actuators: np.ndarray, values: np.ndarray) -> None:
        self.sim.data.ctrl[actuators] = values

    @property
    def time(self) -> float:
        return self.sim.time
