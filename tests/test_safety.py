"""Safety guards: a stop request, joint limits and the time budget halt the tree and the robot comes to rest."""

from py_trees.common import Status

from bt_humanoid.testing.scenario import build_run

DRIVE = {
    "mission": "drive",
    "tree": {"sequence": [{"move_base": {"x": 0.6, "y": -0.9, "yaw": 0}}, {"say": {"text": "there"}}]},
}


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
