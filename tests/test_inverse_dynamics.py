"""The whole-body inverse-dynamics QP (docs/walking.md, "Whole-body inverse dynamics"): Pinocchio's model is the one
MuJoCo simulates, the contact wrench cone is exactly what forces at a sole's corners can do, a solution obeys the
equations of motion, the cones and the limits, and the servos deliver the torques it asks of them. In physics: the
biped stands on the QP alone and takes a 30 N·s push on the pelvis with its ankles and hips."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from bt_humanoid.control.walking.balance import BalanceController
from bt_humanoid.control.wbc.contact import SoleContact, cone_matrix
from bt_humanoid.control.wbc.dynamics import BASE_DOFS, RobotDynamics
from bt_humanoid.control.wbc.id_limits import HeldJointLimit, JointLimit, TorqueLimit
from bt_humanoid.control.wbc.id_solver import solve_id
from bt_humanoid.control.wbc.id_tasks import ComTask, JointPostureTask, OrientationTask
from bt_humanoid.sim.assembly import robot_spec
from bt_humanoid.sim.ground_truth import GroundTruth
from bt_humanoid.sim.robot_config import RobotConfig, load_robot_config
from bt_humanoid.sim.scene_config import SceneConfig
from bt_humanoid.sim.simulation import Simulation
from bt_humanoid.sim.standing import Stance, standing_posture
from bt_humanoid.sim.world_config import load_world_config

ROBOT = "biped_humanoid"
OPEN_FLOOR = (6.5, -0.5, 30.0)  # the apartment's kitchen end: 2 m from anything, so a fall meets only the floor
DT = 0.002


@pytest.fixture(scope="module")
def config() -> RobotConfig:
    return load_robot_config(ROBOT)


@pytest.fixture(scope="module")
def stance(config) -> Stance:
    return standing_posture(config)


@pytest.fixture(scope="module")
def mj_model(config) -> mujoco.MjModel:
    return robot_spec(config).compile()


@pytest.fixture()
def dynamics(config) -> RobotDynamics:
    return RobotDynamics(config)


def open_floor_sim(config: RobotConfig) -> Simulation:
    return Simulation(load_world_config("apartment"), config, SceneConfig(robot_start=OPEN_FLOOR))


def pin_state(dynamics: RobotDynamics, mj_model: mujoco.MjModel, qpos: np.ndarray, qvel: np.ndarray):
    """MuJoCo's state of the robot alone as Pinocchio's (q, v): joints by name, the free joint's conventions."""
    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, qpos[3:7])
    rotation = rotation.reshape(3, 3)
    positions = np.array([qpos[mj_model.joint(j).qposadr[0]] for j in dynamics.joints])
    velocities = np.array([qvel[mj_model.joint(j).dofadr[0]] for j in dynamics.joints])
    # MuJoCo's free joint: linear velocity in the world frame, angular in the body's
    return dynamics.state(qpos[:3], rotation, qvel[:3], rotation @ qvel[3:6], positions, velocities)


def standing_problem(config: RobotConfig, stance: Stance, dynamics: RobotDynamics):
    """The QP's pieces as the balance controller builds them, the targets where the robot is."""
    legs = config.legs
    sole = legs.sole
    contacts = [SoleContact(leg.sole, sole.length, sole.width, sole.friction) for leg in (legs.left, legs.right)]
    held = ["torso_lift", *config.finger_joints]
    servoed = [j for j in dynamics.joints if j not in legs.joints and j not in held]
    model = robot_spec(config).compile()
    limits = {j: legs.torque_limit(j) for j in legs.joints}
    limits |= {j: float(model.actuator_forcerange[model.actuator(j).id][1]) for j in servoed}
    controlled = legs.joints + servoed
    ranges = np.array([model.jnt_range[model.joint(j).id] for j in controlled])
    speeds = np.array([legs.speed_limit(j) if j in legs.joints else 3.0 for j in controlled])
    com = ComTask(100.0, kp=50.0, kd=15.0)
    com.set_target(dynamics.com.copy())
    pelvis = OrientationTask("pelvis", 10.0)
    pelvis.target = dynamics.pose("pelvis").rotation.copy()
    tasks = [
        com,
        pelvis,
        JointPostureTask({j: stance.joints[j] for j in servoed}, 10.0),
        JointPostureTask({j: stance.joints[j] for j in legs.joints}, 0.1, 10.0, 6.0),
    ]
    bounds = [JointLimit(controlled, ranges[:, 0], ranges[:, 1], speeds), HeldJointLimit(held)]
    return contacts, tasks, bounds, TorqueLimit(limits)


