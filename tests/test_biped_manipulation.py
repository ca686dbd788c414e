"""The walking biped does the job on its legs (issue 25, docs/walking.md "Working on legs"): it picks an object
up and weighs it, leaves a table it worked at, stands still holding it when stopped mid-walk, puts things down by
feel and steps nearer when its hand falls short, balancing all the while. Judged in ground truth."""

from __future__ import annotations

import math

import numpy as np
import pytest
from py_trees.common import Status

from bt_humanoid.benchmarks.manipulation import Trial, prepare_trial
from bt_humanoid.control.grasping import PAD_HALF_HEIGHT
from bt_humanoid.control.stance import working_stance
from bt_humanoid.control.wbc.dynamics import RobotDynamics
from bt_humanoid.sim.sensor_models import IDEAL_SENSORS_VARIABLE
from bt_humanoid.skills.manipulation_skills import STEP_IN, Grasp, StandNear
from bt_humanoid.testing.scenario import build_run
from bt_humanoid.testing.scene import place_object
from bt_humanoid.testing.told import tell_object_poses

pytestmark = pytest.mark.sim

OBJECTS = {"red_cube", "blue_cube", "water_bottle", "coffee_mug", "yellow_ball"}  # the apartment's, by geom


def run_watching_contacts(mission: dict, start: tuple[float, float, float] | None = None):
    """Run ``mission`` on the biped from ``start`` (the world's start if None): the result, the run, and every
    contact of the robot with something other than the floor under its soles or what its fingers may touch."""
    run = build_run({"world": "apartment", "robot": "biped_humanoid", **mission}, robot_start=start)
    touched: set[tuple[str, str]] = set()

    def watch() -> None:
        for mine, other in run.truth.robot_contacts():
            on_feet = "_sole_" in mine and other == "floor"
            # the finger pads may touch what they grasp, and brush the top it stands on: the arm's servos follow
            # the balance QP's torques and the hand comes down 6 mm below its target (the wheeled robot's do not)
            fingers = "_pad_" in mine and (other.endswith("_top") or any(other.startswith(n) for n in OBJECTS))
            if not (on_feet or fingers):
                touched.add((mine, other))

    run.executor.observers.append(watch)
    result = run.execute()
    run.stack.close()
    return result, run, touched


def test_the_biped_picks_the_red_cube_from_the_table():
    result, run, touched = run_watching_contacts({"mission": "pick on legs", "tree": {"pick": {"object": "red cube"}}})
    assert result.success, result.cause
    assert run.truth.in_hand("red cube") == "right"
    assert run.truth.object_position("red cube")[2] > 0.85  # lifted clear of the table (its top: 0.75 m)
    assert run.robot.walking.walker.fallen is None
    assert not touched
    # the wrist weighed it (0.1 kg), and the balance counts it at the grip point
    mass = float(run.sim.model.body("red_cube").mass[0])
    believed = run.stack.context.world_model.held("right")
    assert believed is not None and believed.weight == pytest.approx(mass, abs=0.02)
    dynamics = run.robot.walking.walker.dynamics
    assert dynamics.payloads["r_grip"] == believed.weight
    assert dynamics.mass == pytest.approx(RobotDynamics(run.robot.config).mass + believed.weight)


def test_from_a_working_stance_inside_its_footprint_it_steps_back_then_walks_away():
    """The biped works 0.25 m from a table's edge, nearer than its 0.36 m footprint lets a route start: it steps
    straight back before it plans (at first the planner refused: "too close to an obstacle to plan from")."""
    result, run, touched = run_watching_contacts(
        {"mission": "leave the table", "tree": {"navigate": {"place": "kitchen"}}}, (2.55, 0.39, 0.0)
    )
    assert result.success, result.cause
    assert run.robot.walking.walker.fallen is None
    assert not touched


