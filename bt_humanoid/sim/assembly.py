"""Compose robots and worlds with mujoco.MjSpec.

A robot is its lower body with the upper body attached at the mount site; a
world is its scene with the robot attached at the origin (the start pose is an
initial joint state, set by the Simulation). Names are kept unprefixed: one
robot per world, and robot.yaml refers to joints by their MJCF names.
"""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET
from contextlib import contextmanager
from pathlib import Path

import mujoco
import numpy as np

from bt_humanoid.sim.people import add_arm
from bt_humanoid.sim.robot_config import RobotConfig
from bt_humanoid.sim.scene_objects import PlacedObject, add_objects
from bt_humanoid.sim.world_config import Walker, WorldConfig

_EMPTY_PREFIX_WARNING = "Attaching a spec with an empty prefix"
# MuJoCo repeats the Python warning at compile and save time, outside any context.
warnings.filterwarnings("ignore", message=_EMPTY_PREFIX_WARNING)


@contextmanager
def _quiet_empty_prefix_warning():
    """MuJoCo warns that unprefixed attaches may not save; ours round-trip (tested)."""
    previous = mujoco.get_mju_user_warning()

    def handler(message: str) -> None:
        if _EMPTY_PREFIX_WARNING not in message and previous is not None:
            previous(message)

    mujoco.set_mju_user_warning(handler)
    try:
        yield
    finally:
        mujoco.set_mju_user_warning(previous)


def robot_spec(config: RobotConfig) -> mujoco.MjSpec:
    """The robot alone: lower body + upper body at the mount site."""
    lower = mujoco.MjSpec.from_file(str(config.folder / config.parts.lower_body))
    upper = mujoco.MjSpec.from_file(str(config.folder / config.parts.upper_body))
    with _quiet_empty_prefix_warning():
        lower.attach(upper, site=config.parts.mount_site, prefix="")
    lower.modelname = config.name
    if config.base.floating:
        _no_body_gravcomp(lower)
    return lower


def _no_body_gravcomp(spec: mujoco.MjSpec) -> None:
    """Switch off MuJoCo's body gravity compensation on a robot with a floating base.

    ``gravcomp`` pushes each body up with its own weight; ``actuatorgravcomp`` routes a joint's share of that
    through its actuator, but a free joint has no actuator and no force limit, so its share, the whole weight of
    every compensated body, would hold the robot up from outside. On a floating base the motors must carry the
    weight (the controller's gravity torques), as real ones do.
    """
    for body in spec.bodies:
        body.gravcomp = 0.0


def world_spec(world: WorldConfig, robot: RobotConfig, objects: list[PlacedObject] | None = None) -> mujoco.MjSpec:
    """The world's model with the scene's objects in it and the robot attached at the origin."""
    scene = mujoco.MjSpec.from_file(str(world.model_path))
    for body, walker in world.walkers.items():
        _add_walker(scene, body, walker)
    for person in world.people.values():
        add_arm(scene, person.body)
    add_objects(scene, world, objects or [])
    frame = scene.worldbody.add_frame()
    with _quiet_empty_prefix_warning():
        scene.attach(robot_spec(robot), frame=frame, prefix="")
    return scene


WALKER_MASS = 60.0  # kg
WALKER_HEIGHT = 1.7  # m


def _add_walker(scene: mujoco.MjSpec, name: str, walker: Walker) -> None:
    """A person on two slide joints (x, y) driven by velocity actuators: they move only by force."""
    x, y = walker.route[0]
    body = scene.worldbody.add_body(name=name, pos=[x, y, 0.0])
    for axis, direction in (("x", [1, 0, 0]), ("y", [0, 1, 0])):
        joint = body.add_joint(name=f"{name}_{axis}", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=direction, damping=50)
        scene.add_actuator(
            name=f"{name}_{axis}",
            trntype=mujoco.mjtTrn.mjTRN_JOINT,
            target=joint.name,
            gaintype=mujoco.mjtGain.mjGAIN_FIXED,
            biastype=mujoco.mjtBias.mjBIAS_AFFINE,
            gainprm=[2000, 0, 0, 0, 0, 0, 0, 0, 0, 0],
            biasprm=[0, 0, -2000, 0, 0, 0, 0, 0, 0, 0],
            forcelimited=True,
            forcerange=[-400, 400],
        )
    r = walker.radius
    body.add_geom(
        name=f"{name}_body",
        type=mujoco.mjtGeom.mjGEOM_CAPSULE,
        fromto=[0, 0, r + 0.02, 0, 0, WALKER_HEIGHT - r],
        size=[r, 0, 0],
        mass=WALKER_MASS,
        rgba=[0.3, 0.45, 0.7, 1],
    )


def write_robot_mjcf(config: RobotConfig, path: Path) -> Path:
    """Write the composed robot as one frame-free MJCF file (for Pinocchio)."""
    spec = robot_spec(config)
    spec.compile()
    root = ET.fromstring(spec.to_xml())
    _flatten_frames(root)
    path.write_text(ET.tostring(root, encoding="unicode"))
    return path


def _vec(element: ET.Element, key: str, default: list[float]) -> np.ndarray:
    text = element.get(key)
    return np.array([float(v) for v in text.split()]) if text else np.array(default, dtype=float)


def _flatten_frames(parent: ET.Element) -> None:
    """Fold every <frame> into its children's pos/quat.

    Pinocchio's MJCF parser silently drops bodies inside <frame> elements
    (docs/dependencies.md), and MjSpec writes one wherever a spec was attached.
    """
    for child in list(parent):
        _flatten_frames(child)
        if child.tag != "frame":
            continue
        frame_pos = _vec(child, "pos", [0, 0, 0])
        frame_quat = _vec(child, "quat", [1, 0, 0, 0])
        if any(child.get(k) for k in ("euler", "axisangle", "xyaxes", "zaxis")):
            raise ValueError("frames must use pos/quat to be flattened")
        index = list(parent).index(child)
        parent.remove(child)
        for offset, grandchild in enumerate(list(child)):
            if any(grandchild.get(k) for k in ("euler", "axisangle", "xyaxes", "zaxis")):
                raise ValueError(f"<{grandchild.tag} name={grandchild.get('name')}> must use pos/quat")
            pos = np.zeros(3)
            mujoco.mju_rotVecQuat(pos, _vec(grandchild, "pos", [0, 0, 0]), frame_quat)
            quat = np.zeros(4)
            mujoco.mju_mulQuat(quat, frame_quat, _vec(grandchild, "quat", [1, 0, 0, 0]))
            grandchild.set("pos", " ".join(f"{v:.9g}" for v in pos + frame_pos))
            grandchild.set("quat", " ".join(f"{v:.9g}" for v in quat))
            parent.insert(index + offset, grandchild)


def joint_ranges(config: RobotConfig) -> dict[str, tuple[float, float]]:
    """Position range of every limited joint of the robot, from its MJCF."""
    model = robot_spec(config).compile()
    return {
        model.joint(i).name: (float(model.jnt_range[i][0]), float(model.jnt_range[i][1]))
        for i in range(model.njnt)
        if model.jnt_limited[i]
    }
