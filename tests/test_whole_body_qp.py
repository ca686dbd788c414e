"""The whole-body QP compiled in CasADi symbols against the same QP built from Pinocchio's numbers."""

import casadi as ca
import numpy as np
import pinocchio as pin
import pytest

from bt_humanoid.control.wbc.compiled import CompiledQp, QpCache, compile_qp
from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.limits import (
    BaseBoundsLimit,
    BaseKeepoutLimit,
    ClearanceLimit,
    JointPositionLimit,
    JointRangeLimit,
    TorsoMarginLimit,
    VelocityLimit,
)
from bt_humanoid.control.wbc.maths import log3
from bt_humanoid.control.wbc.solver import qp_terms, solve_ik
from bt_humanoid.control.wbc.symbolic_kinematics import SymbolicKinematics
from bt_humanoid.control.wbc.tasks import DampingTask, FrameTask, GazeTask, PostureTask
from bt_humanoid.sim.robot_config import load_robot_config

DT = 0.01


def _controlled(config) -> list[str]:
    return config.base.planar_joints + [j for group in config.groups.values() for j in group]


def _random_configuration(model: pin.Model, rng: np.random.Generator) -> np.ndarray:
    q = rng.uniform(-0.6, 0.6, model.nq)
    if model.joints[1].shortname() == "JointModelFreeFlyer":
        quaternion = rng.normal(size=4)
        q[3:7] = quaternion / np.linalg.norm(quaternion)
    return q


@pytest.mark.parametrize("robot", ["wheeled_humanoid", "biped_humanoid"])
def test_symbolic_frames_and_jacobians_match_pinocchio(robot):
    config = load_robot_config(robot)
    joints = _controlled(config)
    numeric, symbolic = RobotKinematics(config, joints), SymbolicKinematics(config, joints)
    frames = [config.frames["torso"][1], config.frames["head_camera"][1]]
    frames += [g.grip_site for g in config.grippers.values()]
    outputs = []
    for frame in frames:
        outputs += [symbolic.position(frame), ca.vec(symbolic.rotation(frame)), ca.vec(symbolic.jacobian(frame))]
    evaluate = ca.Function("frames", [symbolic.controlled, symbolic.configuration], [ca.vertcat(*outputs)])
    rng = np.random.default_rng(3)
    for _ in range(20):
        q, positions = _random_configuration(numeric.model, rng), rng.uniform(-1.0, 1.0, len(joints))
        numeric.q[:] = q
        numeric.update(positions)
        expected = np.concatenate(
            [
                np.concatenate([numeric.position(f), numeric.rotation(f).ravel("F"), numeric.jacobian(f).ravel("F")])
                for f in frames
            ]
        )
        assert np.allclose(np.array(evaluate(positions, q)).ravel(), expected, atol=1e-12)


def test_symbolic_log3_matches_pinocchio_up_to_nearly_a_half_turn():
    rotation = ca.SX.sym("R", 3, 3)
    evaluate = ca.Function("log3", [rotation], [log3(rotation)])
    rng = np.random.default_rng(0)
    for angle in [0.0, 1e-7, 1e-5, 1e-3, 0.1, 1.0, 2.0, 3.0, 3.13]:
        axis = rng.normal(size=3)
        vector = angle * axis / np.linalg.norm(axis)
        R = pin.exp3(vector)
        assert np.allclose(np.array(evaluate(R)).ravel(), pin.log3(R), atol=1e-6), angle


def _reach_goal(config, numeric, offset: float):
    """A reach with every kind of task and limit; ``offset`` moves every target and outline (the same signature)."""
    n = len(numeric.joints)
    numeric.update(np.zeros(n))
    grip = config.grippers["right"].grip_site
    target = numeric.pose(grip).copy()
    target.translation += offset
    tasks = [
        FrameTask(grip, target, gain=0.6),
        PostureTask({j: 0.1 + offset for j in config.groups["left_arm"]}, 1.0, 0.5),
        GazeTask(config.frames["head_camera"][1], np.array([1.0, 0.2, 0.8]) + offset),
        DampingTask(config.base.planar_joints, 1.0),
    ]
    box = [JointPositionLimit(np.full(n, -2.5), np.full(n, 2.5)), VelocityLimit(np.full(n, 1.0 + offset))]
    limits = [
        TorsoMarginLimit(config.frames["torso"][1], {g.grip_site: 0.2 for g in config.grippers.values()}),
        BaseKeepoutLimit("base", np.array([[0.5, -0.5], [1.5, 0.5]]) + offset, 0.4),
        BaseBoundsLimit("base", np.array([[-1.0, -1.0], [1.0, 1.0]]) + offset, 0.4),
        ClearanceLimit(grip, 0.8 + offset, np.array([[0.2, -0.5], [1.0, 0.5]]) + offset),
        JointRangeLimit({config.groups["right_arm"][-1]: (-0.5, 0.5)}),
    ]
    return tasks, box, limits


