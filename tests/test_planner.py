"""The embedded planner on the command set in tests/data/commands.yaml: plans, questions, refusals, stops."""

from pathlib import Path

import numpy as np
import pytest
import yaml

from bt_humanoid.commanding import plan_command
from bt_humanoid.errors import UserError
from bt_humanoid.language.embedded import EmbeddedPlanner, split_clauses
from bt_humanoid.language.plan import Plan, PlanningContext, mission_signature, plan_outcome
from bt_humanoid.language.words import normalise
from bt_humanoid.mission.loader import MissionLoader
from bt_humanoid.paths import behaviors_dir
from bt_humanoid.testing.told import told_planning_context

COMMANDS = yaml.safe_load((Path(__file__).parent / "data" / "commands.yaml").read_text())


@pytest.fixture(scope="module")
def context() -> PlanningContext:
    return told_planning_context("apartment")  # language, not detection: the objects are told


@pytest.fixture(scope="module")
def planner() -> EmbeddedPlanner:
    return EmbeddedPlanner()


def test_the_command_set_is_big_and_varied():
    assert len(COMMANDS) >= 60
    assert sum("asks" in c for c in COMMANDS) >= 5 and sum("refuses" in c for c in COMMANDS) >= 5


def test_planner_accuracy_on_the_command_set(planner, context):
    wrong = {}
    for command in COMMANDS:
        expected = {k: v for k, v in command.items() if k != "text"}
        got = plan_outcome(planner.plan(command["text"], context))
        if got != expected:
            wrong[command["text"]] = got
    accuracy = 1 - len(wrong) / len(COMMANDS)
    print(f"planner accuracy {accuracy:.1%} over {len(COMMANDS)} commands")  # the README's figure (-s)
    assert accuracy >= 0.95, wrong


@pytest.mark.parametrize("command", [c for c in COMMANDS if "asks" in c], ids=lambda c: c["text"])
def test_every_ambiguous_command_asks(planner, context, command):
    plan = planner.plan(command["text"], context)
    assert plan.kind == "question", plan.say
    assert plan.say.startswith("I see a ") and plan.say.endswith("Which would you like?")


@pytest.mark.parametrize("command", [c for c in COMMANDS if "refuses" in c], ids=lambda c: c["text"])
def test_every_impossible_command_is_refused_with_a_reason(planner, context, command):
    plan = planner.plan(command["text"], context)
    assert plan.kind == "refusal" and plan.mission is None
    assert len(plan.say) > 20 and plan.say.endswith("."), plan.say


@pytest.mark.parametrize("command", [c for c in COMMANDS if "plan" in c], ids=lambda c: c["text"])
def test_every_planned_mission_is_valid_in_the_mission_language(planner, context, command):
    plan = planner.plan(command["text"], context)
    assert plan.kind == "mission", plan.say
    MissionLoader().load_data(plan.mission)  # raises a UserError naming the step if not


def test_a_planned_mission_is_loaded_with_subtree_files_only_from_the_behaviour_folder(context, tmp_path):
    outside = tmp_path / "wave.yaml"
    outside.write_text((behaviors_dir() / "wave.yaml").read_text())  # a valid behaviour, outside behaviors/

    class Planner:  # any planner, e.g. one that was fooled; plan_command loads what it answers
        def __init__(self, file: str) -> None:
            self.file = file

        def plan(self, text, context):
            return Plan("mission", "Waving.", mission={"mission": text, "tree": {"subtree": {"file": self.file}}})

    with pytest.raises(UserError) as refused:
        plan_command("wave", context, lambda _: None, Planner(str(outside)))
    assert str(refused.value).startswith(f"<command> at tree.subtree.file: subtree file '{outside}' is outside")
    assert plan_command("wave", context, lambda _: None, Planner("wave.yaml")).spec is not None


def test_the_answer_to_a_question_continues_the_command(planner, context):
    question = planner.plan("bring me something to drink", context)
    assert question.say == "I see a water bottle and a coffee mug. Which would you like?"
    for reply, chosen in [
        ("the mug", "coffee mug"),
        ("the water bottle please", "water bottle"),
        ("the first one", "water bottle"),
    ]:
        plan = planner.answer(question.choice, reply, context)
        assert mission_signature(plan.mission["tree"])[0] == f"take {chosen}", reply


def test_an_answer_that_fits_no_option_asks_again(planner, context):
    question = planner.plan("pick up the cube", context)
    again = planner.answer(question.choice, "the banana", context)
    assert again.kind == "question" and again.say == "Sorry, which one: the red cube or the blue cube?"


def test_place_spots_are_free_and_distinct(planner, context):
    plan = planner.plan("put all the cubes on the shelf", context)
    spots = [np.array([s["fetch"]["x"], s["fetch"]["y"]]) for s in plan.mission["tree"]["sequence"]]
    shelf = context.belief.surface("shelf")
    assert all(shelf.contains(s, margin=0.1) for s in spots)
    assert np.linalg.norm(spots[0] - spots[1]) >= 0.12
    ball = context.belief.object("yellow ball").position[:2]
    assert all(np.linalg.norm(s - ball) >= 0.12 for s in spots)


def test_words_become_digits_and_the_wake_word_goes():
    assert normalise("Hey robot, walk forward two meters and turn left ninety degrees.") == (
        "walk forward 2 meters and turn left 90 degrees"
    )
    assert normalise("turn right one hundred and eighty degrees") == "turn right 180 degrees"
    assert normalise("go back half a meter") == "go back 0.5 meter"


def test_and_splits_clauses_only_before_a_verb():
    assert split_clauses("pick up the mug and bring it to me") == ["pick up the mug", "bring it to me"]
    assert split_clauses("put the red cube and the blue cube on the shelf") == [
        "put the red cube and the blue cube on the shelf"
    ]


def test_a_second_verb_starts_a_clause_even_without_and_as_speech_recognition_gives_it():
    assert split_clauses("pick up the red cube put it on the counter") == [
        "pick up the red cube",
        "put it on the counter",
    ]
    assert split_clauses("say pick up your toys") == ["say pick up your toys"]  # what is said stays whole
