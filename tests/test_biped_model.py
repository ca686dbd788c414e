"""The biped humanoid's model: one MJCF that MuJoCo and Pinocchio (free-flyer root) read alike, the figures of a
real mid-size humanoid (Unitree G1 motors), sensors that read the robot's weight, and a computed neutral stance
with both feet flat on the floor and the centre of mass over them. Nothing but its motors may hold it up."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from bt_humanoid.control.wbc.kinematics import robot_model
from bt_humanoid.errors import UserError
from bt_humanoid.paths import robots_dir
from bt_humanoid.sim.assembly import robot_spec
from bt_humanoid.sim.robot_config import LEG_ROLES, RobotConfig, load_robot_config
from bt_humanoid.sim.robot_scene import scene_spec
from bt_humanoid.sim.scene_config import SceneConfig
from bt_humanoid.sim.simulation import Simulation
from bt_humanoid.sim.standing import standing_posture
from bt_humanoid.sim.world_config import load_world_config
from bt_humanoid.yaml_source import read_config

ROBOT = "biped_humanoid"
# Unitree G1, 29 DoF, rev 1.0 (unitree_ros/robots/g1_description/g1_29dof_rev_1_0.xml and .urdf at adb48c7)
G1_TORQUE = {"hip_yaw": 88, "hip_roll": 139, "hip_pitch": 88, "knee": 139, "ankle_pitch": 50, "ankle_roll": 50}
G1_SPEED = {"hip_yaw": 32, "hip_roll": 20, "hip_pitch": 32, "knee": 20, "ankle_pitch": 37, "ankle_roll": 37}
GRAVITY = 9.81


@pytest.fixture(scope="module")
def config() -> RobotConfig:
    return load_robot_config(ROBOT)


@pytest.fixture(scope="module")
def model(config) -> mujoco.MjModel:
    return robot_spec(config).compile()


@pytest.fixture(scope="module")
def pin_model(config) -> pin.Model:
    return robot_model(config)


@pytest.fixture(scope="module")
def stance(config):
    return standing_posture(config)


@pytest.fixture(scope="module")
def scene(config) -> mujoco.MjModel:
    """The robot on a floor (robots/biped_humanoid/scene.xml), its 'home' keyframe the stance."""
    return scene_spec(config).compile()


def pin_configuration(model: mujoco.MjModel, pin_model: pin.Model, qpos: np.ndarray) -> np.ndarray:
    """MuJoCo's qpos as Pinocchio's q: joints matched by name; the free joint's quaternion w, x, y, z → x, y, z, w."""
    q = pin.neutral(pin_model)
    for j in range(model.njnt):
        address = model.jnt_qposadr[j]
        index = pin_model.joints[pin_model.getJointId(model.joint(j).name)].idx_q
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            q[index : index + 3] = qpos[address : address + 3]
            q[index + 3 : index + 6] = qpos[address + 4 : address + 7]
            q[index + 6] = qpos[address + 3]
        else:
            q[index] = qpos[address]
    return q


def top_of_robot(model: mujoco.MjModel, data: mujoco.MjData) -> float:
    """Height of the highest point of any geom, bounded above by its bounding sphere (the head's is exact)."""
    return max(float(data.geom_xpos[g][2] + model.geom_rbound[g]) for g in range(model.ngeom))


def at_rest(scene: mujoco.MjModel) -> mujoco.MjData:
    data = mujoco.MjData(scene)
    mujoco.mj_resetDataKeyframe(scene, data, scene.key("home").id)
    mujoco.mj_forward(scene, data)
    return data


# --- the model ---------------------------------------------------------------------------------------------------


def test_a_free_pelvis_carries_twelve_torque_controlled_leg_joints(model, config):
    free = model.joint(config.base.root_joint)
    assert free.type[0] == mujoco.mjtJoint.mjJNT_FREE and free.qposadr[0] == 0
    assert model.body(int(free.bodyid[0])).name == "pelvis"
    assert len(config.legs.joints) == 12 and len(set(config.legs.joints)) == 12
    for leg in (config.legs.left, config.legs.right):
        axes = [tuple(model.joint(j).axis) for j in leg.joints]
        assert axes == [(0, 0, 1), (1, 0, 0), (0, 1, 0), (0, 1, 0), (0, 1, 0), (1, 0, 0)]  # yaw, roll, pitch, …
        assert model.site(leg.sole).bodyid[0] == model.body(leg.foot).id
    assert not config.base.actuators, "nothing drives the pelvis but the legs"


