"""Handing things to a person who takes them: their arm reaches, their fingers close, the robot feels the pull."""

import math
from pathlib import Path

import numpy as np
import pytest

from bt_humanoid.evaluation.episode import run_episode, watch_people
from bt_humanoid.language.embedded import EmbeddedPlanner
from bt_humanoid.sim.people import FOREARM, SHOULDER_HEIGHT, SHOULDER_OUT, UPPER_ARM, arm_angles
from bt_humanoid.sim.robot_config import load_robot_config
from bt_humanoid.sim.scene_config import load_scene
from bt_humanoid.sim.world_config import load_world_config
from bt_humanoid.skills.arm_skills import taking_force
from bt_humanoid.testing.scenario import Scenario, build_run
from bt_humanoid.testing.told import told_planning_context

NEAR_THE_PERSON = (0.32, -2.4, 180.0)  # the kitchen's person stands at (-0.6, -2.4): arm's length from the robot


@pytest.mark.parametrize("reach, height", [(0.3, 0.9), (0.45, 1.0), (0.6, 1.2), (0.25, 0.8)])
def test_the_person_s_arm_puts_the_wrist_where_asked_with_the_hand_level(reach: float, height: float):
    shoulder, elbow, wrist = arm_angles(reach, height)
    # positive angles turn down: each link points (cos a, -sin a) in (forward, up)
    forward = SHOULDER_OUT + UPPER_ARM * math.cos(shoulder) + FOREARM * math.cos(shoulder + elbow)
    up = SHOULDER_HEIGHT - UPPER_ARM * math.sin(shoulder) - FOREARM * math.sin(shoulder + elbow)
    assert (forward, up) == pytest.approx((reach, height), abs=1e-9)
    assert shoulder + elbow + wrist == pytest.approx(0.0)
    assert elbow < 0  # the elbow below the line from shoulder to wrist, as people hold their arms


def _hand_over(
    takes: bool = True, timeout: float = 20.0, tree: dict | None = None, robot: str = "wheeled_humanoid"
) -> Scenario:
    mission = {
        "mission": "hand it over",
        "world": "kitchen",
        "robot": robot,
        "scene": "holding_coke",
        "tree": tree or {"give": {"to": "person", "timeout": timeout}},
        "success": [{"delivered": "coke"}],
    }
    run = build_run(mission, robot_start=NEAR_THE_PERSON)
    run.sim.people["person"].takes = takes
    touched = watch_people(run, run.stack)  # the robot on the person, anywhere but hand on hand, as bt-eval counts
    person_state: list[tuple[str | None, str]] = []  # (the robot's hand on the coke, what the person is doing)
    run.executor.observers.append(
        lambda: person_state.append((run.truth.in_hand("coke"), run.sim.people["person"].state))
    )
    scenario = Scenario(run, run.execute())
    scenario.touched = touched  # type: ignore[attr-defined]
    scenario.person_state = person_state  # type: ignore[attr-defined]
    return scenario


@pytest.mark.sim
def test_the_person_takes_the_coke_and_the_robot_lets_go_when_it_feels_the_pull():
    scenario = _hand_over()
    assert scenario.result.summary()["outcome"] == "success", scenario.result.summary()
    assert scenario.truth.held_by_person("coke") == "person"
    assert scenario.truth.in_hand("coke") is None
    assert scenario.truth.object_position("coke")[2] > 0.8, "in their hand, not on the floor"
    states = scenario.person_state  # type: ignore[attr-defined]
    let_go = next(i for i, (hand, _) in enumerate(states) if hand is None)
    assert states[let_go][1] in ("closing", "pulling"), "let go once their fingers were on it, not before"
    assert not scenario.touched  # type: ignore[attr-defined]
    assert "Please take the coke." not in scenario.run.stack.said, "taken before it had to ask"


@pytest.mark.sim
def test_the_biped_feels_the_person_take_the_coke_though_its_arm_yields_to_the_pull():
    # the biped's arm follows its balance QP and gives way to the person's pull: the wrist feels 2 N, not the
    # wheeled robot's 4 N, and with the wheeled robot's threshold it held on until its timeout (robot.yaml)
    scenario = _hand_over(robot="biped_humanoid", timeout=8.0)
    assert scenario.result.summary()["outcome"] == "success", scenario.result.summary()
    assert scenario.truth.held_by_person("coke") == "person"
    states = scenario.person_state  # type: ignore[attr-defined]
    let_go = next(i for i, (hand, _) in enumerate(states) if hand is None)
    assert states[let_go][1] in ("closing", "pulling"), "let go once their fingers were on it, not before"
    assert not scenario.touched  # type: ignore[attr-defined]