def test_a_stop_while_it_walks_off_with_the_cube_stands_it_still_within_two_steps_holding_it():
    run = build_run(
        {
            "world": "apartment",
            "robot": "biped_humanoid",
            "mission": "carry",
            "tree": {"sequence": [{"pick": {"object": "red cube"}}, {"navigate": {"place": "kitchen"}}]},
        }
    )
    executor, walker = run.executor, run.robot.walking.walker
    executor.events.add(0.0, "start", mission="carry")
    walking_since = None
    while walking_since is None or run.sim.time < walking_since + 2.0:  # 2 s into the walk with it
        assert run.sim.time < 120.0, "never walked off with the cube"
        executor.tick()
        executor.advance()
        carrying = run.truth.in_hand("red cube") == "right" and walker.walking
        walking_since = (walking_since or run.sim.time) if carrying else None
    steps = len(walker.touchdowns)
    run.request_stop("test stop")
    assert executor.tick() is Status.FAILURE
    executor.halt()
    run.stack.close()
    assert not walker.walking and walker.fallen is None
    assert len(walker.touchdowns) - steps <= 2
    assert run.truth.in_hand("red cube") == "right"  # the grip kept
    assert walker.dynamics.payloads["r_grip"] > 0.05  # and the balance still counts it


def _pick_and_place(trial: Trial):
    """Run the manipulation benchmark's ``trial`` on the biped, told where the object is: the result and the run."""
    run = prepare_trial(trial, "told", "biped_humanoid")
    result = run.execute()
    run.stack.close()
    return result, run


def _placed_within(run, name: str, spot: tuple[float, float], tolerance: float = 0.03) -> bool:
    x, y, _ = run.truth.object_position(name)
    return run.truth.in_hand(name) is None and run.truth.rests_on(name, "table") and math.dist((x, y), spot) < tolerance


def test_the_biped_weighs_the_bottle_before_lifting_it_and_feels_the_table_take_it_when_putting_it_down():
    """Lifted with a weight the balance did not know, the arm sagged 1.9 cm short of the lift (the reach failed);
    lowered, it lagged its reference by the 8 mm that meant contact to a stiff arm, and let go 7 cm up."""
    trial = Trial("bottle", "east", (3.838, -0.182), -1.192, (3.785, 0.013), (4.55, -0.422, 180.0))
    result, run = _pick_and_place(trial)
    assert result.success, result.cause
    failures = [e for e in result.events.events if e["event"] == "status" and e["new"] == "FAILURE"]
    assert not failures, failures[0].get("feedback")  # no retry was needed
    assert _placed_within(run, "water bottle", trial.place) and run.truth.upright("water bottle")
    assert run.robot.walking.walker.fallen is None


def test_a_spot_the_hand_stops_short_of_brings_the_biped_a_step_nearer_to_put_it_down():
    """0.26 m behind the table's west edge, the spot is a little beyond what the arm reaches low from the working
    stance: the hand stops 1.4 cm short on its way down, and the put is tried again from a stance stepped nearer."""
    trial = Trial("cube", "west", (2.961, 0.249), 0.945, (3.057, 0.093), (2.25, 0.489, 0.0))
    result, run = _pick_and_place(trial)
    assert result.success, result.cause
    short = [e for e in result.events.events if e["event"] == "status" and e["new"] == "FAILURE"]
    assert any("lower" in (e.get("feedback") or "") for e in short)  # the first put fell short
    base = run.context.robot_config.base
    table = run.context.world_model.surface("table")
    bounds, start = np.array(run.context.world.bounds), np.array(trial.start[:2])
    first, _, _ = working_stance(np.array(trial.place), table, "right", base, bounds, start)
    assert run.truth.robot_pose()[0] > first + 0.03  # it put the cube down from a stance at least 3 cm nearer
    assert _placed_within(run, "red cube", trial.place)
    assert run.robot.walking.walker.fallen is None


def test_walking_in_to_the_counter_the_raised_hand_passes_over_the_mug_it_will_take():
    """The hand raised over what the walk in passes, by as much as on the wheeled robot, bobbed with the steps and
    in a fetch episode knocked the mug over (the camera then took it for a white box, and the mug was lost): the
    pads passed 2 mm below its top here. Raised 3 cm more, they pass 3 cm over it."""
    run = build_run(
        {
            "world": "apartment",
            "robot": "biped_humanoid",
            "mission": "take the mug",
            "tree": {"pick": {"object": "coffee mug"}},
        },
        robot_start=(7.0, 2.4, 0.0),
    )
    place_object(run, "coffee mug", 8.45, 3.065, -0.5)
    tell_object_poses(run.context.world_model, run.sim)
    gaps: list[float] = []  # the pads' lowest point over the mug's top, while the robot walks in

    def watch() -> None:
        hand, mug = run.robot.hand_position("right"), run.truth.object_position("coffee mug")
        walking = run.robot.walking.walker.walking
        if walking and run.truth.in_hand("coffee mug") is None and math.dist(hand[:2], mug[:2]) < 0.15:
            gaps.append(hand[2] - PAD_HALF_HEIGHT - (mug[2] + 0.045))

    run.executor.observers.append(watch)
    result = run.execute()
    run.stack.close()
    assert gaps, "the hand never came over the mug on the way in"
    assert min(gaps) > 0.015, f"the pads passed {min(gaps) * 100:.1f} cm over the mug's top"  # 0.3 cm below, before
    assert result.success, result.cause
    assert run.truth.in_hand("coffee mug") == "right"