def test_same_total_mass_in_mujoco_and_pinocchio_with_a_free_flyer(model, pin_model):
    assert pin.computeTotalMass(pin_model) == pytest.approx(float(np.sum(model.body_mass)), rel=1e-6)
    assert pin_model.joints[1].shortname() == "JointModelFreeFlyer"
    assert (pin_model.nq, pin_model.nv) == (model.nq, model.nv)


def test_mass_and_height_of_a_mid_size_humanoid(model, stance, config):
    mass = float(np.sum(model.body_mass))
    assert 40.0 <= mass <= 70.0
    data = mujoco.MjData(model)
    data.qpos[:] = stance.qpos
    mujoco.mj_kinematics(model, data)
    head = model.geom("head").id
    head_top = float(data.geom_xpos[head][2] + model.geom_size[head][0])
    assert 1.3 <= head_top <= top_of_robot(model, data) <= 1.6  # standing in the neutral stance
    mujoco.mj_resetData(model, data)  # straight legs, soles on the floor (legs.xml's pelvis height)
    mujoco.mj_kinematics(model, data)
    assert all(abs(data.site(leg.sole).xpos[2]) < 1e-9 for leg in (config.legs.left, config.legs.right))
    assert top_of_robot(model, data) <= 1.6


def test_every_leg_joint_has_a_motor_at_its_documented_torque_limit(model, config):
    for joint in config.legs.joints:
        role = config.legs.role(joint)
        jid = model.joint(joint).id
        assert model.jnt_limited[jid] and model.jnt_range[jid][0] < 0 < model.jnt_range[jid][1], joint
        driven = [a for a in range(model.nu) if model.actuator_trnid[a, 0] == jid]
        assert len(driven) == 1, joint
        a = driven[0]
        assert model.actuator_gaintype[a] == mujoco.mjtGain.mjGAIN_FIXED and model.actuator_gainprm[a][0] == 1
        assert model.actuator_biastype[a] == mujoco.mjtBias.mjBIAS_NONE, f"{joint}: a motor, not a servo"
        assert model.actuator_ctrllimited[a]
        limit = config.legs.torque_limit(joint)
        assert limit == G1_TORQUE[role]
        np.testing.assert_array_equal(model.actuator_ctrlrange[a], [-limit, limit])
        np.testing.assert_array_equal(model.jnt_actfrcrange[jid], [-limit, limit])
        assert config.legs.speed_limit(joint) == G1_SPEED[role]
        dof = model.joint(joint).dofadr[0]
        assert 0.005 < model.dof_armature[dof] < 0.03, "a geared motor's reflected rotor inertia"
        assert 0 < model.dof_damping[dof] <= 1.0, "gearbox losses, not a stabiliser"
    assert set(config.legs.torque_limits) == set(LEG_ROLES)
    knee = model.joint(config.legs.left.joints[3])
    assert knee.range[0] <= 0 < 2.0 < knee.range[1], "a knee bends forwards only, and far"


def test_the_upper_body_is_the_wheeled_robots_own(model):
    """Reused as it is: same joints, ranges, servo gains, force limits and masses. Only body gravity
    compensation is off (on a floating base it would hold the robot up: assembly._no_body_gravcomp)."""
    wheeled = robot_spec(load_robot_config("wheeled_humanoid")).compile()
    upper = [wheeled.joint(j).name for j in range(wheeled.njnt) if not wheeled.joint(j).name.startswith("base_")]
    for name in upper:
        a, b = wheeled.joint(name), model.joint(name)
        np.testing.assert_array_equal(a.range, b.range)
        assert (a.damping[0], a.armature[0]) == (b.damping[0], b.armature[0])
        np.testing.assert_array_equal(wheeled.body(a.bodyid[0]).mass, model.body(b.bodyid[0]).mass)
    for a in range(wheeled.nu):
        name = wheeled.actuator(a).name
        if name.startswith("base_"):
            continue
        for field in ("gainprm", "biasprm", "forcerange", "ctrlrange"):
            np.testing.assert_array_equal(getattr(wheeled.actuator(a), field), getattr(model.actuator(name), field))
    assert wheeled.ngravcomp > 0 and model.ngravcomp == 0


