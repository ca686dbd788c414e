"""The robot's forward kinematics as CasADi expressions, built from its Pinocchio model.

Pinocchio's own CasADi bindings (pinocchio.casadi) are not in the PyPI wheels, so
the chain is written out here from the model Pinocchio reads from the MJCF:
each joint's placement in its parent, then its motion (a rotation about, or a
slide along, its axis; a planar base is Pinocchio's composite of x, y and yaw;
a floating base a free-flyer whose quaternion comes in as numbers). Frame
Jacobians over the controlled joints are the textbook columns, a × (p − o)
and a for a revolute joint, a for a prismatic one, in world-aligned axes as
``RobotKinematics.jacobian`` gives them (tests compare the two).

It offers what the whole-body tasks and limits ask a ``RobotKinematics`` for
(``position``, ``rotation``, ``jacobian``, ``positions``), so the same task
code builds the QP in symbols once per goal (``compiled.py``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import casadi as ca
import numpy as np
import pinocchio as pin

from bt_humanoid.control.wbc.kinematics import (
    Parameter,
    RecordsParameters,
    cached_frame_id,
    controlled_indices,
    robot_model,
)
from bt_humanoid.sim.robot_config import RobotConfig

_AXES = {"X": np.array([1.0, 0.0, 0.0]), "Y": np.array([0.0, 1.0, 0.0]), "Z": np.array([0.0, 0.0, 1.0])}


@dataclass
class _Axis:
    """One degree of freedom of the chain, where it is in the world."""

    q_index: int  # in Pinocchio's configuration
    revolute: bool
    axis: ca.SX  # unit vector, world axes
    origin: ca.SX  # a point on the axis, world


class SymbolicKinematics(RecordsParameters):
    """Frame poses and Jacobians of the controlled joints, as CasADi SX expressions of the configuration.

    ``controlled`` (the controlled joints' positions, in ``joints`` order) and
    ``configuration`` (Pinocchio's whole q; its entries at controlled joints
    are ignored) are the symbols the expressions depend on.
    """

    def __init__(self, config: RobotConfig, joints: list[str]) -> None:
        self.model = robot_model(config)
        self.robot = str(config.folder)  # which robot: compiled QPs are kept per robot
        self.joints = list(joints)
        self._q_index, _ = controlled_indices(self.model, config, self.joints)
        self.controlled = ca.SX.sym("controlled", len(self.joints))
        self.configuration = ca.SX.sym("q", self.model.nq)
        q = [self.configuration[i] for i in range(self.model.nq)]
        for k, i in enumerate(self._q_index):
            q[i] = self.controlled[k]
        self.positions = self.controlled  # what a task reads as the controlled joints' positions
        self._column = {int(i): k for k, i in enumerate(self._q_index)}  # q index → Jacobian column
        self._placements: list[tuple[ca.SX, ca.SX]] = [(ca.SX.eye(3), ca.SX.zeros(3, 1))]  # per joint: R, p
        self._axes: list[list[_Axis]] = [[]]  # per joint: its own degrees of freedom and its ancestors'
        for j in range(1, self.model.njoints):
            rotation, translation = self._placements[self.model.parents[j]]
            rotation, translation = _compose(rotation, translation, self.model.jointPlacements[j])
            own: list[_Axis] = []
            rotation, translation = self._joint_motion(self.model.joints[j], q, rotation, translation, own)
            self._placements.append((rotation, translation))
            self._axes.append(self._axes[self.model.parents[j]] + own)
        self._frame_ids: dict[str, int] = {}
        self._frames: dict[str, tuple[ca.SX, ca.SX, int]] = {}  # built once each: one graph node per quantity
        self._jacobians: dict[str, ca.SX] = {}

    def index(self, joint: str) -> int:
        return self.joints.index(joint)

    def parameter(self, read: Callable[[], np.ndarray], shape: tuple[int, int], moving: bool = False) -> ca.SX:
        """A number that is not fixed by a task's or limit's signature, as a new symbol: the compiled QP's
        input, fed from ``read`` when a goal starts (and every step if ``moving``)."""
        if self._recording is None:
            raise RuntimeError("a parameter outside recording_parameters(): nothing would feed it")
        symbol = ca.SX.sym(f"p{len(self._recording)}", *shape)
        self._record(Parameter(read, shape, moving, symbol))
        return symbol

    def frame_id(self, frame: str) -> int:
        return cached_frame_id(self.model, self._frame_ids, frame)

    def _frame(self, frame: str) -> tuple[ca.SX, ca.SX, int]:
        if frame not in self._frames:
            data = self.model.frames[self.frame_id(frame)]
            rotation, translation = _compose(*self._placements[data.parentJoint], data.placement)
            self._frames[frame] = rotation, translation, data.parentJoint
        return self._frames[frame]

    def position(self, frame: str) -> ca.SX:
        """World position of a frame (3 × 1)."""
        return self._frame(frame)[1]

    def rotation(self, frame: str) -> ca.SX:
        """World orientation of a frame (3 × 3)."""
        return self._frame(frame)[0]

    def jacobian(self, frame: str) -> ca.SX:
        """6 × n Jacobian (linear; angular) of the frame origin in world-aligned axes, one column per controlled
        joint."""
        if frame in self._jacobians:
            return self._jacobians[frame]
        _, point, joint = self._frame(frame)
        columns = [ca.SX.zeros(6, 1) for _ in self.joints]
        for axis in self._axes[joint]:
            k = self._column.get(axis.q_index)
            if k is None:  # not controlled: a finger, a floating base
                continue
            if axis.revolute:
                columns[k] = ca.vertcat(ca.cross(axis.axis, point - axis.origin), axis.axis)
            else:
                columns[k] = ca.vertcat(axis.axis, ca.SX.zeros(3, 1))
        self._jacobians[frame] = ca.horzcat(*columns)
        return self._jacobians[frame]

    def _joint_motion(
        self, joint: pin.JointModel, q: list[ca.SX], rotation: ca.SX, translation: ca.SX, axes: list[_Axis]
    ) -> tuple[ca.SX, ca.SX]:
        """The placement after ``joint``'s motion, from the one before it; its degrees of freedom go to ``axes``."""
        kind = joint.shortname()
        if kind == "JointModelComposite":
            composite = joint.extract()
            index = joint.idx_q
            for placement, part in zip(composite.jointPlacements, composite.joints, strict=True):
                rotation, translation = _compose(rotation, translation, placement)
                rotation, translation = self._one_dof(part, index, q, rotation, translation, axes)
                index += part.nq
            return rotation, translation
        if kind == "JointModelFreeFlyer":
            i = joint.idx_q
            x, y, z, w = q[i + 3], q[i + 4], q[i + 5], q[i + 6]
            local = ca.vertcat(
                ca.horzcat(1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
                ca.horzcat(2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
                ca.horzcat(2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)),
            )
            return rotation @ local, translation + rotation @ ca.vertcat(q[i], q[i + 1], q[i + 2])
        return self._one_dof(joint, joint.idx_q, q, rotation, translation, axes)

    @staticmethod
    def _one_dof(
        joint: pin.JointModel, index: int, q: list[ca.SX], rotation: ca.SX, translation: ca.SX, axes: list[_Axis]
    ) -> tuple[ca.SX, ca.SX]:
        kind = joint.shortname()
        if kind in ("JointModelRevoluteUnaligned", "JointModelPrismaticUnaligned"):
            axis = np.asarray(joint.extract().axis, dtype=float)
        elif kind[-1] in _AXES and kind[:-1] in ("JointModelR", "JointModelP"):
            axis = _AXES[kind[-1]]
        else:
            raise NotImplementedError(f"symbolic kinematics: joint type {kind} is not supported")
        revolute = kind.startswith("JointModelR")
        axes.append(_Axis(index, revolute, rotation @ ca.SX(axis), translation))
        if revolute:
            skew = ca.SX(pin.skew(axis))
            local = ca.SX.eye(3) + ca.sin(q[index]) * skew + (1 - ca.cos(q[index])) * (skew @ skew)
            return rotation @ local, translation
        return rotation, translation + rotation @ ca.SX(axis) * q[index]


def _compose(rotation: ca.SX, translation: ca.SX, placement: pin.SE3) -> tuple[ca.SX, ca.SX]:
    """(R, p) ∘ placement."""
    return rotation @ ca.SX(placement.rotation), translation + rotation @ ca.SX(placement.translation)


_built: dict[tuple[str, tuple[str, ...]], SymbolicKinematics] = {}


def symbolic_kinematics(config: RobotConfig, joints: list[str]) -> SymbolicKinematics:
    """The process's symbolic kinematics of a robot over these joints, built once (a few tens of ms)."""
    key = (str(config.folder), tuple(joints))
    if key not in _built:
        _built[key] = SymbolicKinematics(config, joints)
    return _built[key]
