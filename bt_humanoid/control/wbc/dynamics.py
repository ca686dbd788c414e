"""Pinocchio rigid-body dynamics of a floating-base robot, for the inverse-dynamics QP.

The model is ``robot_model()``'s: the MJCF MuJoCo simulates, with the free joint as Pinocchio's free-flyer. All
quantities are numeric (``pinocchio.casadi`` is not in the wheels) and recomputed by ``update(q, v)`` once per
control step; tasks and limits then ask for what they need, and frame quantities are cached until the next
update.

Conventions (Pinocchio's): ``q`` is the pelvis position, its quaternion x, y, z, w, then one coordinate per joint;
``v`` is the pelvis's linear and angular velocity in the pelvis frame, then one rate per joint. Joints come in
the model's order (``joints``), which is also MuJoCo's for the same MJCF. Jacobians and their drifts are in
LOCAL_WORLD_ALIGNED: the frame's origin, the world's axes.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from bt_humanoid.control.wbc.kinematics import cached_frame_id, robot_model
from bt_humanoid.sim.robot_config import RobotConfig

BASE_DOFS = 6  # the free-flyer's velocity coordinates
WORLD = pin.LOCAL_WORLD_ALIGNED


class RobotDynamics:
    """Mass matrix, bias forces, frame and centre-of-mass kinematics of a floating-base robot at one state."""

    def __init__(self, config: RobotConfig) -> None:
        if not config.base.floating:
            raise ValueError(f"robot '{config.name}' has no floating base: RobotDynamics is for legged robots")
        self.model = pin.Model(robot_model(config))  # its own copy: a payload changes its inertias
        self.data = self.model.createData()
        if self.model.joints[1].shortname() != "JointModelFreeFlyer":
            raise ValueError(f"robot '{config.name}': the model's first joint must be its free-flyer")
        #: every joint but the free-flyer, in the model's order; each has one coordinate (hinges and slides)
        self.joints = [self.model.names[j] for j in range(2, self.model.njoints)]
        if self.model.nv != BASE_DOFS + len(self.joints):
            raise ValueError(f"robot '{config.name}': every joint below the free-flyer must have one coordinate")
        self.nv = self.model.nv
        self.mass = float(pin.computeTotalMass(self.model))
        self.gravity = -float(self.model.gravity.linear[2])  # m/s², positive
        # MuJoCo's joint damping is a passive force −d·q̇ that Pinocchio's bias forces leave out
        self._damping = np.array(self.model.damping, dtype=float)
        self._zero = np.zeros(self.nv)
        self.q = pin.neutral(self.model)
        self.v = np.zeros(self.nv)
        self._mass_matrix = np.zeros((self.nv, self.nv))
        self._bias = np.zeros(self.nv)
        self._frame_ids: dict[str, int] = {}
        self._jacobians: dict[str, np.ndarray] = {}
        self._drifts: dict[str, np.ndarray] = {}
        self._momentum_drift: np.ndarray | None = None
        self._bare_inertias = [pin.Inertia(inertia) for inertia in self.model.inertias]
        self.payloads: dict[str, float] = {}  # kg held at a frame (set_payload)

    # --- what the robot carries ---------------------------------------------------------------------------------

    def set_payload(self, frame: str, mass: float) -> None:
        """Carry a point mass of ``mass`` kg at ``frame`` (a hand's grip site): it joins the inertia of the body
        the frame is on, and the whole-body terms, the centre of mass and ``mass`` count it from the next
        ``update``. 0 takes it away again."""
        if mass < 0.0:
            raise ValueError(f"a payload's mass is not negative (got {mass} kg at {frame})")
        self.payloads[frame] = mass
        model = self.model
        for joint, bare in enumerate(self._bare_inertias):
            model.inertias[joint] = pin.Inertia(bare)
        for name, held in self.payloads.items():
            placed = model.frames[self.frame_id(name)]
            point = pin.Inertia(held, placed.placement.translation, np.zeros((3, 3)))
            model.inertias[placed.parentJoint] = model.inertias[placed.parentJoint] + point
        self.mass = float(pin.computeTotalMass(model))

    # --- state -----------------------------------------------------------------------------------------------

    def joint_index(self, joint: str) -> int:
        """Column of ``joint`` in v (and in every Jacobian); its coordinate in q is one further on."""
        return BASE_DOFS + self.joints.index(joint)

    def state(
        self,
        position: np.ndarray,
        rotation: np.ndarray,
        linear_velocity: np.ndarray,
        angular_velocity: np.ndarray,
        joint_positions: np.ndarray,
        joint_velocities: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        """(q, v) from the pelvis's pose and world-frame velocities (as an estimator gives them) and the joints'
        positions and velocities in ``joints`` order."""
        quat = pin.Quaternion(np.asarray(rotation, dtype=float)).coeffs()  # x, y, z, w
        q = np.concatenate([position, quat, joint_positions])
        twist = np.concatenate([rotation.T @ linear_velocity, rotation.T @ angular_velocity])
        return q, np.concatenate([twist, joint_velocities])

    def update(self, q: np.ndarray, v: np.ndarray) -> None:
        """Recompute everything at (q, v): M, h, joint Jacobians, the centre of mass with its Jacobian, and every
        body's acceleration at zero joint acceleration (the drifts J̇v)."""
        self.q = np.asarray(q, dtype=float)
        self.v = np.asarray(v, dtype=float)
        model, data = self.model, self.data
        pin.computeAllTerms(model, data, self.q, self.v)
        # second-order kinematics with v̇ = 0: data.a becomes J̇v for every joint, data.acom the CoM's drift
        pin.centerOfMass(model, data, self.q, self.v, self._zero, False)
        pin.updateFramePlacements(model, data)
        upper = data.M
        self._mass_matrix = np.triu(upper) + np.triu(upper, 1).T  # Pinocchio fills the upper triangle only
        self._bias = data.nle + self._damping * self.v
        self._jacobians.clear()
        self._drifts.clear()
        self._momentum_drift: np.ndarray | None = None

    # --- whole body --------------------------------------------------------------------------------------------

    @property
    def mass_matrix(self) -> np.ndarray:
        """M(q), nv × nv (rotor inertias included: Pinocchio reads MuJoCo's armature)."""
        return self._mass_matrix

    @property
    def bias(self) -> np.ndarray:
        """h(q, v): Coriolis, centrifugal, gravity and joint damping, so that M v̇ + h = Sᵀτ + Σ Jᵀf."""
        return self._bias

    # --- frames ------------------------------------------------------------------------------------------------

    def frame_id(self, frame: str) -> int:
        return cached_frame_id(self.model, self._frame_ids, frame)

    def pose(self, frame: str) -> pin.SE3:
        """World pose of a frame (site, body or joint name)."""
        return self.data.oMf[self.frame_id(frame)]

    def jacobian(self, frame: str) -> np.ndarray:
        """6 × nv Jacobian (linear; angular) of the frame's origin, world axes."""
        if frame not in self._jacobians:
            self._jacobians[frame] = pin.getFrameJacobian(self.model, self.data, self.frame_id(frame), WORLD)
        return self._jacobians[frame]

    def drift(self, frame: str) -> np.ndarray:
        """J̇v (linear; angular), world axes: the frame origin's classical acceleration when v̇ = 0."""
        if frame not in self._drifts:
            acceleration = pin.getFrameClassicalAcceleration(self.model, self.data, self.frame_id(frame), WORLD)
            self._drifts[frame] = acceleration.vector.copy()
        return self._drifts[frame]

    def velocity(self, frame: str) -> np.ndarray:
        """The frame's twist (linear; angular), world axes."""
        return self.jacobian(frame) @ self.v

    # --- centre of mass ----------------------------------------------------------------------------------------

    @property
    def com(self) -> np.ndarray:
        return self.data.com[0]

    @property
    def com_velocity(self) -> np.ndarray:
        return self.data.vcom[0]

    @property
    def com_jacobian(self) -> np.ndarray:
        """3 × nv."""
        return self.data.Jcom

    @property
    def com_drift(self) -> np.ndarray:
        """J̇_c v: the centre of mass's acceleration when v̇ = 0."""
        return self.data.acom[0]

    # --- centroidal momentum -----------------------------------------------------------------------------------

    @property
    def centroidal_map(self) -> np.ndarray:
        """A_g (6 × nv): the centroidal momentum (linear; angular, about the centre of mass) is A_g v."""
        return self.data.Ag

    @property
    def centroidal_momentum(self) -> np.ndarray:
        """(m ċ; L), world axes, about the centre of mass."""
        return self.data.hg.vector

    @property
    def centroidal_drift(self) -> np.ndarray:
        """Ȧ_g v: the centroidal momentum's rate of change when v̇ = 0."""
        if self._momentum_drift is None:
            pin.computeCentroidalMomentumTimeVariation(self.model, self.data, self.q, self.v, self._zero)
            self._momentum_drift = self.data.dhg.vector.copy()
        return self._momentum_drift
