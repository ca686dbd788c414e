"""Standing balance: the biped held up by the whole-body inverse-dynamics QP alone (docs/walking.md).

Every control step (every physics step, 500 Hz): the state estimator turns the IMU, encoders and touch sensors
into the pelvis's pose and velocity; ``RobotDynamics`` evaluates the model there; ``solve_id`` finds the joint
accelerations, sole wrenches and torques that best serve the tasks below within the robot's physics and limits;
the leg motors get their torques, the upper body's position servos targets that make them exert theirs.

Balance is the centre of mass's task, a law on the divergent component of motion (DCM) ξ = c + ċ/ω of the
linear inverted pendulum (ω = √(g/z_c)): the commanded ZMP p = ξ + (k_ξ/ω)(ξ − ξ_ref) and the LIPM's c̈ = ω²(c − p).
It is not clamped to the feet: when it lies beyond a sole's edge the cone constraints stop the centre of
pressure there, and the QP makes up what the ankles cannot give by turning the upper body about the hips (the
orientation tasks weigh little against the centre of mass's): the ankle strategy, then the hip strategy.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from bt_humanoid.control.walking.estimator import BaseState, StateEstimator
from bt_humanoid.control.wbc.contact import SoleContact
from bt_humanoid.control.wbc.dynamics import RobotDynamics
from bt_humanoid.control.wbc.id_limits import HeldJointLimit, JointLimit, TorqueLimit
from bt_humanoid.control.wbc.id_solver import IdSolution, solve_id
from bt_humanoid.control.wbc.id_tasks import ComTask, JointPostureTask, OrientationTask
from bt_humanoid.sim.robot_config import LEG_ROLES
from bt_humanoid.sim.robot_io import MujocoRobotIO
from bt_humanoid.sim.scene_config import start_pose
from bt_humanoid.sim.simulation import Simulation
from bt_humanoid.sim.standing import standing_posture

# 1/s: k_ξ, the DCM error decays as e^{−k_ξ t} while the centre of pressure has room. Standing, a stiff law
# moves the centre of pressure to the edge of the feet as soon as a push begins, which is what recovers the
# largest pushes (benchmarks/balance.py: 2.5, walking.md's tracking gain, survives about 150 N for 0.2 s; 10,
# about 205 N)
DCM_GAIN = 10.0
COM_WEIGHT = 100.0
# The height weighs less than the horizontal position: when the hip strategy leans the torso forward the centre
# of mass may sink a little, rather than the knees straightening against their stops to hold it up.
COM_HEIGHT_WEIGHT = 10.0
COM_HEIGHT_GAINS = (100.0, 20.0)  # K_p (1/s²), K_d (1/s) of the centre of mass's height
# The pelvis and torso are held upright softly and with little weight, so that the QP may turn them to keep
# the centre of mass when the ankles saturate (the hip strategy), and brings them back slowly afterwards.
ORIENTATION_WEIGHT = 0.1
ORIENTATION_GAINS = (30.0, 11.0)  # K_p, K_d ≈ 2√K_p: critically damped
UPPER_BODY_WEIGHT = 10.0
UPPER_BODY_GAINS = (100.0, 20.0)
LEG_POSTURE_WEIGHT = 0.1
LEG_POSTURE_GAINS = (10.0, 6.0)
# the QP lets an upper-body joint reach this times its motion limit (robot.yaml joint_limits: what its joint
# trajectories plan under); a servo is not a motor, and the QP does not drive it faster than its plans do
SERVO_SPEED_MARGIN = 1.5
HELD_JOINTS_GAIN = 10.0
LIMIT_MARGIN = 0.01  # rad (m) the QP keeps inside each joint's range
# rad the QP keeps each knee bent at the least. A straight leg is singular: its foot cannot be lifted (a stance leg
# pushed sideways straightened to its stop, and the recovery step that followed dragged its sole along the floor)
LEAST_KNEE_BEND = 0.15
# A fall, by the robot's own sensors: the pelvis (the IMU) tilted further than this from upright, or lower than
# this above the feet (standing it is 0.52 m up). Walking tilts it a few degrees; no recovery comes back from 30°.
MAX_TILT_DEG = 30.0
FALLEN_HEIGHT = 0.35  # m
LIMP_DAMPING = 5.0  # N·m·s/rad at each leg joint of a fallen robot


class BalanceController:
    """Holds a legged robot standing on its two feet with the inverse-dynamics QP; writes actuator commands only.

    ``step()`` runs one control step and must be called every ``dt`` (every physics step): the legs are
    torque-controlled and a torque holds only until the next command.
    """

    def __init__(self, sim: Simulation, posture: str = "home") -> None:
        config = sim.robot
        if config.legs is None or config.imu is None or config.imu.orientation is None:
            raise ValueError(f"robot '{config.name}' has no legs and IMU to balance on")
        self.config = config
        legs = config.legs
        self.dt = sim.timestep
        self.dynamics = RobotDynamics(config)
        joints = self.dynamics.joints
        self.io = MujocoRobotIO(sim, joints)  # encoders, sensors and actuators: never the free joint
        self.estimator = StateEstimator(config, joints, self.dt)
        x, y, _ = start_pose(sim.scene, sim.world)  # where the robot was put: its odometry starts there
        self._start = (x, y)
        stance = standing_posture(config, posture=posture)
        self.com_height = float(stance.com[2])  # above the soles
        self.omega = math.sqrt(self.dynamics.gravity / self.com_height)
        # the torso lift raises everything above it: the centre of mass by that share of the lift's travel, which
        # the height's target follows (else the knees would bend to hold the centre of mass where it was)
        model = self.dynamics.model
        data = model.createData()
        pin.computeSubtreeMasses(model, data)
        lifts = [j for j in config.groups.get("lift", []) if j in self.dynamics.joints]
        self._lift_q = np.array([self.dynamics.joint_index(j) + 1 for j in lifts], dtype=int)
        self._lift_share = np.array([data.mass[model.getJointId(j)] / data.mass[0] for j in lifts])

        # who drives what: leg motors take torques; the upper body's servos (the lift among them, where it is in a
        # group) take targets; the fingers and any joint in no group stay with their own servos (the grippers to
        # the gripper controller)
        grouped = {joint for group in config.groups.values() for joint in group}
        self.held = [j for j in joints if j in config.finger_joints or (j not in legs.joints and j not in grouped)]
        self.servoed = [j for j in joints if j not in legs.joints and j not in self.held]
        self.legs = list(legs.joints)
        self._leg_columns = np.array([joints.index(j) for j in self.legs])
        self._servo_columns = np.array([joints.index(j) for j in self.servoed])
        self._leg_actuators = np.array([self.io.actuator(j) for j in self.legs])
        self._servo_actuators = np.array([self.io.actuator(j) for j in self.servoed])
        servos = [self.io.servo(j) for j in self.servoed]
        self._kp = np.array([s[0] for s in servos])
        self._kv = np.array([s[1] for s in servos])

        sole = legs.sole
        self.contacts = [
            SoleContact(leg.sole, sole.length, sole.width, sole.friction) for leg in (legs.left, legs.right)
        ]
        self.sensors = [legs.left.touch_sensor, legs.right.touch_sensor]
        controlled = self.legs + self.servoed
        model = sim.model
        ranges = np.array([model.jnt_range[model.joint(j).id] for j in controlled])
        knees = [controlled.index(leg.joints[LEG_ROLES.index("knee")]) for leg in (legs.left, legs.right)]
        ranges[knees, 0] = np.maximum(ranges[knees, 0], LEAST_KNEE_BEND)
        # the lift rests on its lower stop (walking, 'home'): its bound is the stop itself, not a margin above it
        # (which lifted it 1 cm at the start with a jolt that tipped a foot onto its edge)
        lifts = [controlled.index(j) for j in config.groups.get("lift", []) if j in controlled]
        ranges[lifts, 0] -= LIMIT_MARGIN
        speeds = np.array(
            [
                legs.speed_limit(j) if j in legs.joints else SERVO_SPEED_MARGIN * config.motion_limits(j).velocity
                for j in controlled
            ]
        )
        self.torque_limit = TorqueLimit(
            {j: legs.torque_limit(j) for j in self.legs} | {j: s[2] for j, s in zip(self.servoed, servos, strict=True)}
        )
        self.bounds = [
            JointLimit(controlled, ranges[:, 0], ranges[:, 1], speeds, margin=LIMIT_MARGIN),
            HeldJointLimit(self.held, HELD_JOINTS_GAIN),
        ]

        self.com = ComTask(
            np.array([COM_WEIGHT, COM_WEIGHT, COM_HEIGHT_WEIGHT]),
            kp=[0.0, 0.0, COM_HEIGHT_GAINS[0]],
            kd=[0.0, 0.0, COM_HEIGHT_GAINS[1]],
        )
        self.pelvis = OrientationTask(config.frames["pelvis"][1], ORIENTATION_WEIGHT, *ORIENTATION_GAINS)
        self.torso = OrientationTask(config.frames["torso"][1], ORIENTATION_WEIGHT, *ORIENTATION_GAINS)
        #: the upper body's joint references: a manipulation or gaze controller may stream its own
        self.upper_body = JointPostureTask(
            {j: stance.joints[j] for j in self.servoed}, UPPER_BODY_WEIGHT, *UPPER_BODY_GAINS
        )
        self.leg_posture = JointPostureTask(
            {j: stance.joints[j] for j in self.legs}, LEG_POSTURE_WEIGHT, *LEG_POSTURE_GAINS
        )
        self.tasks = [self.com, self.pelvis, self.torso, self.upper_body, self.leg_posture]

        #: the centre of mass's reference relative to the middle of the feet (x, y, world axes): shifting weight
        self.com_offset = np.zeros(2)
        self.dcm_gain = DCM_GAIN
        self.zmp_command = np.zeros(2)  # the balance law's last commanded ZMP (x, y, world)
        self.com_offset_velocity = np.zeros(2)
        self.com_offset_acceleration = np.zeros(2)
        self.state: BaseState | None = None
        self.solution: IdSolution | None = None
        self.solve_times: list[float] = []  # s per control step building and solving the QP, for the benchmark
        self.conic_times: list[float] = []  # s of each in DAQP itself
        self.failures = 0  # control steps whose QP had no solution (the last command was held)
        self.relaxed = 0  # control steps solved only without the joints' range and speed bounds
        self.fallen: str | None = None  # why the robot fell, once it has: it then only damps its legs

    # --- the control step ---------------------------------------------------------------------------------------

    def step(self) -> None:
        """Read the sensors, estimate, solve the QP, command the actuators; once fallen, only damp the legs."""
        positions, velocities = self.observe()
        if self.fallen is None:
            self.fallen = self.fall_reason()
        if self.fallen is not None:
            self._go_limp(velocities)
            return
        self._balance()
        self._command(positions, velocities)

    def fall_reason(self) -> str | None:
        """Why the robot has fallen (or is falling past saving) by its own sensors; None while it stands."""
        state = self.state
        assert state is not None
        tilt = math.degrees(math.acos(float(np.clip(state.rotation[2, 2], -1.0, 1.0))))
        if tilt > MAX_TILT_DEG:
            return f"the pelvis tilts {tilt:.0f}° from upright (more than {MAX_TILT_DEG:.0f}°)"
        soles = [self.dynamics.pose(c.frame).translation[2] for c in self.contacts]
        height = float(state.position[2] - min(soles))
        if height < FALLEN_HEIGHT:
            return f"the pelvis is {height:.2f} m above the feet (lowest standing {FALLEN_HEIGHT:g} m)"
        return None

    def _go_limp(self, velocities: np.ndarray) -> None:
        """A fallen robot's safe state: the legs' motors only damp their joints (no torque drives a limb into the
        floor or a person), the upper body's servos hold where they are."""
        io = self.io
        io.command(self._leg_actuators, -LIMP_DAMPING * velocities[self._leg_columns])
        io.command(self._servo_actuators, io.positions()[self._servo_columns])

    def observe(self) -> tuple[np.ndarray, np.ndarray]:
        """Read the sensors and update the state estimate and the model there (no command); the joints' positions
        and velocities read."""
        io = self.io
        positions, velocities = io.positions().copy(), io.velocities().copy()
        imu = self.config.imu
        assert imu is not None and imu.orientation is not None
        if self.state is None:
            self.estimator.reset(io.sensor(imu.orientation), positions, self._start)
        touch = (float(io.sensor(self.sensors[0])[0]), float(io.sensor(self.sensors[1])[0]))
        self.state = state = self.estimator.update(
            io.sensor(imu.orientation), io.sensor(imu.gyro), io.sensor(imu.accelerometer), positions, velocities, touch
        )
        q, v = self.dynamics.state(
            state.position, state.rotation, state.linear_velocity, state.angular_velocity, positions, velocities
        )
        self.dynamics.update(q, v)
        return positions, velocities

    def _command(self, positions: np.ndarray, velocities: np.ndarray) -> None:
        io = self.io
        solution = solve_id(self.dynamics, self.contacts, self.tasks, self.bounds, self.torque_limit, self.dt)
        if not solution.solved:
            # the joints' range and speed bounds are the soft ones: a joint at its range's edge as a foot lands
            # can make the problem infeasible, and the robot's balance comes before a servo's stop
            self.relaxed += 1
            solution = solve_id(self.dynamics, self.contacts, self.tasks, [], self.torque_limit, self.dt)
        self.solve_times.append(solution.solve_time)
        self.conic_times.append(solution.conic_time)
        if not solution.solved:
            self.failures += 1
            return  # the motors keep the last torques, the servos their targets
        self.solution = solution
        torques = solution.torques
        io.command(self._leg_actuators, torques[self._leg_columns])
        # a servo's force is kp (r − q) − kv q̇: the target r that makes it exert the QP's torque
        servo_q, servo_v = positions[self._servo_columns], velocities[self._servo_columns]
        io.command(self._servo_actuators, servo_q + (torques[self._servo_columns] + self._kv * servo_v) / self._kp)

    def set_com_offset(
        self, offset: np.ndarray, velocity: np.ndarray | None = None, acceleration: np.ndarray | None = None
    ) -> None:
        """Where the centre of mass should be relative to the middle of the feet (x, y, m, world axes), and how
        that reference moves: the balance law follows a moving reference without lag."""
        self.com_offset = np.asarray(offset, dtype=float)
        self.com_offset_velocity = np.zeros(2) if velocity is None else np.asarray(velocity, dtype=float)
        self.com_offset_acceleration = np.zeros(2) if acceleration is None else np.asarray(acceleration, dtype=float)

    def _balance(self) -> None:
        """The tasks' targets: the centre of mass over the middle of the feet (plus the offset), upright, facing
        the way the feet face."""
        left, right = (self.dynamics.pose(c.frame) for c in self.contacts)
        middle = (left.translation + right.translation) / 2
        heading = left.rotation[:, 0] + right.rotation[:, 0]
        omega = self.omega
        # the DCM's reference and its rate for a reference moving with ċ_ref, c̈_ref
        dcm_reference = middle[:2] + self.com_offset + self.com_offset_velocity / omega
        dcm_rate = self.com_offset_velocity + self.com_offset_acceleration / omega
        self._track(dcm_reference, dcm_rate, float(middle[2]), math.atan2(heading[1], heading[0]))

    def _track(self, dcm_reference: np.ndarray, dcm_rate: np.ndarray, floor: float, yaw: float) -> None:
        """Targets that track a DCM reference (x, y) and its rate, the centre of mass ``com_height`` above
        ``floor`` (m), the pelvis and torso upright and facing ``yaw``: the balance law of the module docstring."""
        dynamics, omega = self.dynamics, self.omega
        com, velocity = dynamics.com, dynamics.com_velocity
        dcm = com[:2] + velocity[:2] / omega
        zmp = dcm - dcm_rate / omega + self.dcm_gain / omega * (dcm - dcm_reference)
        self.zmp_command = zmp
        acceleration = np.zeros(3)
        acceleration[:2] = omega**2 * (com[:2] - zmp)
        height = self.com_height + float(self._lift_share @ dynamics.q[self._lift_q])
        self.com.set_target(np.array([com[0], com[1], floor + height]), acceleration=acceleration)
        upright = pin.rpy.rpyToMatrix(0.0, 0.0, yaw)
        self.pelvis.target = upright
        self.torso.target = upright

    # --- what it reports ----------------------------------------------------------------------------------------

    def dcm(self) -> np.ndarray:
        """The estimated divergent component of motion (x, y), world frame."""
        return self.dynamics.com[:2] + self.dynamics.com_velocity[:2] / self.omega
