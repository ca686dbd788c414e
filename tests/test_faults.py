"""Every injected fault kind ends in recovery or a safe stop (missions/benchmarks/faults.yaml, one episode each).

The episode is "bring me the red cube" from the world's start; episode i gets fault kind i (the suite takes
them in turn). Each test checks that the fault really happened, that the robot then did the job (judged in
ground truth) and ended at rest without touching anyone, and how it got there, from the event log.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from pydantic import ValidationError

from bt_humanoid.evaluation.episode import Draw, run_episode
from bt_humanoid.evaluation.faults import FaultConfig, pick
from bt_humanoid.evaluation.suite import load_suite

SUITE = str(Path(__file__).resolve().parents[1] / "missions" / "benchmarks" / "faults.yaml")
KINDS = [
    "slip",
    "target_moved",
    "obstacle_dropped",
    "push",
    "blind",
    "new_command",
    "arm_bump",
    "off_centre",
    "way_closed",
]
OFF_CENTRE_BOTTLE = str(Path(__file__).resolve().parent / "data" / "off_centre_bottle.yaml")
FETCH_FAULTS = str(Path(__file__).resolve().parents[1] / "missions" / "benchmarks" / "fetch_faults.yaml")
FETCH_SEVEN_KINDS = str(Path(__file__).resolve().parent / "data" / "fetch_seven_kinds.yaml")


def _episode(kind: str) -> tuple[dict, list[dict]]:
    events: list[dict] = []
    record = run_episode(SUITE, KINDS.index(kind), events=events)
    assert record["fault"] == kind
    assert record["fault_fired"], f"the {kind} fault never found its moment"
    assert record["person_contacts"] == 0 and not record["ended_moving"]
    return record, events


def _failures(events: list[dict]) -> list[str]:
    return [e.get("feedback", "") for e in events if e["event"] == "status" and e["new"] == "FAILURE"]


def _fault_time(events: list[dict]) -> float:
    return next(e["t"] for e in events if e["event"] == "fault")


@pytest.mark.slow
@pytest.mark.sim
def test_an_object_that_slips_out_of_the_fingers_is_grasped_again():
    record, events = _episode("slip")
    assert record["success"], record["failure"]
    dropped = [e for e in events if e["event"] == "monitor" and e["monitor"] == "dropped"]
    assert dropped and "fell out of the right hand" in dropped[0]["message"], "the dropped monitor noticed"
    assert any("slipped out" in message for message in _failures(events)), "the grasp, which checks for itself"


@pytest.mark.slow
@pytest.mark.sim
def test_an_object_moved_during_the_approach_is_found_where_it_now_is():
    record, events = _episode("target_moved")
    assert record["success"], record["failure"]
    status = [e for e in events if e["event"] == "status"]
    picked = [e["t"] for e in status if e["node"].endswith(".pick") and e["new"] == "SUCCESS"]
    assert picked and picked[-1] > _fault_time(events), "picked up after it was moved"


@pytest.mark.slow
@pytest.mark.sim
def test_a_parcel_dropped_on_the_way_is_seen_and_driven_round():
    record, _ = _episode("obstacle_dropped")
    assert record["success"], record["failure"]
    assert not record["collision"]


@pytest.mark.slow
@pytest.mark.sim
def test_a_shove_while_driving_is_recovered_from():
    record, _ = _episode("push")
    assert record["success"], record["failure"]
    assert not record["collision"]


@pytest.mark.slow
@pytest.mark.sim
def test_a_camera_that_goes_blind_for_seconds_is_ridden_out():
    record, _ = _episode("blind")
    assert record["success"], record["failure"]


@pytest.mark.slow
@pytest.mark.sim
def test_a_new_command_mid_mission_stops_the_robot_and_is_done_instead():
    record, events = _episode("new_command")
    assert record["success"], record["failure"]
    assert record["stop_latency_s"] is not None and record["stop_latency_s"] < 1.0
    said = [e["text"] for e in events if e["event"] == "say"]
    assert "I have stopped." in said
    missions = [e["mission"] for e in events if e["event"] == "start"]
    assert missions[-1].startswith("put the red cube on the table"), missions
    assert _fault_time(events) < max(e["t"] for e in events if e["event"] == "start")


@pytest.mark.slow
@pytest.mark.sim
def test_a_knock_on_the_carrying_arm_keeps_the_thing_in_hand():
    record, _ = _episode("arm_bump")
    assert "8 N·s" in record["fault_fired"] and "carrying the red cube" in record["fault_fired"]
    assert record["success"], record["failure"]
    assert not record["object_on_floor"] and not record["collision"]


@pytest.mark.slow
@pytest.mark.sim
@pytest.mark.parametrize("suite, obj", [(SUITE, "red cube"), (OFF_CENTRE_BOTTLE, "water bottle")])
def test_a_grasp_that_closes_off_the_object_s_centre_is_felt_let_go_and_taken_again(suite: str, obj: str):
    """Nudged 4 cm as the hand comes to it: the parallel fingers close on it where it is, 4 cm from where the
    robot believes it. The cube, nudged mostly along the way the fingers close, is pushed between them and
    brought. The bottle, nudged across the pads, is felt at their edge as the first pad touches it, before a
    squeeze pushes it over: the hand lets go, and the next grasp takes it by its middle."""
    events: list[dict] = []
    record = run_episode(suite, KINDS.index("off_centre") if suite == SUITE else 0, events=events)
    assert record["fault"] == "off_centre"
    assert record["fault_fired"] and f"the {obj} was nudged 4.0 cm" in record["fault_fired"]
    if obj == "water bottle":
        assert any("at their edge" in failure for failure in _failures(events)), _failures(events)
    assert record["success"], record["failure"]
    assert not record["object_on_floor"] and record["person_contacts"] == 0 and not record["ended_moving"]


@pytest.mark.slow
@pytest.mark.sim
def test_a_cube_closed_on_by_the_pads_edge_is_felt_and_taken_again_before_it_is_handed_over():
    """fetch_faults' episode 16: the cube nudged 3.6 cm across the pads, closed on by their edge. Held like
    that, the person's fingers met the robot's pads and the cube fell to the floor; now the pads feel it at
    their edge, the hand lets go, and the cube taken by its middle ends in the person's hand."""
    events: list[dict] = []
    record = run_episode(FETCH_FAULTS, 16, events=events)
    assert record["fault"] == "off_centre" and "nudged 3.6 cm" in record["fault_fired"]
    assert any("(felt by the pads): let go to grasp it afresh" in f for f in _failures(events)), _failures(events)
    assert record["success"], record["failure"]
    assert not record["object_on_floor"]


