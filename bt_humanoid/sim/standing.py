"""The neutral standing posture of a legged robot, computed from its model.

Both soles flat on the floor, parallel and facing +x, ``width`` apart and centred on the origin; the pelvis
upright at ``pelvis_height``; the centre of mass over the middle of the soles; the upper body in a named
posture of robot.yaml. That is 18 conditions (two sole poses, the pelvis's height and attitude, the centre of
mass's x and y) on 18 unknowns (the floating base's six coordinates and the twelve leg joints), solved by
Newton's method on the model's own kinematics. Below straight legs the knees bend; a start with the knees bent
forwards picks that branch (the other would bend them backwards, outside their range).

It lives beside the simulation because the simulation starts a legged robot in it (the scene file's ``home``
keyframe; a world's start pose); controllers take it from here as their nominal posture. The same posture is
checked in Pinocchio by tests/test_biped_model.py.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from bt_humanoid.sim.assembly import robot_spec
from bt_humanoid.sim.robot_config import RobotConfig

TOLERANCE = 1e-10  # m and rad: the residual the solution meets
MAX_ITERATIONS = 50
_SCALAR_JOINTS = {int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)}
KNEE_GUESS = 0.6  # rad: the start bends each knee this much, ankle and hip pitch half as much the other way


@dataclass(frozen=True)
class Stance:
    """A standing posture: the robot's joint positions with the feet centred on the world origin, facing +x."""

    qpos: np.ndarray  # of the robot alone (robot_spec's order); the free joint's quaternion is w, x, y, z
    joints: dict[str, float]  # every hinge and slide joint of the robot
    base_joint: str  # the free joint
    pelvis_height: float  # m
    width: float  # m between the sole centres
    com: np.ndarray  # the centre of mass (world frame, m)

    @property
    def base(self) -> np.ndarray:
        """The free joint's pose in the stance: position (3) and quaternion (w, x, y, z)."""
        return self.qpos[:7].copy()

    def base_pose(self, x: float, y: float, yaw: float) -> np.ndarray:
        """The free joint's pose that stands the robot with its feet centred on (x, y), facing ``yaw`` (rad)."""
        c, s = math.cos(yaw), math.sin(yaw)
        px, py, pz = self.qpos[:3]
        position = [x + c * px - s * py, y + s * px + c * py, pz]
        return np.array([*position, math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])


def standing_posture(
    config: RobotConfig,
    pelvis_height: float | None = None,
    width: float | None = None,
    posture: str = "home",
) -> Stance:
    """The neutral stance of a legged robot (robot.yaml ``legs.stance`` unless given); ValueError when the legs
    cannot reach it within their joint ranges."""
    if config.legs is None:
        raise ValueError(f"robot '{config.name}' has no legs to stand on")
    legs = config.legs
    height = legs.stance.pelvis_height if pelvis_height is None else pelvis_height
    spread = legs.stance.width if width is None else width
    model = robot_spec(config).compile()
    data = mujoco.MjData(model)
    free = model.joint(config.base.root_joint)
    if int(free.type[0]) != int(mujoco.mjtJoint.mjJNT_FREE) or free.qposadr[0] != 0:
        raise ValueError(f"robot '{config.name}': the base joint '{free.name}' must be the model's first, a free joint")
    pelvis = int(free.bodyid[0])

    q = model.qpos0.copy()
    for joint, value in config.postures.get(posture, {}).items():
        q[model.joint(joint).qposadr[0]] = value
    q[:7] = [0.0, 0.0, height, 1.0, 0.0, 0.0, 0.0]
    for leg in (legs.left, legs.right):
        _, _, hip_pitch, knee, ankle_pitch, _ = leg.joints
        for joint, value in ((hip_pitch, -KNEE_GUESS / 2), (knee, KNEE_GUESS), (ankle_pitch, -KNEE_GUESS / 2)):
            q[model.joint(joint).qposadr[0]] = value

    columns = list(range(6)) + [int(model.joint(j).dofadr[0]) for j in legs.joints]
    soles = [(model.site(legs.left.sole).id, spread / 2), (model.site(legs.right.sole).id, -spread / 2)]
    jacp, jacr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    for _ in range(MAX_ITERATIONS):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        errors, rows = [], []
        for site, y in soles:
            mujoco.mj_jacSite(model, data, jacp, jacr, site)
            errors += [np.array([0.0, y, 0.0]) - data.site_xpos[site], _rotation_error(data.site_xmat[site])]
            rows += [jacp.copy(), jacr.copy()]
        mujoco.mj_jacBody(model, data, jacp, jacr, pelvis)
        errors += [[height - data.xpos[pelvis][2]], _rotation_error(data.xmat[pelvis])]
        rows += [jacp[2:3].copy(), jacr.copy()]
        mujoco.mj_jacSubtreeCom(model, data, jacp, pelvis)
        errors.append(-data.subtree_com[pelvis][:2])
        rows.append(jacp[:2].copy())
        error = np.concatenate(errors)
        if np.max(np.abs(error)) < TOLERANCE:
            break
        step = np.zeros(model.nv)
        step[columns] = np.linalg.lstsq(np.vstack(rows)[:, columns], error, rcond=None)[0]
        mujoco.mj_integratePos(model, q, step, 1.0)
    else:
        raise ValueError(
            f"robot '{config.name}' cannot stand with its pelvis {height:.3f} m up and its feet {spread:.3f} m apart"
        )
    q[3:7] /= np.linalg.norm(q[3:7])

    joints = {
        model.joint(j).name: float(q[model.jnt_qposadr[j]])
        for j in range(model.njnt)
        if int(model.jnt_type[j]) in _SCALAR_JOINTS
    }
    for joint in legs.joints:
        low, high = model.joint(joint).range
        if not low <= joints[joint] <= high:
            raise ValueError(
                f"robot '{config.name}': standing with the pelvis {height:.3f} m up puts {joint} at "
                f"{joints[joint]:.3f} rad, outside its range [{low:.3f}, {high:.3f}]"
            )
    return Stance(q, joints, free.name, height, spread, data.subtree_com[pelvis].copy())


def _rotation_error(matrix: np.ndarray) -> np.ndarray:
    """The rotation vector (world frame) that takes a frame with rotation ``matrix`` to the world's axes."""
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, matrix)
    inverse = np.zeros(4)
    mujoco.mju_negQuat(inverse, quat)
    error = np.zeros(3)
    mujoco.mju_quat2Vel(error, inverse, 1.0)
    return error
