"""The kitchen by voice: names the recogniser can hear are in the grammar, the others are typed only."""

import pytest

from bt_humanoid.errors import UserError
from bt_humanoid.language.asr import CommandRecognizer, command_grammar
from bt_humanoid.language.audio import spoken
from bt_humanoid.sim.world_config import load_world_config


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