@pytest.fixture(scope="module")
def reach():
    """A reach with every kind of task and limit, on the wheeled robot."""
    config = load_robot_config("wheeled_humanoid")
    numeric = RobotKinematics(config, _controlled(config))
    tasks, box, limits = _reach_goal(config, numeric, 0.0)
    function, parameters = compile_qp(SymbolicKinematics(config, numeric.joints), tasks, box, limits, DT)
    compiled = CompiledQp(function)
    compiled.bind(parameters)
    return numeric, tasks[0], tasks, box, limits, compiled


def test_compiled_qp_equals_the_qp_built_from_numbers(reach):
    numeric, frame_task, tasks, box, limits, compiled = reach
    n = len(numeric.joints)
    rng = np.random.default_rng(1)
    solved = 0
    for _ in range(100):
        positions = rng.uniform(-1.0, 1.0, n)
        # the target moves every step: the compiled QP must read it afresh
        frame_task.target = pin.SE3(pin.exp3(rng.normal(size=3) * 0.5), rng.uniform(-0.5, 0.8, 3))
        numeric.update(positions)
        terms = qp_terms(numeric, tasks, box, limits, DT)
        expected = solve_ik(numeric, tasks, box, limits, DT)
        got = compiled.solve(positions, numeric.q)
        inputs = compiled.qp.inputs
        assert np.allclose(inputs["h"].reshape(n, n), terms.hessian, atol=1e-10)
        assert np.allclose(inputs["g"], terms.gradient, atol=1e-10)
        assert np.allclose(inputs["a"].reshape(n, -1).T, terms.constraints, atol=1e-10)
        for name, expected_bound in (("lba", terms.constraints_lower), ("lbx", terms.lower), ("ubx", terms.upper)):
            # ±inf where no bound holds, in the same places (allclose counts equal infinities as close)
            assert np.allclose(inputs[name], expected_bound, atol=1e-12), name
        assert got.solved == expected.solved
        assert np.allclose(got.step, expected.step, atol=1e-9)
        solved += got.solved
    assert solved > 50  # most of these random problems are feasible: the comparison is of real steps


def test_a_limit_row_holds_only_where_it_applies(reach):
    numeric, *_ = reach
    walls = BaseBoundsLimit("base", np.array([[-5.0, -5.0], [5.0, 5.0]]), 0.4)
    numeric.update(np.zeros(len(numeric.joints)))
    assert np.all(np.isneginf(walls.inequality(numeric, DT).lower))  # every wall is far: no bound
    near = BaseBoundsLimit("base", np.array([[-0.5, -5.0], [5.0, 5.0]]), 0.4)
    lower = near.inequality(numeric, DT).lower
    assert np.isfinite(lower[0]) and np.all(np.isneginf(lower[1:]))  # only the west wall, 0.5 m away


def test_an_infeasible_compiled_qp_is_reported_and_gives_no_step(reach):
    numeric, _, tasks, *_ = reach
    n = len(numeric.joints)
    # the hand far below the table's clearance height, over the table, with no speed to climb
    stuck = [JointPositionLimit(np.full(n, -2.5), np.full(n, 2.5)), VelocityLimit(np.zeros(n))]
    config = load_robot_config("wheeled_humanoid")
    grip = config.grippers["right"].grip_site
    numeric.update(np.zeros(n))
    x, y, z = numeric.position(grip)
    over = ClearanceLimit(grip, z + 0.5, np.array([[x - 0.1, y - 0.1], [x + 0.1, y + 0.1]]))
    function, parameters = compile_qp(SymbolicKinematics(config, numeric.joints), tasks, stuck, [over], DT)
    qp = CompiledQp(function)
    qp.bind(parameters)
    solution = qp.solve(np.zeros(n), numeric.q)
    assert not solution.solved
    assert np.array_equal(solution.step, np.zeros(n))


def test_a_goal_like_an_earlier_one_reuses_its_compiled_qp_with_its_own_numbers():
    config = load_robot_config("wheeled_humanoid")
    numeric = RobotKinematics(config, _controlled(config))
    symbolic = SymbolicKinematics(config, numeric.joints)
    dt = 0.0123  # a control period no other test compiles for: the process's compiled QPs start empty for it
    qps = QpCache(symbolic, numeric)
    first = qps.for_goal(*_reach_goal(config, numeric, 0.0), dt)
    tasks, box, limits = _reach_goal(config, numeric, 0.05)  # new targets, outlines and speeds
    second = qps.for_goal(tasks, box, limits, dt)
    assert second is first and len(qps.compile_times) == 1 and len(qps.bind_times) == 1
    # another controller in the process reuses the compiled function, with buffers of its own
    other = QpCache(symbolic, RobotKinematics(config, numeric.joints))
    third = other.for_goal(*_reach_goal(config, numeric, 0.1), dt)
    assert third is not second and not other.compile_times and len(other.bind_times) == 1
    rng = np.random.default_rng(2)
    for _ in range(20):
        positions = rng.uniform(-1.0, 1.0, len(numeric.joints))
        numeric.update(positions)
        expected = solve_ik(numeric, tasks, box, limits, dt)
        got = second.solve(positions, numeric.q)
        assert got.solved == expected.solved
        assert np.allclose(got.step, expected.step, atol=1e-9)
    # another kind of goal (no gaze) is compiled for itself
    qps.for_goal(tasks[:2], box, limits, dt)
    assert len(qps.compile_times) == 2