def test_a_mug_the_hand_stops_a_centimetre_short_of_is_closed_on_from_there(monkeypatch):
    """A mug 0.25 m in from the table's edge (fetch episode 18): the biped's arm stops its deep grip 1 cm short,
    towards the robot along the line the pads close on, and 4 mm high. Before, the grasp failed out of reach,
    twice, and again from a stance a step nearer; now it closes there, once: the nearer pad meets the mug first
    and pushes it to the other."""
    monkeypatch.setenv(IDEAL_SENSORS_VARIABLE, "1")
    trial = Trial("mug", "south", (3.44, -0.194), -2.967, (3.2, -0.3), (3.44, -0.75, 90.0))
    run = prepare_trial(trial, "told", "biped_humanoid")
    settled: list[float] = []  # how far from its plan each descent that stopped short closed
    settle_for = Grasp.settle_for

    def settle_and_note(skill: Grasp, motion) -> bool:
        planned = skill.grasp.position.copy()
        if not settle_for(skill, motion):
            return False
        settled.append(float(np.linalg.norm(skill.grasp.position - planned)))
        return True

    monkeypatch.setattr(Grasp, "settle_for", settle_and_note)
    grasps = []  # each grasp the pick starts

    def note_grasp(event: dict) -> None:
        if event["event"] == "status" and event.get("node", "").endswith("grasp") and event["new"] == "RUNNING":
            grasps.append(event)

    run.events.listeners.append(note_grasp)
    result = run.execute()
    run.stack.close()
    assert result.success, result.cause
    assert len(grasps) == 1  # no retry, no replan
    assert len(settled) == 1 and 0.005 < settled[0] < 0.02, settled  # it closed short of its plan, by about 1 cm
    assert _placed_within(run, "coffee mug", trial.place) and run.truth.upright("coffee mug")


def test_after_a_short_reach_the_next_stance_is_a_step_from_where_the_robot_stood_not_from_the_last_stance():
    """In a camera run the biped stopped 1.1 cm to one side of its stance and its hand fell short that way: a step
    of 4 cm measured from the stance lay 2.9 cm from the robot, too little for the walker to set off, and the
    retry failed the same. The next stance is now a step from where the robot stood; one asked for far from the
    stance (the object has moved since) is not followed."""
    spot = (2.961, 0.249)

    def stand_near(start: tuple[float, float, float]):
        run = build_run(
            {"world": "apartment", "robot": "biped_humanoid", "mission": "stance", "tree": {"wait": {"seconds": 1}}},
            robot_start=start,
        )
        place_object(run, "red cube", *spot, 0.0)
        tell_object_poses(run.context.world_model, run.sim)
        skill = StandNear("stand near", {}, run.context, "test")
        skill.params = StandNear.Params(object="red cube")
        return run, skill

    run, skill = stand_near((2.25, 0.489, 0.0))
    _, nominal = skill._stance()
    run.stack.close()
    aside = np.array([-math.sin(nominal[2]), math.cos(nominal[2])])  # the stance's left
    start = nominal[:2] + 0.011 * aside
    run, skill = stand_near((*start, math.degrees(nominal[2])))
    cube = run.context.world_model.object("red cube")
    hand = skill._hand_xyz("right")
    skill._note_short_reach(cube, hand + np.array([*(0.009 * aside), 0.0]))  # the hand stopped 9 mm short, left
    stood = run.robot.base.pose()[:2]
    assert cube.step_to == pytest.approx(stood + STEP_IN * aside, abs=1e-6)  # at least a step, from here
    _, stance = skill._stance()
    assert np.dot(stance[:2] - stood, aside) == pytest.approx(STEP_IN, abs=1e-3)  # not 2.9 cm: the walker steps
    cube.step_to = stood + 0.5 * aside  # asked for before the cube moved half a metre
    _, stance = skill._stance()
    assert stance == pytest.approx(nominal, abs=1e-6)
    run.stack.close()
