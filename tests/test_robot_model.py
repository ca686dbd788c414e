"""The robot MJCF: loads in MuJoCo and Pinocchio alike, and robot.yaml matches it."""

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from bt_humanoid.sim.assembly import robot_spec, write_robot_mjcf
from bt_humanoid.sim.robot_config import load_robot_config


@pytest.fixture(scope="module")
def config():
    return load_robot_config("wheeled_humanoid")


@pytest.fixture(scope="module")
def models(config, tmp_path_factory):
    path = write_robot_mjcf(config, tmp_path_factory.mktemp("robot") / "robot.xml")
    return robot_spec(config).compile(), pin.buildModelFromMJCF(str(path))


def test_same_total_mass_in_mujoco_and_pinocchio(models):
    mj_model, pin_model = models
    assert pin.computeTotalMass(pin_model) == pytest.approx(float(np.sum(mj_model.body_mass)), rel=1e-9)
    assert pin.computeTotalMass(pin_model) > 60.0  # the upper body was not dropped


def test_hand_positions_agree_for_random_postures(models, config):
    mj_model, pin_model = models
    mj_data, pin_data = mujoco.MjData(mj_model), pin_model.createData()
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = np.zeros(mj_model.nq)
        for j in range(mj_model.njnt):
            low, high = mj_model.jnt_range[j] if mj_model.jnt_limited[j] else (-1.0, 1.0)
            q[mj_model.jnt_qposadr[j]] = rng.uniform(low, high)
        mj_data.qpos[:] = q
        mujoco.mj_kinematics(mj_model, mj_data)
        q_pin = np.zeros(pin_model.nq)
        for j in range(mj_model.njnt):
            name = mj_model.joint(j).name
            jid = pin_model.getJointId(name)
            if jid < pin_model.njoints:
                q_pin[pin_model.joints[jid].idx_q] = q[mj_model.jnt_qposadr[j]]
        # the three base joints are one composite joint in Pinocchio
        composite = pin_model.joints[1]
        q_pin[composite.idx_q : composite.idx_q + 3] = q[
            [mj_model.joint(n).qposadr[0] for n in ("base_x", "base_y", "base_yaw")]
        ]
        pin.framesForwardKinematics(pin_model, pin_data, q_pin)
        for site in ("l_grip", "r_grip"):
            np.testing.assert_allclose(
                pin_data.oMf[pin_model.getFrameId(site)].translation, mj_data.site(site).xpos, atol=1e-9
            )


def test_robot_yaml_names_exist_in_the_mjcf(models, config):
    mj_model, _ = models
    joints = {mj_model.joint(i).name for i in range(mj_model.njnt)}
    for group, names in config.groups.items():
        assert set(names) <= joints, group
    assert len(config.groups["left_arm"]) == 7 and len(config.groups["right_arm"]) == 7
    for posture, targets in config.postures.items():
        assert set(targets) <= joints, posture
    for _name, (kind, mjcf_name) in config.frames.items():
        lookup = {"site": mj_model.site, "camera": mj_model.camera, "body": mj_model.body}[kind]
        lookup(mjcf_name)  # raises KeyError when missing
    for camera in config.cameras:
        mj_model.camera(camera)
    for side in config.grippers.values():
        assert set(side.joints) <= joints


def test_base_moves_only_through_actuators(models):
    mj_model, _ = models
    for joint in ("base_x", "base_y", "base_yaw"):
        jid = mj_model.joint(joint).id
        driven = [i for i in range(mj_model.nu) if mj_model.actuator_trnid[i, 0] == jid]
        assert len(driven) == 1, joint
