"""Pinocchio kinematics of the robot, indexed by the whole-body controller's joints.

The model is built from the same MJCF MuJoCo simulates (written frame-free by
``write_robot_mjcf``). The controller works on a reduced set of joints (base
x/y/yaw, waist, arms, head); every Jacobian returned here has one column per
controlled joint, in that order.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pinocchio as pin

from bt_humanoid.sim.assembly import robot_spec, write_robot_mjcf
from bt_humanoid.sim.robot_config import RobotConfig

_models: dict[Path, pin.Model] = {}


def robot_model(config: RobotConfig) -> pin.Model:
    """Pinocchio model of a robot, built once per process (a few tens of ms).

    A planar base's x, y and yaw joints become one composite joint; a floating base's MJCF free joint becomes a
    free-flyer (configuration x, y, z, then the quaternion as x, y, z, w where MuJoCo writes w, x, y, z).
    """
    if config.folder in _models:
        return _models[config.folder]
    with tempfile.TemporaryDirectory() as folder:
        model = pin.buildModelFromMJCF(str(write_robot_mjcf(config, Path(folder) / "robot.xml")))
    _add_camera_frames(model, config)
    _models[config.folder] = model
    return model


def _add_camera_frames(model: pin.Model, config: RobotConfig) -> None:
    """Pinocchio does not import MJCF cameras: add each as a frame on its body (looking along -z)."""
    mj_model = robot_spec(config).compile()
    for i in range(mj_model.ncam):
        camera = mj_model.camera(i)
        body = mj_model.body(int(mj_model.cam_bodyid[i])).name
        parent = model.getFrameId(body, pin.FrameType.BODY)
        rotation = np.zeros(9)
        mujoco.mju_quat2Mat(rotation, mj_model.cam_quat[i])
        placement = model.frames[parent].placement * pin.SE3(rotation.reshape(3, 3), mj_model.cam_pos[i].copy())
        model.addFrame(
            pin.Frame(camera.name, model.frames[parent].parentJoint, parent, placement, pin.FrameType.OP_FRAME)
        )


def cached_frame_id(model: pin.Model, cache: dict[str, int], frame: str) -> int:
    """A frame's id in ``model``, looked up once per name (KeyError naming the frame if it has none)."""
    if frame not in cache:
        if not model.existFrame(frame):
            raise KeyError(f"robot has no frame {frame!r}")
        cache[frame] = model.getFrameId(frame)
    return cache[frame]