# --- the model ---------------------------------------------------------------------------------------------------


def test_pinocchio_dynamics_are_the_ones_mujoco_simulates(config, stance, mj_model, dynamics):
    """M and h (Coriolis, gravity, joint damping) agree at a tilted, moving state, once the free joint's velocity
    conventions are accounted for: MuJoCo's v = T v_pin with T = diag(R, 1, …), so M_pin = Tᵀ M T and
    h_pin = Tᵀ (h + M Ṫ v_pin), Ṫ v_pin = (R (ω × v), 0)."""
    rng = np.random.default_rng(3)
    data = mujoco.MjData(mj_model)
    data.qpos[:] = stance.qpos
    axis = rng.normal(size=3)
    mujoco.mju_axisAngle2Quat(data.qpos[3:7], axis / np.linalg.norm(axis), 0.4)
    data.qvel[:] = rng.normal(scale=0.5, size=mj_model.nv)
    mujoco.mj_forward(mj_model, data)
    full = np.zeros((mj_model.nv, mj_model.nv))
    mujoco.mj_fullM(mj_model, data, full)
    bias = data.qfrc_bias - data.qfrc_passive  # passive here is the joints' damping alone

    q, v = pin_state(dynamics, mj_model, data.qpos, data.qvel)
    dynamics.update(q, v)
    order = list(range(BASE_DOFS)) + [mj_model.joint(j).dofadr[0] for j in dynamics.joints]
    full, bias = full[np.ix_(order, order)], bias[order]
    rotation = dynamics.pose("pelvis").rotation
    T = np.eye(dynamics.nv)
    T[:3, :3] = rotation
    T_dot_v = np.zeros(dynamics.nv)
    T_dot_v[:3] = rotation @ np.cross(v[3:6], v[:3])
    np.testing.assert_allclose(dynamics.mass_matrix, T.T @ full @ T, atol=1e-9)
    np.testing.assert_allclose(dynamics.bias, T.T @ (bias + full @ T_dot_v), atol=1e-8)


def test_the_contact_wrench_cone_is_what_corner_forces_can_do():
    """Caron et al.'s closed form: every wrench that forces inside friction pyramids at the four corners add up to
    satisfies U w ≥ 0, and each of the sixteen faces is reached by some such wrench (none is loose)."""
    X, Y, mu = 0.11, 0.05, 0.7
    cone = cone_matrix(X, Y, mu)
    rng = np.random.default_rng(0)
    corners = [np.array([sx * X, sy * Y, 0.0]) for sx in (1, -1) for sy in (1, -1)]
    slack = np.full(len(cone), np.inf)
    for _ in range(4000):
        wrench = np.zeros(6)
        for corner in corners:
            fz = rng.uniform(0, 1) * (rng.uniform() < 0.8)
            tangent = rng.choice([-mu, mu], size=2) if rng.uniform() < 0.5 else rng.uniform(-mu, mu, 2)
            force = np.array([*(tangent * fz), fz])
            wrench += np.concatenate([force, np.cross(corner, force)])
        values = cone @ wrench / max(wrench[2], 1e-9)
        assert values.min() >= -1e-9
        slack = np.minimum(slack, values)
    assert slack.max() < 0.05, "each face is touched by some corner forces"
    # a centre of pressure past the edge, or more shear than friction allows, is outside
    assert (cone @ np.array([0, 0, 100, 0, -100 * (X + 0.01), 0])).min() < 0
    assert (cone @ np.array([0, 100 * (mu + 0.01), 100, 0, 0, 0])).min() < 0