def test_sensors_are_where_robot_yaml_says(model, config):
    def sensor(name: str) -> tuple[int, int]:
        s = model.sensor(name)
        return int(s.type[0]), int(s.objid[0])

    imu = model.site(config.imu.site).id
    assert model.site(config.imu.site).bodyid[0] == model.joint(config.base.root_joint).bodyid[0]
    assert sensor(config.imu.gyro) == (mujoco.mjtSensor.mjSENS_GYRO, imu)
    assert sensor(config.imu.accelerometer) == (mujoco.mjtSensor.mjSENS_ACCELEROMETER, imu)
    assert sensor(config.imu.orientation)[0] == mujoco.mjtSensor.mjSENS_FRAMEQUAT
    for leg in (config.legs.left, config.legs.right):
        foot = model.body(leg.foot).id
        for name, kind in (
            (leg.force_sensor, mujoco.mjtSensor.mjSENS_FORCE),
            (leg.torque_sensor, mujoco.mjtSensor.mjSENS_TORQUE),
            (leg.touch_sensor, mujoco.mjtSensor.mjSENS_TOUCH),
        ):
            found, site = sensor(name)
            assert found == kind and model.site_bodyid[site] == foot, name


def test_robot_yaml_names_exist_in_the_mjcf(model, config):
    joints = {model.joint(i).name for i in range(model.njnt)}
    for names in config.groups.values():
        assert set(names) <= joints
    for targets in config.postures.values():
        assert set(targets) <= joints
    for kind, name in config.frames.values():
        {"site": model.site, "camera": model.camera, "body": model.body}[kind](name)
    for leg in (config.legs.left, config.legs.right):
        model.body(leg.foot), model.site(leg.sole)


# --- standing ----------------------------------------------------------------------------------------------------


def test_the_stance_stands_flat_with_the_centre_of_mass_over_the_feet(model, config, stance):
    data = mujoco.MjData(model)
    data.qpos[:] = stance.qpos
    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)
    sole = config.legs.sole
    for leg, side in ((config.legs.left, 1), (config.legs.right, -1)):
        site = data.site(leg.sole)
        assert abs(site.xpos[2]) < 2e-3
        np.testing.assert_allclose(site.xmat.reshape(3, 3), np.eye(3), atol=1e-6)  # flat, facing +x
        np.testing.assert_allclose(site.xpos[:2], [0, side * stance.width / 2], atol=1e-6)
        _, _, hip_pitch, knee, ankle_pitch, _ = leg.joints
        assert 0.3 < stance.joints[knee] < 1.2, "slightly bent knees"
        assert stance.joints[hip_pitch] < 0 and stance.joints[ankle_pitch] < 0
    for joint in config.legs.joints:
        low, high = model.joint(joint).range
        assert low <= stance.joints[joint] <= high
    # the support polygon: both soles side by side, flat, their rectangles' hull
    com = data.subtree_com[model.joint(config.base.root_joint).bodyid[0]]
    np.testing.assert_allclose(com, stance.com, atol=1e-12)
    assert abs(com[0]) < sole.length / 2 - 0.05
    assert abs(com[1]) < stance.width / 2 + sole.width / 2 - 0.05
    np.testing.assert_allclose(com[:2], 0, atol=1e-9)  # at its middle
    assert data.xpos[model.body("pelvis").id][2] == pytest.approx(config.legs.stance.pelvis_height)