def controlled_indices(model: pin.Model, config: RobotConfig, joints: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """Where each of ``joints`` sits in Pinocchio's configuration q and velocity v.

    A floating base is not among them: it stays where the caller leaves it.
    """
    base = config.base.planar_joints
    q_index, v_index = [], []
    for joint in joints:
        if joint in base:
            # MJCF base x/y/yaw become one composite joint in Pinocchio, in that order
            composite = model.joints[model.getJointId(f"Composite_{base[0]}")]
            offset = base.index(joint)
            q_index.append(composite.idx_q + offset)
            v_index.append(composite.idx_v + offset)
        else:
            pin_joint = model.joints[model.getJointId(joint)]
            q_index.append(pin_joint.idx_q)
            v_index.append(pin_joint.idx_v)
    return np.array(q_index, dtype=int), np.array(v_index, dtype=int)


@dataclass
class Parameter:
    """A number a task or limit reads through ``kinematics.parameter``: what differs between goals of one
    signature (a posture's targets, a table's outline), or moves during one (a reach's target)."""

    read: Callable[[], np.ndarray]
    shape: tuple[int, int]
    moving: bool  # read every control step, not once when the goal starts
    symbol: Any = None  # its CasADi symbol, where the QP is built in symbols


class RecordsParameters:
    """Lists the parameters tasks and limits ask for while one QP is built."""

    _recording: list[Parameter] | None = None

    @contextmanager
    def recording_parameters(self) -> Iterator[list[Parameter]]:
        self._recording = []
        try:
            yield self._recording
        finally:
            self._recording = None

    def _record(self, parameter: Parameter) -> None:
        if self._recording is not None:
            self._recording.append(parameter)


class RobotKinematics(RecordsParameters):
    """Forward kinematics and frame Jacobians over the controlled joints."""

    def __init__(self, config: RobotConfig, joints: list[str]) -> None:
        self.model = robot_model(config)
        self.data = self.model.createData()
        self.joints = list(joints)
        self.q = pin.neutral(self.model)
        self.positions = np.zeros(len(self.joints))  # controlled joints, as last set by update()
        self._q_index, self._v_index = controlled_indices(self.model, config, self.joints)
        self._frame_ids: dict[str, int] = {}
        self._jacobians: dict[str, np.ndarray] = {}  # per configuration: tasks and limits ask for the same frames
        self._placed_q: np.ndarray | None = None  # the configuration the frame placements are of; None: not yet
        self._joint_jacobians = False  # whether Pinocchio's joint Jacobians are of it too (computed on demand)

    def index(self, joint: str) -> int:
        return self.joints.index(joint)

    def parameter(self, read: Callable[[], np.ndarray], shape: tuple[int, int], moving: bool = False) -> np.ndarray:
        """A number a task or limit reads that is not fixed by its signature: here, its value now. (A
        ``SymbolicKinematics`` makes it an input of the compiled QP instead.)"""
        self._record(Parameter(read, shape, moving))
        return np.asarray(read(), dtype=float)

    def update(self, positions: np.ndarray) -> None:
        """Set the controlled joints (other joints stay at their last value). Frame placements and Jacobians
        are computed when first asked for and kept while the configuration stays (a control step asks where the
        hands are several times; a step of the compiled QP asks for none)."""
        self._set(positions)
        if self._placed_q is not None and np.array_equal(self.q, self._placed_q):
            return
        self._moved()

    def _moved(self) -> None:
        self._placed_q = None
        self._joint_jacobians = False
        self._jacobians.clear()

    def _place(self) -> None:
        if self._placed_q is None:
            pin.framesForwardKinematics(self.model, self.data, self.q)
            self._placed_q = self.q.copy()

    def _set(self, positions: np.ndarray) -> None:
        self.positions = np.array(positions, dtype=float)
        self.q[self._q_index] = self.positions

    def mass_matrix(self, positions: np.ndarray) -> np.ndarray:
        """Joint-space inertia (n × n over the controlled joints) at ``positions`` (no Jacobians: dynamics only)."""
        self._set(positions)
        self._moved()  # crba leaves the data at these positions: frames are placed afresh when asked for
        full = pin.crba(self.model, self.data, self.q)
        full = np.triu(full) + np.triu(full, 1).T  # Pinocchio fills the upper triangle only
        return full[np.ix_(self._v_index, self._v_index)]

    def frame_id(self, frame: str) -> int:
        return cached_frame_id(self.model, self._frame_ids, frame)

    def pose(self, frame: str) -> pin.SE3:
        """World pose of a frame (site, body or camera name)."""
        self._place()
        return self.data.oMf[self.frame_id(frame)]

    def position(self, frame: str) -> np.ndarray:
        """World position of a frame."""
        return self.pose(frame).translation

    def rotation(self, frame: str) -> np.ndarray:
        """World orientation of a frame as a rotation matrix."""
        return self.pose(frame).rotation

    def jacobian(self, frame: str) -> np.ndarray:
        """6 × n Jacobian (linear; angular) of the frame origin in world-aligned axes."""
        if frame not in self._jacobians:
            self._place()
            if not self._joint_jacobians:
                pin.computeJointJacobians(self.model, self.data, self.q)
                self._joint_jacobians = True
            full = pin.getFrameJacobian(self.model, self.data, self.frame_id(frame), pin.LOCAL_WORLD_ALIGNED)
            self._jacobians[frame] = full[:, self._v_index]
        return self._jacobians[frame]