# --- the QP ------------------------------------------------------------------------------------------------------


def test_standing_still_the_torques_are_rnea_with_the_contact_wrenches(config, stance, mj_model, dynamics):
    q, v = pin_state(dynamics, mj_model, stance.qpos, np.zeros(mj_model.nv))
    dynamics.update(q, v)
    contacts, tasks, bounds, torque_limit = standing_problem(config, stance, dynamics)
    solution = solve_id(dynamics, contacts, tasks, bounds, torque_limit, DT)
    assert solution.solved
    assert np.max(np.abs(solution.accelerations)) < 1e-3  # at rest on target: it stays
    generalised = pin.rnea(dynamics.model, dynamics.data, q, v, solution.accelerations).copy()
    for contact, wrench in zip(contacts, solution.wrenches, strict=True):
        generalised -= contact.wrench_jacobian(dynamics).T @ wrench
    np.testing.assert_allclose(generalised[:BASE_DOFS], 0, atol=1e-6)  # nothing pushes the pelvis but the floor
    np.testing.assert_allclose(generalised[BASE_DOFS:], solution.torques, atol=1e-6)
    com_acceleration = dynamics.com_jacobian @ solution.accelerations + dynamics.com_drift
    weight = dynamics.mass * (dynamics.gravity + com_acceleration[2])
    assert solution.wrenches[:, 2].sum() == pytest.approx(weight, rel=1e-6)
    assert solution.wrenches[:, 2].sum() == pytest.approx(dynamics.mass * dynamics.gravity, rel=1e-3)
    assert solution.wrenches[0, 2] == pytest.approx(solution.wrenches[1, 2], rel=0.05)  # shared


def test_every_solution_keeps_the_physics_the_cones_and_the_limits(config, stance, mj_model, dynamics):
    """Disturbed states (joint and pelvis velocities, centre-of-mass targets off by up to 8 cm): each solution obeys
    the floating base's equations, keeps the soles still, their wrenches in the cones and every torque in its
    limit."""
    rng = np.random.default_rng(7)
    for _ in range(20):
        qvel = rng.normal(scale=0.3, size=mj_model.nv)
        q, v = pin_state(dynamics, mj_model, stance.qpos, qvel)
        dynamics.update(q, v)
        contacts, tasks, bounds, torque_limit = standing_problem(config, stance, dynamics)
        tasks[0].set_target(dynamics.com + np.concatenate([rng.uniform(-0.08, 0.08, 2), [0.0]]))
        solution = solve_id(dynamics, contacts, tasks, bounds, torque_limit, DT)
        assert solution.solved
        accelerations = solution.accelerations
        base = dynamics.mass_matrix[:BASE_DOFS] @ accelerations + dynamics.bias[:BASE_DOFS]
        for contact, wrench in zip(contacts, solution.wrenches, strict=True):
            base -= contact.wrench_jacobian(dynamics)[:, :BASE_DOFS].T @ wrench
            assert (contact.cone @ wrench).min() > -1e-6
            assert wrench[2] >= contact.min_normal_force - 1e-6
            jacobian, rhs = contact.acceleration_constraint(dynamics)
            np.testing.assert_allclose(jacobian @ accelerations, rhs, atol=1e-6)
        np.testing.assert_allclose(base, 0, atol=1e-6)
        columns = torque_limit.columns(dynamics) - BASE_DOFS
        assert np.all(np.abs(solution.torques[columns]) <= torque_limit.maximum + 1e-6)


