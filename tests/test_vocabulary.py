"""One command vocabulary: what can be typed and what can be said come from the same verbs and the world's names.

A new object or place written into a world's world.yaml (with its body in world.xml) is commandable by typing
and by voice with no other edit; every command the speech grammar can hear is one the planner understands.
"""

import shutil

import pytest

from bt_humanoid.language.asr import CommandRecognizer, command_grammar
from bt_humanoid.language.audio import spoken
from bt_humanoid.language.embedded import EmbeddedPlanner
from bt_humanoid.language.plan import mission_signature
from bt_humanoid.language.vocabulary import INTENTS, WorldVocabulary, planned_kinds
from bt_humanoid.language.whisper_asr import world_prompt
from bt_humanoid.mission.behaviors import BehaviorLibrary
from bt_humanoid.paths import project_root
from bt_humanoid.sim.world_config import load_world_config
from bt_humanoid.skills import REGISTRY
from bt_humanoid.testing.grammar import not_understood
from bt_humanoid.testing.told import told_planning_context

TEA_TIN = """
    <body name="tea_tin" pos="8.35 3.0 0.95">
      <freejoint name="tea_tin"/>
      <geom name="tea_tin" class="object" type="cylinder" size="0.035 0.05" mass="0.15" rgba="0.1 0.6 0.2 1"/>
    </body>
"""


@pytest.fixture(scope="module")
def home(tmp_path_factory):
    """A copy of the project whose apartment has one more object (a tea tin, "tea caddy" to some) and one more
    place (a hallway, "entrance" to some): written into world.yaml and world.xml, nothing else."""
    root = tmp_path_factory.mktemp("project")
    for folder in ("robots", "behaviors"):
        (root / folder).symlink_to(project_root() / folder)
    world = root / "worlds" / "apartment"
    shutil.copytree(project_root() / "worlds" / "apartment", world)
    config = (world / "world.yaml").read_text()
    config = config.replace(
        "\nobjects:",
        "\nobjects:\n  tea tin: {body: tea_tin, kind: can, colour: green, upright: true, aliases: [tea caddy]}",
    )
    config = config.replace(
        "\nplaces:", "\nplaces:\n  hallway: {pose: [4.5, -3.0, 0.0], kind: spot, aliases: [entrance]}"
    )
    (world / "world.yaml").write_text(config)
    scene = (world / "world.xml").read_text()
    (world / "world.xml").write_text(
        scene.replace('    <body name="yellow_ball"', TEA_TIN + '    <body name="yellow_ball"', 1)
    )
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("BT_HUMANOID_HOME", str(root))
        yield root


@pytest.fixture(scope="module")
def context(home):
    return told_planning_context("apartment")


@pytest.mark.parametrize(
    ("command", "steps"),
    [
        ("pick up the tea tin", ["take tea tin"]),
        ("put the tea tin on the table", ["fetch tea tin table"]),
        ("bring me the tea caddy", ["take tea tin", "navigate person", "give person"]),
        ("put the tea caddy on the dining table", ["fetch tea tin table"]),
        ("go to the hallway", ["navigate hallway"]),
        ("walk to the entrance and pick up the green can", ["navigate hallway", "take tea tin"]),
    ],
)
def test_a_new_object_and_place_are_planned_when_typed(context, command, steps):
    plan = EmbeddedPlanner().plan(command, context)
    assert plan.kind == "mission" and mission_signature(plan.mission["tree"]) == steps, plan.say


def test_a_new_object_and_place_are_in_the_speech_grammar_and_heard(context):
    grammar = command_grammar(context.world)
    for words in ("tea tin", "tea caddy", "hallway", "entrance"):
        assert words in grammar and words in world_prompt(context.world)  # Whisper is told them too
    recognizer = CommandRecognizer(context.world)
    for said in (
        "hey robot, pick up the tea tin",
        "hey robot, bring me the tea caddy",
        "hey robot, go to the entrance",
    ):
        heard = recognizer.transcribe(spoken(said))
        assert heard.woken and heard.command == said.removeprefix("hey robot, "), heard.text
        plan = EmbeddedPlanner().plan(heard.command, context)
        assert plan.kind == "mission", plan.say


def test_every_step_a_command_plans_is_a_skill_or_a_behaviour():
    assert planned_kinds() <= set(REGISTRY) | set(BehaviorLibrary().behaviors)


def test_aliases_name_places_and_surfaces():
    words = WorldVocabulary.of(load_world_config("apartment"))
    assert words.place("living room") == "living_room" and words.place("dining table") == "table"
    assert words.surface("kitchen counter") == "counter" and words.surface("kitchen") is None
    assert words.place("home") == "start"


def test_every_command_the_grammar_hears_is_one_the_planner_understands(tmp_path):
    # "I can't …" is the planner's answer to words it has no phrasing for; any other answer (a plan, a question,
    # a refusal with a reason such as "I can't pick up people") means it understood what was asked.
    assert not_understood(told_planning_context("apartment"), tmp_path) == {}


def test_each_intent_has_verbs():
    for name, intent in INTENTS.items():
        assert intent.verbs and len(set(intent.verbs)) == len(intent.verbs), name
