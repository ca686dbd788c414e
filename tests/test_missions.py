"""Scenario tests: one per mission in missions/, judged in the simulator's ground truth."""

import math

import pytest

from bt_humanoid.paths import project_root

MISSIONS = project_root() / "missions"


def test_every_mission_has_a_scenario_test():
    tested = {"demo.yaml", "visit_kitchen.yaml", "language_tour.yaml"}
    tested |= {"pick_and_place.yaml", "pick_and_place_bottle.yaml", "pick_and_place_mug.yaml"}  # test_manipulation.py
    tested |= {"tour.yaml"}  # test_navigation.py
    tested |= {"recovery.yaml"}  # test_recovery.py
    assert {p.name for p in MISSIONS.glob("*.yaml")} == tested


@pytest.mark.sim
def test_demo_drives_around_the_box_to_the_table(run_mission):
    scenario = run_mission(MISSIONS / "demo.yaml")
    assert scenario.result.success, scenario.result.summary()
    x, y, yaw = scenario.truth.robot_pose()
    assert math.hypot(x - 2.4, y) < 0.05 and abs(yaw) < math.radians(3)
    assert scenario.truth.robot_contacts() == []
    # it went around the storage box: the first waypoint was reached on its south side
    first = scenario.statuses("sequence[1].sequence[0].move_base")
    assert first == ["RUNNING", "SUCCESS"]
    assert scenario.statuses("sequence[5].gripper") == ["RUNNING", "SUCCESS"]
    assert scenario.result.said == ["Heading to the table.", "Ready at the table."]
    assert scenario.final_speed() < 0.01


@pytest.mark.sim
def test_visit_kitchen_calls_behaviours_and_returns(run_mission):
    scenario = run_mission(MISSIONS / "visit_kitchen.yaml")
    assert scenario.result.success, scenario.result.summary()
    assert "I am at the kitchen." in scenario.result.said
    assert "I am at the living_room." in scenario.result.said
    assert scenario.truth.robot_contacts() == []


@pytest.mark.sim
def test_language_tour_takes_every_branch_it_should(run_mission):
    scenario = run_mission(MISSIONS / "language_tour.yaml")
    assert scenario.result.success, scenario.result.summary()
    said = scenario.result.said
    assert said == ["The door is closed, I will open it.", "All done."]
    # the 5 s wait was halted by its 1 s timeout
    wait_events = [e for e in scenario.events if e["event"] == "status" and e["node"].endswith("timeout.wait")]
    assert [e["new"] for e in wait_events] == ["RUNNING", "INVALID"]
    assert wait_events[1]["t"] == pytest.approx(wait_events[0]["t"] + 1.0, abs=0.06)
    assert scenario.run.context.blackboard.get("door_open") is True
