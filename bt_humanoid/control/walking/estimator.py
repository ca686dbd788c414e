"""The floating base's state from the robot's own sensors: the IMU, the joint encoders and the foot touch sensors.

Nothing here reads the simulator's free joint. Attitude and angular velocity come from the IMU (``imu_quat`` is
an attitude filter's output, ideal in this simulation; ``imu_gyro``); position and velocity from a linear Kalman
filter in the world frame after Bloesch et al. ("State estimation for legged robots", RSS 2012), linear once the
attitude is known:

- state: the IMU's position and velocity, and each sole's position (12);
- prediction: the IMU's specific force turned into the world frame, plus gravity, integrated over the step; a
  sole in contact barely moves (small process noise), a swinging one may go anywhere (large);
- measurements: each sole's position relative to the IMU, from the encoders' forward kinematics and the
  attitude; for a sole in contact also the IMU's velocity that a still sole implies (the legs' joint rates
  through their Jacobian, and the body's rotation), and its height: the floor's (the worlds' floors are flat, at
  z = 0). Without that the height drifted as legged odometry does, 2 cm in 40 s of walking, and a hand placed
  by the estimate reached 2 cm lower than the robot believed, into the table under an object.

The IMU's readings are one physics step older than the encoders': MuJoCo computes sensors in the forward pass
that starts a step, before it integrates, so after ``mj_step`` the attitude and rates are those of the step's
start (a real IMU has a latency of its own). The attitude is carried forward over that latency with the gyro.

Contact is the touch sensor's normal force with hysteresis (on above 30 N, off below 15 N). A sole in contact is
trusted to stand still only while the velocity it implies agrees with the prediction (within ``SLIP_SPEED``): a
swinging foot that scuffs the floor, or a sole that slides, touches without standing, and taking it for still
once made the estimate lose 0.6 m/s in a step (a pushed robot then stepped backwards and fell). Absolute position is
not observable from these sensors: the filter starts from a known start (the feet centred on the world's start
pose, flat on the floor) and from there integrates, as legged odometry does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from bt_humanoid.control.wbc.kinematics import robot_model
from bt_humanoid.sim.robot_config import RobotConfig

GRAVITY = np.array([0.0, 0.0, -9.81])
CONTACT_ON = 30.0  # N of sole normal force above which a foot counts as standing
CONTACT_OFF = 15.0  # N below which it counts as lifted again: the gap keeps the flag from chattering
ACCELEROMETER_NOISE = 0.5  # m/s² (1σ) of the accelerometer over a step: unmodelled vibration, impacts
STANCE_FOOT_DRIFT = 0.002  # m/√s: how far a sole in contact may creep (soft contact, micro-slip)
SWING_FOOT_DRIFT = 5.0  # m/√s: a lifted foot may go anywhere; the kinematics tell where
KINEMATICS_NOISE = 0.002  # m (1σ) of a sole's position relative to the IMU from the encoders
VELOCITY_NOISE = 0.02  # m/s (1σ) of the IMU's velocity implied by a still sole
INITIAL_POSITION_SPREAD = 1e-3  # m (1σ): the start pose is known
FLOOR_HEIGHT = 0.0  # m: the height of the floor a standing sole is on
FLOOR_NOISE = 0.002  # m (1σ): the sole's sinking into the floor (soft contact) and the floor's unevenness
# m/s between a touching sole's implied IMU velocity and the prediction beyond which the sole is not standing
# still (it scuffs or slides): an impact changes the body's velocity by less within a step, a scuff by far more
SLIP_SPEED = 0.25


@dataclass
class BaseState:
    """The pelvis's estimated state, world frame."""

    position: np.ndarray  # of the pelvis origin (the free joint's), m
    rotation: np.ndarray  # 3 × 3, pelvis axes in the world
    linear_velocity: np.ndarray  # of the pelvis origin, m/s
    angular_velocity: np.ndarray  # rad/s
    contacts: tuple[bool, bool]  # left and right sole on the ground

    @property
    def yaw(self) -> float:
        return float(np.arctan2(self.rotation[1, 0], self.rotation[0, 0]))