@pytest.mark.sim
def test_a_busy_person_is_asked_and_the_robot_keeps_what_they_do_not_take():
    scenario = _hand_over(takes=False, timeout=4.0)
    assert scenario.result.summary()["outcome"] == "failure"
    assert "person did not take the coke in 4 s; still holding it" in scenario.result.summary()["cause"]
    assert "Please take the coke." in scenario.run.stack.said
    assert scenario.truth.in_hand("coke") == "right"
    assert scenario.truth.held_by_person("coke") is None


@pytest.mark.sim
def test_what_a_busy_person_does_not_take_is_put_down_on_the_surface_nearest_them():
    # the hand-over "bring me the coke" plans: with a free spot on the surface nearest the person
    context = told_planning_context("kitchen", load_scene(load_world_config("kitchen"), "holding_coke"))
    plan = EmbeddedPlanner().plan("bring me the coke", context)
    hand_over = plan.mission["tree"]["sequence"][-1]["hand_over"]
    assert hand_over["surface"] == "table"
    scenario = _hand_over(takes=False, tree={"hand_over": {**hand_over, "timeout": 4.0}})
    said = scenario.run.stack.said
    assert "Please take the coke." in said
    assert "You did not take it, so I put it on the table." in said
    assert scenario.truth.in_hand("coke") is None and scenario.truth.held_by_person("coke") is None
    assert scenario.truth.rests_on("coke", "table"), "put down, not dropped"
    assert scenario.truth.upright("coke")
    assert scenario.result.summary()["outcome"] == "failure", scenario.result.summary()  # the person has not got it
    assert not scenario.touched  # type: ignore[attr-defined]


@pytest.mark.slow
@pytest.mark.sim
def test_the_loosened_fingers_do_not_drag_a_pulled_cube_out_of_the_person_s_hand():
    # the fetch suite's episode 9: the person's pull pressed the cube against one pad; loosened by 3 cm, that pad
    # kept touching it, and the hand rising clear dragged it up out of their fingers onto the floor
    fetch = str(Path(__file__).resolve().parents[1] / "missions" / "benchmarks" / "fetch.yaml")
    record = run_episode(fetch, 9)
    assert record["command"] == "bring me the red cube"
    assert record["success"], record["failure"]
    assert record["person_contacts"] == 0 and not record["object_on_floor"]


@pytest.mark.slow
@pytest.mark.sim
@pytest.mark.parametrize(
    "seed, episode",
    [
        # the handle stood 45° off the person's fingers: one finger landed on its flank, not on the mug, and the
        # fingers closing pushed the mug 4 N back at the robot, which let go then (a push, not a take)
        (0, 43),
        # the person drew the mug 6 cm towards themselves against the loosened near pad; the hand rising clear
        # dragged along it and flicked the mug out of their fingers
        (1, 44),
    ],
)
def test_the_person_takes_a_mug_held_out_with_its_handle_to_their_side(seed: int, episode: int):
    fetch = str(Path(__file__).resolve().parents[1] / "missions" / "benchmarks" / "fetch.yaml")
    record = run_episode(fetch, episode, seed=seed)
    assert record["command"] == "bring me the coffee mug"
    assert record["success"], record["failure"]
    assert record["person_contacts"] == 0 and not record["object_on_floor"]


def test_only_a_pull_towards_the_person_and_the_weight_they_take_count_as_taking():
    """The rule ``give`` lets go by, on made-up wrist forces (world frame): the person stands 1 m along +x."""
    hand, person = np.array([0.0, 0.0]), np.array([1.0, 0.0])
    towards = np.array([1.0, 0.0, 0.0])
    assert taking_force(-6.0 * towards, hand, person) == pytest.approx(6.0)  # the wrist holds it back: a pull
    assert taking_force(6.0 * towards, hand, person) == 0.0  # fingers closing round it push it at the robot
    assert taking_force(np.array([0.0, 6.0, 0.0]), hand, person) == 0.0  # sideways: someone brushing past
    assert taking_force(np.array([0.0, 0.0, -4.0]), hand, person) == pytest.approx(4.0)  # they hold it up
    assert taking_force(np.array([0.0, 0.0, 4.0]), hand, person) == 0.0  # pressed down on: not taken
    assert taking_force(np.array([-3.0, 0.0, -4.0]), hand, person) == pytest.approx(5.0)  # both at once
    assert taking_force(-6.0 * towards, hand, np.array([-1.0, 0.0])) == 0.0  # the same force, them behind
    for robot in ("wheeled_humanoid", "biped_humanoid"):
        assert load_robot_config(robot).grippers["right"].taking_pull < 5.0, "a 5 N pull and lift lets go"