def test_the_stance_is_computed_for_other_heights_and_refused_out_of_reach(config):
    low = standing_posture(config, pelvis_height=0.45)
    high = standing_posture(config, pelvis_height=0.54)
    assert low.joints["l_knee"] > high.joints["l_knee"] > 0
    with pytest.raises(ValueError, match=r"cannot stand|outside its range"):
        standing_posture(config, pelvis_height=0.6)  # the legs are 0.55 m long
    with pytest.raises(ValueError, match="no legs"):
        standing_posture(load_robot_config("wheeled_humanoid"))


def test_the_stance_holds_in_pinocchio_too(model, pin_model, stance, config):
    data = pin_model.createData()
    q = pin_configuration(model, pin_model, stance.qpos)
    pin.framesForwardKinematics(pin_model, data, q)
    for leg in (config.legs.left, config.legs.right):
        placement = data.oMf[pin_model.getFrameId(leg.sole)]
        assert abs(placement.translation[2]) < 1e-9
        np.testing.assert_allclose(placement.rotation, np.eye(3), atol=1e-9)
    np.testing.assert_allclose(pin.centerOfMass(pin_model, data, q), stance.com, atol=1e-9)


def test_kinematics_agree_in_mujoco_and_pinocchio_for_random_poses(model, pin_model, config):
    mj_data, pin_data = mujoco.MjData(model), pin_model.createData()
    rng = np.random.default_rng(5)
    frames = [config.legs.left.sole, config.legs.right.sole, "l_grip", "r_grip", config.imu.site]
    for _ in range(5):
        qpos = model.qpos0.copy()
        qpos[:3] = rng.uniform(-1, 1, 3)
        quat = rng.normal(size=4)
        qpos[3:7] = quat / np.linalg.norm(quat)
        for j in range(1, model.njnt):
            low, high = model.jnt_range[j] if model.jnt_limited[j] else (-1.0, 1.0)
            qpos[model.jnt_qposadr[j]] = rng.uniform(low, high)
        mj_data.qpos[:] = qpos
        mujoco.mj_kinematics(model, mj_data)
        mujoco.mj_comPos(model, mj_data)
        q = pin_configuration(model, pin_model, qpos)
        pin.framesForwardKinematics(pin_model, pin_data, q)
        for site in frames:
            placement = pin_data.oMf[pin_model.getFrameId(site)]
            np.testing.assert_allclose(placement.translation, mj_data.site(site).xpos, atol=1e-9)
            np.testing.assert_allclose(placement.rotation, mj_data.site(site).xmat.reshape(3, 3), atol=1e-9)
        np.testing.assert_allclose(pin.centerOfMass(pin_model, pin_data, q), mj_data.subtree_com[1], atol=1e-9)


def test_the_scene_keyframe_stands_on_the_soles_and_the_sensors_read_rest(scene, config):
    data = at_rest(scene)
    floor = scene.geom("floor").id
    fromto = np.zeros(6)
    for g in range(scene.ngeom):
        if g == floor or not scene.geom_contype[g] | scene.geom_conaffinity[g]:
            continue
        gap = mujoco.mj_geomDistance(scene, data, floor, g, 0.1, fromto)
        if "_sole_" in scene.geom(g).name:
            assert abs(gap) < 1e-6, scene.geom(g).name  # on the floor, not in it
        else:
            assert gap > 3e-3, scene.geom(g).name  # only the soles touch it
    np.testing.assert_allclose(data.sensor(config.imu.gyro).data, 0, atol=1e-12)
    np.testing.assert_allclose(data.sensor(config.imu.orientation).data, [1, 0, 0, 0], atol=1e-6)
    np.testing.assert_array_equal(data.ctrl[[scene.actuator(j).id for j in config.legs.joints]], 0)