@pytest.mark.slow
@pytest.mark.sim
def test_a_box_that_closes_the_gap_on_the_way_is_driven_round_the_long_way():
    """The box lands between the storage box and the table, 1 m ahead: the way round is 1.5 m longer."""
    record, _ = _episode("way_closed")
    assert "a box closed the way" in record["fault_fired"]
    longer = float(record["fault_fired"].split("the way round is ")[1].split(" m")[0])
    assert longer >= 1.0
    assert record["success"], record["failure"]
    assert not record["collision"], "it did not squeeze past: there was no room"


def test_a_fault_s_strength_may_be_a_span_drawn_per_episode():
    config = FaultConfig.model_validate({"push": {"impulse": [40, 80]}})
    draws = [pick(config.settings.impulse, np.random.default_rng(seed)) for seed in range(50)]
    assert all(40 <= d <= 80 for d in draws) and max(draws) - min(draws) > 20
    assert pick(FaultConfig.model_validate({"blind": {"seconds": 7}}).settings.seconds, np.random.default_rng()) == 7
    for bad in ({"push": {"impulse": [80, 40]}}, {"push": {"impulse": 0}}, {"blind": {"seconds": [5, 90]}}):
        with pytest.raises(ValidationError, match="low before high"):
            FaultConfig.model_validate(bad)


@pytest.mark.parametrize("kind", KINDS)
def test_the_suite_takes_fault_kinds_in_turn(kind):
    suite, _ = load_suite(Path(SUITE))
    assert suite.faults.kinds[Draw(suite, KINDS.index(kind)).fault_index].kind == kind


@pytest.mark.slow
@pytest.mark.sim
def test_a_bottle_that_slips_but_stays_caught_in_the_pads_is_set_down_and_grasped_afresh():
    # the fetch suite's episode 147: the wet bottle slides down between the pads and is caught at another width;
    # carried like that it once went round the flat, held, while the robot searched the rooms for it
    fetch = FETCH_SEVEN_KINDS
    events: list[dict] = []
    record = run_episode(fetch, 147, events=events)
    assert record["fault"] == "slip" and record["fault_fired"]
    askew = [m for m in _failures(events) if "slipped in the right hand" in m]
    assert askew and "set it down to grasp it afresh" in askew[0], _failures(events)
    assert record["success"], record["failure"]
    assert record["person_contacts"] == 0 and not record["collision"]


@pytest.mark.slow
@pytest.mark.sim
def test_a_box_dropped_beside_the_base_out_of_the_camera_s_view_is_backed_away_from_and_driven_round():
    # the fetch suite's episode 39 at seed 1: the box landed where the head camera, looking along the route, never
    # saw it; the route passed it, a protective stop held the base 0.2 m from it for 10 s, and the search failed.
    # Now what the base scanner senses goes on the map after a second's hold, and the robot backs out and replans
    fetch = FETCH_SEVEN_KINDS
    events: list[dict] = []
    record = run_episode(fetch, 39, seed=1, events=events)
    assert record["fault"] == "obstacle_dropped" and record["fault_fired"]
    assert not any("protective stop" in m for m in _failures(events)), _failures(events)
    assert record["success"], record["failure"]
    assert record["person_contacts"] == 0 and not record["collision"]
