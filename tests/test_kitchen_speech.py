"""The kitchen by voice and typed: names the recogniser can hear, and things thrown into the bin that takes them."""

import pytest

from bt_humanoid.errors import UserError
from bt_humanoid.language.asr import CommandRecognizer, command_grammar
from bt_humanoid.language.audio import spoken
from bt_humanoid.language.embedded import EmbeddedPlanner
from bt_humanoid.sim.world_config import load_world_config
from bt_humanoid.testing.grammar import not_understood
from bt_humanoid.testing.told import told_planning_context


@pytest.fixture(scope="module")
def kitchen():
    return told_planning_context("kitchen")


def test_the_kitchen_grammar_says_every_object_by_a_name_it_can_hear():
    grammar = command_grammar(load_world_config("kitchen"))
    names = next(line for line in grammar.splitlines() if line.startswith("<name> ="))
    for heard in ("seven up", "coca cola", "jalapeno chips", "red bull", "whole grain chips"):
        assert f" {heard} " in names or f" {heard};" in names
    for typed_only in ("7up", "coca-cola", "jalapeño", "rxbar", "redbull"):
        assert typed_only not in names


def test_an_object_with_no_name_the_recogniser_knows_is_named_in_the_error():
    world = load_world_config("kitchen")
    objects = dict(world.objects)
    objects["rxbar"] = objects.pop("energy bar").model_copy(update={"aliases": ["rx-bar"]})
    with pytest.raises(UserError, match=r"cannot hear any name of the object 'rxbar'") as error:
        command_grammar(world.model_copy(update={"objects": objects}))
    assert "worlds/kitchen/world.yaml" in str(error.value) and "alias" in str(error.value)


def test_a_spoken_kitchen_command_is_heard():
    recognizer = CommandRecognizer(load_world_config("kitchen"))
    for said in ("hey robot, bring me the seven up", "hey robot, pick up the coca cola"):
        heard = recognizer.transcribe(spoken(said))
        assert heard.woken and heard.command == said.removeprefix("hey robot, "), heard.text


@pytest.mark.parametrize(
    ("command", "steps", "said"),
    [
        ("throw away the coke", [{"throw_away": {"object": "coke", "into": "recycling_bin"}}], "recycling bin"),
        ("throw the sponge away", [{"throw_away": {"object": "sponge", "into": "trash_can"}}], "trash can"),
        ("compost the apple", [{"throw_away": {"object": "apple", "into": "compost_bin"}}], "compost bin"),
        ("put the apple in the trash", [{"throw_away": {"object": "apple", "into": "trash_can"}}], "trash can"),
        (
            "pick up the pepsi and recycle it",
            [
                {"take": {"object": "pepsi"}},
                {"navigate": {"place": "recycling_bin"}},
                {"drop": {"into": "recycling_bin"}},
            ],
            "recycling bin",
        ),
    ],
)
def test_throw_away_recycle_and_compost_go_to_the_bin_that_takes_it(kitchen, command, steps, said):
    plan = EmbeddedPlanner().plan(command, kitchen)
    assert plan.kind == "mission", plan.say
    tree = plan.mission["tree"]
    assert tree.get("sequence", [tree]) == steps
    assert said in plan.say


def test_recycling_what_is_not_recyclable_says_where_it_goes(kitchen):
    plan = EmbeddedPlanner().plan("recycle the apple", kitchen)
    assert plan.kind == "refusal" and "not recyclable" in plan.say and "compost bin" in plan.say


def test_a_spoken_throw_away_is_heard_and_planned(kitchen):
    recognizer = CommandRecognizer(kitchen.world)
    heard = recognizer.transcribe(spoken("hey robot, throw away the seven up"))
    assert heard.command == "throw away the seven up", heard.text
    assert EmbeddedPlanner().plan(heard.command, kitchen).kind == "mission"


def test_every_kitchen_command_the_grammar_hears_is_one_the_planner_understands(kitchen, tmp_path):
    assert not_understood(kitchen, tmp_path) == {}