def test_the_robot_stands_in_a_world_at_its_start_pose(config):
    """Assembled into a world as the wheeled robot is; the simulation starts it standing at the start pose."""
    sim = Simulation(load_world_config("kitchen"), config, SceneConfig(robot_start=(1.0, -2.0, 45.0)))
    yaw = math.radians(45.0)
    soles = [sim.data.site(leg.sole) for leg in (config.legs.left, config.legs.right)]
    np.testing.assert_allclose((soles[0].xpos + soles[1].xpos) / 2, [1.0, -2.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(soles[0].xmat.reshape(3, 3)[:2, 0], [math.cos(yaw), math.sin(yaw)], atol=1e-6)
    assert sim.model.body_rootid[sim.model.body("l_foot").id] == sim.model.body("pelvis").id
    assert sim.model.body("l_foot").id in sim.robot_bodies and sim.model.body("head").id in sim.robot_bodies


# --- robot.yaml --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("kind: floating", "kind: planar"), "a planar base names joints for x, y and yaw"),
        (("joints: {free: floating_base}", "joints: {x: a, y: b, yaw: c}"), "a floating base names one free joint"),
        (("    joints: [l_hip_yaw, l_hip_roll, ", "    joints: ["), "a leg has 6 joints"),
        (("hip_yaw: 88, ", ""), "torque_limits: one value for each of"),
        (("  waist: [waist_yaw]", "  waist: [waist_yaw, l_knee]"), "leg joints are torque-controlled"),
    ],
)
def test_robot_yaml_mistakes_are_named_at_file_line(tmp_path, change, message):
    text = (robots_dir() / ROBOT / "robot.yaml").read_text()
    old, new = change
    assert old in text
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / "robot.yaml").write_text(text.replace(old, new, 1))
    with pytest.raises(UserError, match=message) as error:
        read_config("robot", tmp_path, "bad", "robot.yaml", RobotConfig)
    assert error.value.where is not None and error.value.where.split(":")[-1].isdigit()


# --- physics -----------------------------------------------------------------------------------------------------


@pytest.mark.sim
def test_with_the_motors_off_the_robot_falls(scene):
    """Joint damping and armature are a real gearbox's: they do not hold the robot up, its controller must."""
    data = at_rest(scene)
    standing = float(data.qpos[2])
    mujoco.mj_step(scene, data, 750)  # 1.5 s, every motor at zero torque
    assert data.qpos[2] < standing - 0.2


@pytest.mark.sim
def test_held_by_a_joint_pd_it_stands_and_its_sensors_read_its_weight(scene, config):
    """A stiff PD on the leg motors (torques within their limits) holds the stance; then the IMU reads +g and
    the feet carry the weight. Not a balance controller: standing still on flat feet needs none."""
    data = at_rest(scene)
    legs = config.legs.joints
    motors = [scene.actuator(j).id for j in legs]
    positions = [scene.joint(j).qposadr[0] for j in legs]
    velocities = [scene.joint(j).dofadr[0] for j in legs]
    target = data.qpos[positions].copy()
    for _ in range(1500):  # 3 s
        data.ctrl[motors] = 1000.0 * (target - data.qpos[positions]) - 30.0 * data.qvel[velocities]
        mujoco.mj_step(scene, data)
    weight = float(np.sum(scene.body_mass)) * GRAVITY
    feet = sum(float(scene.body(leg.foot).mass[0]) for leg in (config.legs.left, config.legs.right)) * GRAVITY
    np.testing.assert_allclose(data.sensor(config.imu.accelerometer).data, [0, 0, GRAVITY], atol=0.1)
    np.testing.assert_allclose(data.sensor(config.imu.gyro).data, 0, atol=0.01)
    sides = (config.legs.left, config.legs.right)
    assert sum(data.sensor(leg.touch_sensor).data[0] for leg in sides) == pytest.approx(weight, rel=0.01)
    # the ankles press down on the feet with the weight of everything above them
    pressed = -sum(data.sensor(leg.force_sensor).data[2] for leg in sides)
    assert pressed == pytest.approx(weight - feet, rel=0.01)
    for leg in sides:
        site = data.site(leg.sole)
        assert abs(site.xpos[2]) < 2e-3 and site.xmat[8] > math.cos(math.radians(1.0))  # flat on the floor
    com = data.subtree_com[scene.body("pelvis").id]
    assert abs(com[0]) < config.legs.sole.length / 2 and abs(com[1]) < config.legs.stance.width / 2