def test_a_swinging_foot_carries_nothing_and_an_impossible_problem_says_so(config, stance, mj_model, dynamics):
    q, v = pin_state(dynamics, mj_model, stance.qpos, np.zeros(mj_model.nv))
    dynamics.update(q, v)
    contacts, tasks, bounds, torque_limit = standing_problem(config, stance, dynamics)
    contacts[1].active = False
    solution = solve_id(dynamics, contacts, tasks, bounds, torque_limit, DT)
    assert solution.solved
    np.testing.assert_allclose(solution.wrenches[1], 0, atol=1e-9)
    assert solution.wrenches[0, 2] > 0.9 * dynamics.mass * dynamics.gravity
    contacts[1].active = True
    contacts[0].min_normal_force = 10 * dynamics.mass * dynamics.gravity  # more than the robot can press down
    solution = solve_id(dynamics, contacts, tasks, bounds, torque_limit, DT)
    assert not solution.solved
    np.testing.assert_array_equal(solution.torques, 0)


# --- the controller ----------------------------------------------------------------------------------------------


def test_the_controller_writes_actuator_commands_only_and_the_servos_deliver_the_qp_torques(config):
    """One control step (no physics step): motors get the QP's torques; each upper-body servo's force, kp (r − q) −
    kv q̇ at its new target r, is the QP's torque for its joint; nothing but ``ctrl`` changes."""
    sim = open_floor_sim(config)
    controller = BalanceController(sim)
    data = sim.data
    before = {name: getattr(data, name).copy() for name in ("qpos", "qvel", "qfrc_applied", "xfrc_applied")}
    controller.step()
    for name, value in before.items():
        np.testing.assert_array_equal(getattr(data, name), value, err_msg=name)
    solution = controller.solution
    assert solution is not None and solution.solved
    torques = dict(zip(controller.dynamics.joints, solution.torques, strict=True))
    mujoco.mj_forward(sim.model, data)
    for joint in controller.legs:
        assert data.ctrl[sim.actuator_for_joint(joint)] == pytest.approx(torques[joint])
    for joint in controller.servoed:
        force = data.actuator_force[sim.actuator_for_joint(joint)]
        assert force == pytest.approx(torques[joint], rel=0.01, abs=1e-6), joint
    assert any(abs(torques[j]) > 1.0 for j in controller.servoed), "the servos carry the arms' weight"


def test_the_controller_reads_sensors_not_the_free_joint(config):
    """The same sensor readings with a nonsense pelvis state behind them give the same commands: nothing reads the
    simulator's free joint. (The state is overwritten after the sensors were computed, with no physics step: an
    information-flow check, not a run.)"""
    commands = []
    for garbage in (False, True):
        sim = open_floor_sim(config)
        if garbage:
            free = sim.model.joint(config.base.root_joint)
            sim.data.qpos[free.qposadr[0] : free.qposadr[0] + 7] = [9.0, -9.0, 3.0, 0.5, 0.5, 0.5, 0.5]
            sim.data.qvel[free.dofadr[0] : free.dofadr[0] + 6] = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
        controller = BalanceController(sim)
        controller.step()
        controller.step()
        commands.append(sim.data.ctrl.copy())
    np.testing.assert_array_equal(commands[0], commands[1])


# --- in physics --------------------------------------------------------------------------------------------------


def touching_anything_but_the_soles(sim: Simulation) -> list[tuple[str, str]]:
    return [(mine, other) for mine, other in GroundTruth(sim).robot_contacts() if "_sole_" not in mine]


@pytest.mark.sim
def test_it_stands_on_the_qp_alone_for_ten_seconds(config):
    sim = open_floor_sim(config)
    truth = GroundTruth(sim)
    controller = BalanceController(sim)
    start = truth.floating_base()[0]
    for _ in range(round(10.0 / sim.timestep)):
        controller.step()
        sim.step()
        assert not touching_anything_but_the_soles(sim)
    position, rotation, velocity, _ = truth.floating_base()
    assert np.linalg.norm(position - start) < 0.01  # pelvis drift
    assert np.linalg.norm(velocity) < 1e-3 and rotation[2, 2] > math.cos(math.radians(1.0))
    assert controller.failures == 0
    # nothing but the actuators holds it: no applied forces, no constraints on its bodies
    assert not sim.data.xfrc_applied.any() and not sim.data.qfrc_applied.any()
    robot = sim.robot_bodies
    for e in range(sim.model.neq):
        assert not {sim.model.eq_obj1id[e], sim.model.eq_obj2id[e]} & robot


