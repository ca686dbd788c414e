"""Safety guards: a stop request, joint limits, the time budget and the bumper halt the tree; the robot rests."""

import numpy as np
import pytest
from py_trees.common import Status

from bt_humanoid.sim.ground_truth import GroundTruth
from bt_humanoid.testing.scenario import build_run

DRIVE = {
    "mission": "drive",
    "tree": {"sequence": [{"move_base": {"x": 0.6, "y": -0.9, "yaw": 0}}, {"say": {"text": "there"}}]},
}


@pytest.mark.sim
def test_stop_request_mid_motion_halts_and_brakes():
    run = build_run(DRIVE)
    executor = run.executor
    executor.events.add(0.0, "start", mission="drive")
    while run.sim.time < 1.0:
        executor.tick()
        executor.advance()
    assert run.robot.max_speed() > 0.2  # driving
    run.request_stop("test stop")
    status = executor.tick()
    assert status is Status.FAILURE
    stop_time = run.sim.time
    executor.halt()
    assert run.robot.at_rest()
    assert run.sim.time - stop_time < 1.5  # braked within the base's limits
    safety = [e for e in run.events.events if e["event"] == "safety"]
    assert safety and safety[0]["monitor"] == "stop"
    assert "there" not in run.said
    halted = [e for e in run.events.events if e["event"] == "status" and e["new"] == "INVALID"]
    assert any(e["node"].endswith("move_base") for e in halted)


@pytest.mark.sim
@pytest.mark.parametrize("held", [True, False], ids=["feedforward", "without"])
def test_the_upper_body_is_held_still_while_the_base_brakes(held):
    """The base's deceleration deflects soft joints (head, shoulders); the inertial feedforward cancels it."""
    run = build_run(DRIVE)
    executor, robot = run.executor, run.robot
    if not held:
        robot.feedforward.update = lambda *_: np.zeros(len(robot.body_io.joints))
    while run.sim.time < 1.5:
        executor.tick()
        executor.advance()
    assert np.hypot(*robot.base.speeds()[:2]) > 0.5  # driving fast
    arms_and_head = np.array([j not in robot.config.finger_joints for j in robot.body_io.joints])
    deflection: list[float] = []
    executor.observers.append(
        lambda: deflection.append(
            float(np.max(np.abs(robot.body_io.positions() - robot.joints.position)[arms_and_head]))
        )
    )
    run.request_stop("test stop")
    executor.tick()
    stopped = run.sim.time
    executor.halt()
    assert robot.at_rest()
    if held:
        assert max(deflection) < 0.002  # rad
        assert run.sim.time - stopped < 0.35  # s, from full speed: 3.2 m/s² and no swinging back
    else:
        assert max(deflection) > 0.004


@pytest.mark.sim
def test_time_budget_ends_a_long_mission():
    run = build_run({"mission": "slow", "safety": {"time_budget": 1.0}, "tree": {"wait": {"seconds": 30}}})
    result = run.execute()
    assert result.tree_status == "FAILURE"
    assert result.safety.startswith("time_budget")
    assert result.sim_time < 2.0


def test_joint_limit_monitor_fires_past_the_margin():
    run = build_run({"mission": "limits", "tree": {"wait": {"seconds": 2}}})
    joint = "l_elbow"
    io = run.robot.body_io
    low = io.lower[io.index(joint)]
    # test set-up only: place the joint past its range before the run starts
    run.sim.set_initial_joint(joint, low - 0.1)
    result = run.execute()
    assert result.tree_status == "FAILURE"
    assert result.safety.startswith("joint_limits") and joint in result.safety


@pytest.mark.sim
def test_safety_failures_are_not_retried():
    mission = {
        "mission": "r",
        "recovery": {"retries": 3, "backoff": 0.0},
        "safety": {"time_budget": 0.5},
        "tree": {"wait": {"seconds": 2}},
    }
    result = build_run(mission).execute()
    waits = [e for e in result.events.events if e["event"] == "status" and e["node"] == "wait"]
    assert [e["new"] for e in waits] == ["RUNNING", "INVALID"]


@pytest.mark.sim
def test_driving_into_furniture_is_stopped_at_the_first_touch():
    """A relative move does not steer: straight ahead from the start is the storage box. The bumper stops it."""
    run = build_run({"mission": "blind", "tree": {"move_base": {"x": 3.0, "y": 0.0, "relative": True}}})
    truth = GroundTruth(run.sim)
    result = run.execute()
    assert result.tree_status == "FAILURE"
    assert result.safety.startswith("collision: the robot's base")
    x, _, _ = run.robot.base.pose()
    assert 0.5 < x < 1.5  # stopped at the box (about 1.1 m ahead), not driven through or past it
    assert run.robot.at_rest()
    contacts = [pair for pair in truth.robot_contacts() if not pair[0].startswith(("l_", "r_"))]
    assert len(contacts) <= 4  # resting against it, not pushing into it


@pytest.mark.sim
def test_the_arms_may_touch_what_they_work_on():
    from bt_humanoid.engine.runner import run_mission_file
    from bt_humanoid.paths import missions_dir

    result = run_mission_file(missions_dir() / "pick_and_place.yaml")
    assert result.success, result.cause or result.safety
    assert result.safety is None


def test_workspace_monitor_fires_off_the_map_and_for_a_hand_near_the_floor():
    import numpy as np

    from bt_humanoid.safety.monitors import WorkspaceMonitor

    run = build_run({"mission": "idle", "tree": {"wait": {"seconds": 0}}})
    bounds = np.array(run.context.world.bounds)
    assert WorkspaceMonitor(run.robot, bounds, 0.1).check(0.0) is None
    elsewhere = bounds + 5.0  # a map the robot's start is not on
    assert "left the map" in WorkspaceMonitor(run.robot, elsewhere, 0.1).check(0.0)
    message = WorkspaceMonitor(run.robot, bounds, 0.6).check(0.0)  # the hands hang about 0.48 m up
    assert message.startswith("the left hand is 48 cm above the floor")


@pytest.mark.sim
def test_a_relative_move_that_would_leave_the_map_is_refused_before_moving():
    run = build_run({"mission": "away", "tree": {"move_base": {"x": 30.0, "relative": True}}})
    start = np.array(run.truth.robot_pose())
    result = run.execute()
    assert result.tree_status == "FAILURE"
    assert "move_base: the goal (30.0, 0.0) is outside the map" in result.cause
    assert abs(np.array(run.truth.robot_pose()) - start).max() < 1e-3  # it never moved (its belief jitters by mm)