class StateEstimator:
    """Pelvis pose and velocity at each control step, from IMU, encoders and foot contacts."""

    def __init__(self, config: RobotConfig, joints: list[str], dt: float, imu_latency: float | None = None) -> None:
        if config.legs is None or config.imu is None or config.imu.orientation is None:
            raise ValueError(f"robot '{config.name}' needs legs and an IMU with an attitude output to estimate")
        self.dt = dt
        self.imu_latency = dt if imu_latency is None else imu_latency  # s: one physics step (module docstring)
        self.model = robot_model(config)
        self.data = self.model.createData()
        self.joints = list(joints)
        self._q_index = np.array([self.model.joints[self.model.getJointId(j)].idx_q for j in joints])
        self._v_index = np.array([self.model.joints[self.model.getJointId(j)].idx_v for j in joints])
        self._q = pin.neutral(self.model)  # the pelvis stays at the origin: kinematics relative to it
        self._v = np.zeros(self.model.nv)
        self._soles = [self.model.getFrameId(leg.sole) for leg in (config.legs.left, config.legs.right)]
        imu = self.model.frames[self.model.getFrameId(config.imu.site)]
        if self.model.names[imu.parentJoint] != self.model.names[1]:
            raise ValueError(f"robot '{config.name}': the IMU must sit on the pelvis (the free-flyer's body)")
        self._imu_in_pelvis = imu.placement  # fixed: the IMU is mounted on the pelvis
        self._diagonal = np.diag_indices(12)
        self._models: dict[tuple[tuple[bool, bool], float], tuple[np.ndarray, ...]] = {}
        self._contact = [True, True]
        self.x = np.zeros(12)  # IMU position, IMU velocity, left sole, right sole (world)
        self.P = np.eye(12) * INITIAL_POSITION_SPREAD**2
        self._rotation = np.eye(3)  # IMU attitude
        self._initialised = False
        self._synchronous = True
        self.state: BaseState | None = None

    # --- inputs --------------------------------------------------------------------------------------------------

    def reset(
        self,
        quaternion: np.ndarray,
        joint_positions: np.ndarray,
        start: tuple[float, float] = (0.0, 0.0),
    ) -> None:
        """Start standing: both soles flat on the floor (z = 0), their midpoint at ``start`` (x, y)."""
        rotation = _rotation(quaternion)
        relative = self._kinematics(joint_positions)[0]  # soles relative to the IMU, IMU axes
        soles = [rotation @ r for r in relative]
        middle = (soles[0] + soles[1]) / 2
        imu = np.array([start[0], start[1], 0.0]) - middle
        self.x = np.concatenate([imu, np.zeros(3), imu + soles[0], imu + soles[1]])
        self.P = np.eye(12) * INITIAL_POSITION_SPREAD**2
        self._contact = [True, True]
        self._rotation = rotation
        self._initialised = True
        self._synchronous = True  # the first readings after a reset are of the same instant as the reset

    def update(
        self,
        quaternion: np.ndarray,
        gyro: np.ndarray,
        accelerometer: np.ndarray,
        joint_positions: np.ndarray,
        joint_velocities: np.ndarray,
        touch: tuple[float, float],
    ) -> BaseState:
        """One control step: the sensors now (IMU site frame; ``joints`` order; the soles' normal forces)."""
        if not self._initialised:
            self.reset(quaternion, joint_positions)
        for side in (0, 1):  # hysteresis on the touch sensors
            if self._contact[side] and touch[side] < CONTACT_OFF:
                self._contact[side] = False
            elif not self._contact[side] and touch[side] > CONTACT_ON:
                self._contact[side] = True
        # the attitude now: the reading's, turned on by the body rates over the IMU's latency
        latency, dt = (0.0, 0.0) if self._synchronous else (self.imu_latency, self.dt)
        self._synchronous = False
        rotation = _rotation(quaternion) @ pin.exp3(np.asarray(gyro, dtype=float) * latency)
        omega = rotation @ gyro  # world frame

        # prediction: the accelerometer's specific force plus gravity, integrated (the IMU's own point)
        acceleration = rotation @ accelerometer + GRAVITY
        x = self.x
        x[0:3] += x[3:6] * dt + 0.5 * acceleration * dt**2
        x[3:6] += acceleration * dt
        # measurements: each sole relative to the IMU; a standing sole's stillness gives the IMU's velocity
        relative, rates = self._kinematics(joint_positions, joint_velocities)
        offsets = [rotation @ r for r in relative]
        implied = [-_cross(omega, offsets[side]) - rotation @ rates[side] for side in (0, 1)]
        contacts = self._still_soles(implied, x[3:6])
        F, Q, H, noise = self._filter_model(contacts, dt)
        P = F @ self.P @ F.T
        P[self._diagonal] += Q
        values = []
        for side in (0, 1):
            values.append(offsets[side])
            if contacts[side]:
                values += [implied[side], np.array([FLOOR_HEIGHT])]
        innovation = np.concatenate(values) - H @ x
        PH = P @ H.T
        S = H @ PH
        S[np.diag_indices(len(S))] += noise
        gain = np.linalg.solve(S, PH.T).T  # P Hᵀ S⁻¹ (S and P symmetric)
        self.x = x + gain @ innovation
        P = P - gain @ PH.T
        self.P = 0.5 * (P + P.T)
        self._rotation = rotation

        # the pelvis origin from the IMU's point
        placement = self._imu_in_pelvis
        pelvis_rotation = rotation @ placement.rotation.T
        lever = pelvis_rotation @ placement.translation  # pelvis origin → IMU, world axes
        self.state = BaseState(
            position=self.x[0:3] - lever,
            rotation=pelvis_rotation,
            linear_velocity=self.x[3:6] - _cross(omega, lever),
            angular_velocity=omega,
            contacts=(self._contact[0], self._contact[1]),
        )
        return self.state

    def _still_soles(self, implied: list[np.ndarray], predicted: np.ndarray) -> tuple[bool, bool]:
        """Which touching soles stand still: those whose implied IMU velocity agrees with the prediction. If none
        does, the one that agrees best: the filter is not left to the accelerometer alone."""
        touching = [side for side in (0, 1) if self._contact[side]]
        misfit = {side: float(np.linalg.norm(implied[side] - predicted)) for side in touching}
        still = [side for side in touching if misfit[side] <= SLIP_SPEED]
        if not still and touching:
            still = [min(touching, key=misfit.__getitem__)]
        return (0 in still, 1 in still)

    # --- outputs -------------------------------------------------------------------------------------------------

    def sole_positions(self) -> tuple[np.ndarray, np.ndarray]:
        """Where the filter believes each sole is (world)."""
        return self.x[6:9].copy(), self.x[9:12].copy()

    # --- the filter's matrices ------------------------------------------------------------------------------------

    def _filter_model(self, contacts: tuple[bool, bool], dt: float) -> tuple[np.ndarray, ...]:
        """F, the process noise Q (diagonal), the measurement matrix H and its noise (diagonal) for these contacts;
        four combinations, built once each."""
        key = (contacts, dt)
        if key not in self._models:
            F = np.eye(12)
            F[0:3, 3:6] = dt * np.eye(3)
            Q = np.zeros(12)
            Q[0:3] = (0.5 * ACCELEROMETER_NOISE * dt**2) ** 2
            Q[3:6] = (ACCELEROMETER_NOISE * dt) ** 2
            rows, noise = [], []
            for side in (0, 1):
                drift = STANCE_FOOT_DRIFT if contacts[side] else SWING_FOOT_DRIFT
                Q[6 + 3 * side : 9 + 3 * side] = drift**2 * dt
                H = np.zeros((3, 12))  # the sole relative to the IMU: p_sole − p_imu
                H[:, 0:3] = -np.eye(3)
                H[:, 6 + 3 * side : 9 + 3 * side] = np.eye(3)
                rows.append(H)
                noise.append(np.full(3, KINEMATICS_NOISE**2))
                if contacts[side]:
                    H = np.zeros((3, 12))  # the IMU's velocity that a still sole implies
                    H[:, 3:6] = np.eye(3)
                    rows.append(H)
                    noise.append(np.full(3, VELOCITY_NOISE**2))
                    H = np.zeros((1, 12))  # a still sole's height: the floor's
                    H[0, 8 + 3 * side] = 1.0
                    rows.append(H)
                    noise.append(np.array([FLOOR_NOISE**2]))
            self._models[key] = (F, Q, np.vstack(rows), np.concatenate(noise))
        return self._models[key]

    # --- kinematics ----------------------------------------------------------------------------------------------

    def _kinematics(
        self, joint_positions: np.ndarray, joint_velocities: np.ndarray | None = None
    ) -> tuple[list[np.ndarray], list[np.ndarray]]:
        """Each sole's position relative to the IMU and its rate of change, in the IMU's axes."""
        self._q[self._q_index] = joint_positions
        model, data = self.model, self.data
        if joint_velocities is None:
            pin.forwardKinematics(model, data, self._q)
        else:
            self._v[self._v_index] = joint_velocities
            pin.forwardKinematics(model, data, self._q, self._v)
        placement = self._imu_in_pelvis
        relative, rates = [], []
        for frame in self._soles:
            sole = pin.updateFramePlacement(model, data, frame)  # the two soles only, not every frame
            relative.append(placement.rotation.T @ (sole.translation - placement.translation))
            if joint_velocities is not None:
                # the sole's velocity in the pelvis frame with the pelvis held still: the legs' joint rates alone
                velocity = pin.getFrameVelocity(model, data, frame, pin.LOCAL_WORLD_ALIGNED).linear
                rates.append(placement.rotation.T @ velocity)
        return relative, rates


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a × b for 3-vectors (numpy's cross is slow on single vectors)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _rotation(quaternion: np.ndarray) -> np.ndarray:
    """3 × 3 rotation of a unit quaternion w, x, y, z (MuJoCo's order)."""
    w, x, y, z = quaternion
    return pin.Quaternion(w, x, y, z).normalized().toRotationMatrix()