PUSH = 150.0  # N, for 0.2 s on the pelvis: 30 N·s, the push
PUSH_TIME = 0.2


def push_and_settle(config: RobotConfig, direction_deg: float, force: float = PUSH, settle: float = 3.0):
    """Stand 1 s, push the pelvis ``force`` N for 0.2 s towards ``direction_deg`` of the robot's heading (a fault
    injected through xfrc_applied, in this test only), let it settle; returns the sim, controller and whether it
    stayed up on its soles throughout."""
    sim = open_floor_sim(config)
    controller = BalanceController(sim)
    pelvis = sim.model.body("pelvis").id
    angle = math.radians(OPEN_FLOOR[2] + direction_deg)
    push = force * np.array([math.cos(angle), math.sin(angle), 0.0])
    upright = True
    for _ in range(round((1.0 + PUSH_TIME + settle) / sim.timestep)):
        controller.step()
        sim.data.xfrc_applied[pelvis, :3] = push if 1.0 <= sim.time < 1.0 + PUSH_TIME else 0.0
        sim.step()
        upright &= not touching_anything_but_the_soles(sim)
    return sim, controller, upright


@pytest.mark.sim
@pytest.mark.parametrize("direction", [0.0, 90.0, 180.0, 270.0], ids=["forward", "left", "backward", "right"])
def test_a_30_newton_second_push_is_taken_by_the_ankles_and_hips(config, direction):
    soles = [config.legs.left.sole, config.legs.right.sole]
    sim = open_floor_sim(config)
    feet = [sim.data.site(s).xpos.copy() for s in soles]
    sim, controller, upright = push_and_settle(config, direction)
    assert upright, "it fell"
    assert controller.failures == 0
    for site, before in zip(soles, feet, strict=True):  # no step, no slip
        assert np.linalg.norm(sim.data.site(site).xpos[:2] - before[:2]) < 0.01
    middle = (feet[0] + feet[1]) / 2
    assert np.linalg.norm(controller.dcm() - middle[:2]) < 0.02  # balanced again over the middle of the feet


def test_a_payload_at_the_grip_point_adds_its_mass_where_the_hand_holds_it(dynamics, stance):
    q = np.concatenate(
        [[0.0, 0.0, stance.pelvis_height, 0.0, 0.0, 0.0, 1.0], [stance.joints[j] for j in dynamics.joints]]
    )
    v = np.zeros(dynamics.nv)
    dynamics.update(q, v)
    bare_mass, bare_com, bare_gravity = dynamics.mass, dynamics.com.copy(), dynamics.bias.copy()
    grip = dynamics.pose("r_grip").translation.copy()
    dynamics.set_payload("r_grip", 0.5)
    dynamics.update(q, v)
    assert dynamics.mass == pytest.approx(bare_mass + 0.5)
    assert RobotDynamics(load_robot_config(ROBOT)).mass == pytest.approx(bare_mass)  # its own model, not shared
    assert dynamics.com == pytest.approx((bare_mass * bare_com + 0.5 * grip) / (bare_mass + 0.5))
    # held still, the joints carry its weight at the grip point: h grows by J_gripᵀ (0, 0, m g)
    weight = dynamics.jacobian("r_grip")[:3].T @ np.array([0.0, 0.0, 0.5 * dynamics.gravity])
    assert dynamics.bias - bare_gravity == pytest.approx(weight, abs=1e-9)
    dynamics.set_payload("r_grip", 0.0)  # let go
    dynamics.update(q, v)
    assert dynamics.mass == pytest.approx(bare_mass) and dynamics.com == pytest.approx(bare_com)
