"""The LLM planner against a local OpenAI-compatible server that answers with scripted plans.

Good, malformed and hallucinated answers: valid plans pass, broken ones are sent back with the error for
repair, and after too many the embedded planner answers. A cache spares repeated calls. The prompt carries what
the embedded planner knows (categories, what is held, counts), and plans are held to the robot's one hand.
"""

import copy
import dataclasses
import json
import os
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

import numpy as np
import pytest

from bt_humanoid.cli import EXIT_OK, plan_main
from bt_humanoid.commanding import make_planner
from bt_humanoid.language.llm import MAX_REPLY_BYTES, LlmSettings, PlanCache, hand_problems, world_summary
from bt_humanoid.language.plan import PlanningContext, mission_signature
from bt_humanoid.paths import behaviors_dir
from bt_humanoid.testing.told import told_planning_context
from bt_humanoid.yaml_source import display_path

GOOD = {"kind": "mission", "say": "I will fetch the mug.", "tree": {"take": {"object": "coffee mug"}}}
UNKNOWN_SKILL = {"kind": "mission", "say": "Backflip!", "tree": {"backflip": {"height": 2}}}
UNKNOWN_OBJECT = {"kind": "mission", "say": "Got it.", "tree": {"take": {"object": "golden key"}}}
OFF_THE_MAP = {"kind": "mission", "say": "Going.", "tree": {"navigate": {"pose": [40.0, 3.0, 0.0]}}}
WRONG_TYPE = {"kind": "mission", "say": "Turning.", "tree": {"move_base": {"relative": True, "yaw": "a lot"}}}
# a description the skills accept (grounding could read it), of nothing the robot has seen or been told of
UNSEEN = {
    "kind": "mission",
    "say": "Got it.",
    "tree": {"sequence": [{"wave": {}}, {"take": {"object": "the purple cube"}}]},
}
LONG_STEP = {"kind": "mission", "say": "Walking.", "tree": {"move_base": {"relative": True, "x": 8.0}}}


class ScriptedModel:
    """A chat-completions endpoint that replies with the next scripted answer and records every request."""

    def __init__(self) -> None:
        self.script: list[str] = []
        self.requests: list[dict] = []
        model = self

        class Handler(BaseHTTPRequestHandler):
            def do_POST(self) -> None:
                body = json.loads(self.rfile.read(int(self.headers["Content-Length"])))
                model.requests.append({"path": self.path, "auth": self.headers.get("Authorization"), **body})
                content = model.script.pop(0) if model.script else "{}"
                reply = json.dumps({"choices": [{"message": {"role": "assistant", "content": content}}]}).encode()
                self.send_response(200)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(reply)))
                self.end_headers()
                self.wfile.write(reply)

            def log_message(self, *args) -> None:
                pass

        self.server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.url = f"http://127.0.0.1:{self.server.server_port}/v1"
        threading.Thread(target=self.server.serve_forever, daemon=True).start()

    def answers(self, *answers) -> None:
        self.script = [a if isinstance(a, str) else json.dumps(a) for a in answers]
        self.requests = []


@pytest.fixture(scope="module")
def model():
    scripted = ScriptedModel()
    yield scripted
    scripted.server.shutdown()


@pytest.fixture(scope="module")
def context() -> PlanningContext:
    return told_planning_context("apartment")


def _planner(model, repairs: int = 2):
    planner = make_planner(LlmSettings(model.url, "scripted", api_key="secret", max_repairs=repairs))
    planner.cache = PlanCache()
    return planner


def test_a_good_plan_is_validated_and_used(model, context):
    model.answers(GOOD)
    plan = _planner(model).plan("bring the mug", context)
    assert plan.kind == "mission" and mission_signature(plan.mission["tree"]) == ["take coffee mug"]
    request = model.requests[0]
    assert request["path"] == "/v1/chat/completions" and request["auth"] == "Bearer secret"
    prompt = request["messages"][0]["content"]
    assert "| `take` (behaviour)" in prompt and '"coffee mug"' in prompt  # generated from registry and world
    assert request["response_format"] == {"type": "json_object"}


@pytest.mark.parametrize(
    ("bad", "problem"),
    [
        ("this is not json", "not JSON"),
        (UNKNOWN_SKILL, "unknown skill or node kind 'backflip'"),
        (UNKNOWN_OBJECT, "unknown object 'golden key'"),
        (OFF_THE_MAP, "(40.0, 3.0) is outside the map"),
        (WRONG_TYPE, "yaw"),
        (UNSEEN, "<plan> at tree.sequence[1].take: find.object: unknown object 'the purple cube'"),
        (LONG_STEP, "<plan> at tree.move_base: a relative move of 8 m; at most 5 m"),
    ],
)
def test_a_bad_answer_goes_back_with_its_error_and_the_repair_is_used(model, context, bad, problem):
    model.answers(bad, GOOD)
    planner = _planner(model)
    plan = planner.plan("bring the mug", context)
    assert plan.kind == "mission" and mission_signature(plan.mission["tree"]) == ["take coffee mug"]
    assert len(model.requests) == 2
    feedback = model.requests[1]["messages"][-1]["content"]
    assert feedback.startswith("That answer is not valid:") and problem in feedback, feedback


def test_after_too_many_bad_answers_the_embedded_planner_answers(model, context):
    model.answers(UNKNOWN_SKILL, UNKNOWN_OBJECT, OFF_THE_MAP)
    planner = _planner(model, repairs=2)
    plan = planner.plan("pick up the red cube", context)
    assert len(model.requests) == 3
    assert plan.kind == "mission" and mission_signature(plan.mission["tree"]) == ["take red cube"]
    assert "planned offline: the language model gave no valid plan in 3 tries" in plan.say


def test_an_unreachable_endpoint_falls_back_with_the_reason(context):
    planner = make_planner(LlmSettings("http://127.0.0.1:9/v1", "none", timeout=2.0))
    plan = planner.plan("turn left ninety degrees", context)
    assert plan.kind == "mission" and mission_signature(plan.mission["tree"]) == ["turn 90"]
    assert "planned offline: the language model at http://127.0.0.1:9/v1 failed" in plan.say


def _waving_with(file: str) -> dict:
    return {
        "kind": "mission",
        "say": "Waving.",
        "tree": {"sequence": [{"say": {"text": "Hi"}}, {"subtree": {"file": file}}]},
    }


def test_a_plan_calls_subtree_files_only_from_the_behaviour_folder(model, context, tmp_path):
    # Before: a plan could name any file; a valid behaviour outside behaviors/ was loaded and run
    outside = tmp_path / "wave.yaml"
    outside.write_text((behaviors_dir() / "wave.yaml").read_text())
    for file in (str(outside), os.path.relpath(outside, behaviors_dir()), "../../../../../../etc/passwd"):
        model.answers(_waving_with(file), GOOD)
        plan = _planner(model).plan("wave", context)
        assert len(model.requests) == 2 and mission_signature(plan.mission["tree"]) == ["take coffee mug"], file
        feedback = model.requests[1]["messages"][-1]["content"]
        where = "<plan> at tree.sequence[1].subtree.file"
        assert f"{where}: subtree file '{file}' is outside {display_path(behaviors_dir())}/" in feedback, feedback
        assert "valid: approach.yaml, fetch.yaml" in feedback and "wave.yaml" in feedback
    model.answers(_waving_with("wave.yaml"))  # a behaviour of the project's own, by its file: fine
    plan = _planner(model).plan("wave", context)
    assert len(model.requests) == 1 and plan.mission["tree"]["sequence"][1] == {"subtree": {"file": "wave.yaml"}}


def test_a_reply_over_the_size_limit_is_not_read_and_the_embedded_planner_answers(model, context):
    # Before the limit, the whole reply was read into memory, however large, and this plan was used
    padding = MAX_REPLY_BYTES - len(json.dumps(GOOD))
    model.answers({**GOOD, "say": "x" * (padding - 200)})  # just under the limit, with the reply's wrapping: read
    assert _planner(model).plan("bring the mug", context).say.startswith("xxx")
    model.answers({**GOOD, "say": "x" * padding})
    plan = _planner(model).plan("pick up the red cube", context)
    assert len(model.requests) == 1 and mission_signature(plan.mission["tree"]) == ["take red cube"]
    limit = f"{MAX_REPLY_BYTES:,}"
    assert f"(planned offline: the language model at {model.url} failed: its reply is larger than {limit}" in plan.say


def test_a_repeated_command_comes_from_the_cache(model, context):
    model.answers(GOOD)
    planner = _planner(model)
    first = planner.plan("bring the mug", context)
    second = planner.plan("Bring the mug", context)
    assert len(model.requests) == 1 and first.mission["tree"] == second.mission["tree"]


def test_questions_and_refusals_from_the_model_are_passed_on(model, context):
    model.answers(
        {"kind": "question", "say": "Which cube?", "options": ["red cube", "blue cube"]},
        {"kind": "refusal", "say": "I cannot fly."},
    )
    planner = _planner(model)
    question = planner.plan("pick up the cube", context)
    assert question.kind == "question" and question.choice.options == ["red cube", "blue cube"]
    refusal = planner.plan("fly", context)
    assert refusal.kind == "refusal" and refusal.say == "I cannot fly."


def test_the_world_summary_is_what_the_robot_believes(context):
    summary = json.loads(world_summary(context))
    assert {name for names in summary["seen_on"].values() for name in names} == set(context.world.objects)
    assert summary["surfaces"] == ["counter", "shelf", "table"] and "kitchen" in summary["places"]
    assert summary["other_names"]["kitchen counter"] == "counter"  # world.yaml's aliases, with what they name
    assert summary["robot"] == {"holding": None, "near": "start"}


# --- the kitchen: what the embedded planner knows, and one hand -------------------------------------------------


def _bring(*things: str) -> dict:
    """A mission that brings each thing to the person in turn: take, navigate, give."""
    steps = [s for t in things for s in ({"take": {"object": t}}, {"navigate": {"person": "person"}}, {"give": {}})]
    return {"kind": "mission", "say": "Bringing them.", "tree": {"sequence": steps}}


BRING_BOTH = ["take apple", "navigate person", "give person", "take tea", "navigate person", "give person"]
# the tea taken while the apple is still in hand
BOTH_IN_ONE_HAND = {
    "kind": "mission",
    "say": "Bringing them.",
    "tree": {
        "sequence": [
            {"take": {"object": "apple"}},
            {"take": {"object": "tea"}},
            {"navigate": {"person": "person"}},
            {"give": {}},
        ]
    },
}


@pytest.fixture(scope="module")
def kitchen() -> PlanningContext:
    return told_planning_context("kitchen")


@pytest.fixture(scope="module")
def holding_apple(kitchen) -> PlanningContext:
    """The kitchen by the table with the apple in the right hand and a second coke on the table."""
    belief = copy.deepcopy(kitchen.belief)
    belief.objects["apple"].held_by = "right"
    coke = belief.objects["coke"]
    belief.update(dataclasses.replace(coke, id="coke_2", name="coke 2", position=coke.position - np.array([0, 0.1, 0])))
    return PlanningContext(kitchen.world, belief, np.array([2.0, -1.3, 0.0]))


def _known(request: dict) -> dict:
    """The world section of the prompt a request sent."""
    prompt = request["messages"][0]["content"]
    return json.loads(prompt.split("What the robot knows now:\n", 1)[1].split("\n\n", 1)[0])


def test_the_prompt_carries_categories_what_is_held_and_counts(model, holding_apple):
    model.answers({"kind": "refusal", "say": "No."})
    _planner(model).plan("bring me two drinks", holding_apple)
    known = _known(model.requests[0])
    assert known["robot"] == {"holding": "apple", "near": "table"}
    assert known["things"]["red bull"]["categories"] == ["caffeinated", "drink", "energy drink", "recyclable", "sugary"]
    assert "water" in known["things"]["water bottle"]["aliases"]
    assert known["seen_count"]["coke"] == 2 and known["seen_count"]["apple"] == 1  # held counts too
    assert known["seen_by_category"]["drink"] == 9 and known["seen_by_category"]["fruit"] == 1
    assert known["seen_on"]["table"] == ["7up", "coke", "coke 2", "kettle chips", "pepsi"]  # the apple is in hand
    assert known["bins"] == {"compost_bin": "compostable", "recycling_bin": "recyclable", "trash_can": "anything"}
    rules = model.requests[0]["messages"][0]["content"]
    assert 'A count ("three drinks") means that many different things' in rules
    assert "carries one thing at a time" in rules and "already holds the thing asked for" in rules


def test_the_summary_is_the_same_for_the_same_belief(kitchen):
    shuffled = copy.deepcopy(kitchen.belief)
    shuffled.objects = dict(reversed(shuffled.objects.items()))
    again = PlanningContext(kitchen.world, shuffled, kitchen.robot_pose)
    assert world_summary(again) == world_summary(kitchen)  # sorted: one cache key, one prompt


def test_a_plan_that_brings_two_things_one_after_the_other_is_accepted(model, kitchen):
    model.answers(_bring("apple", "tea"))
    plan = _planner(model).plan("bring me the apple and the tea", kitchen)
    assert len(model.requests) == 1 and plan.kind == "mission" and "planned offline" not in plan.say
    assert mission_signature(plan.mission["tree"]) == BRING_BOTH
    assert plan.mission["world"] == "kitchen"  # validated against the kitchen


def test_a_count_is_that_many_different_things(model, kitchen):
    model.answers(_bring("coke", "water bottle"))
    plan = _planner(model).plan("bring me two drinks", kitchen)
    assert len(model.requests) == 1 and "planned offline" not in plan.say
    assert mission_signature(plan.mission["tree"])[::3] == ["take coke", "take water bottle"]
    model.answers(_bring("coke", "coke"), _bring("coke", "water bottle"))  # the same can twice: sent back
    plan = _planner(model).plan("bring me two drinks", kitchen)
    assert len(model.requests) == 2 and mission_signature(plan.mission["tree"])[::3] == [
        "take coke",
        "take water bottle",
    ]
    feedback = model.requests[1]["messages"][-1]["content"]
    assert "tree.sequence[3].take: the coke was given away or thrown out at tree.sequence[2].give" in feedback


def test_taking_a_second_thing_while_holding_the_first_is_sent_back_then_planned_offline(model, kitchen):
    model.answers(BOTH_IN_ONE_HAND, BOTH_IN_ONE_HAND, BOTH_IN_ONE_HAND)
    plan = _planner(model, repairs=2).plan("bring me the apple and the tea", kitchen)
    assert len(model.requests) == 3  # sent back twice for repair, then the embedded planner answers
    problem = "<plan> at tree.sequence[1].take: take picks up the tea while the robot still holds the apple"
    assert problem in model.requests[1]["messages"][-1]["content"]
    assert "planned offline: the language model gave no valid plan in 3 tries" in plan.say and problem in plan.say
    assert mission_signature(plan.mission["tree"]) == BRING_BOTH


def test_what_is_in_hand_is_not_taken_again(model, holding_apple):
    again = _bring("apple")
    carried = {**again, "tree": {"sequence": again["tree"]["sequence"][1:]}}  # navigate, give: from the hand
    model.answers(again, carried)
    plan = _planner(model).plan("bring me the apple", holding_apple)
    assert mission_signature(plan.mission["tree"]) == ["navigate person", "give person"]
    feedback = model.requests[1]["messages"][-1]["content"]
    assert "tree.sequence[0].take: the robot already holds the apple; do not take it again" in feedback


@pytest.mark.parametrize(
    ("steps", "problem"),
    [
        ([{"take": {"object": "tea"}}], "take picks up the tea while the robot still holds the apple"),
        ([{"fetch": {"object": "coke", "to": "table", "x": 2.6, "y": -1.3}}], "fetch picks up the coke while"),
        ([{"throw_away": {"object": "red apple", "into": "compost_bin"}}], "already holds the red apple"),
        ([{"drop": {"into": "compost_bin"}}, {"take": {"object": "tea"}}], None),  # the hand is free again
        ([{"place": {"surface": "table", "x": 2.6, "y": -1.3}}, {"take": {"object": "apple"}}], None),
        ([{"give": {}}, {"fetch": {"object": "apple", "to": "table", "x": 2.6, "y": -1.3}}], "given away"),
        ([{"retry": {"attempts": 2, "child": {"take": {"object": "tea"}}}}], "still holds the apple"),
    ],
)
def test_the_hand_is_followed_through_the_steps(holding_apple, steps, problem):
    problems = hand_problems({"sequence": steps}, holding_apple)
    assert (problem is None and problems == []) or (len(problems) == 1 and problem in problems[0]), problems


@pytest.mark.sim  # bt-plan looks around before planning a request about things: physics
def test_bt_plan_uses_the_endpoint_given_on_the_command_line(model, capsys):
    model.answers(GOOD)
    code = plan_main(["bring the mug", "--llm-url", model.url, "--llm-model", "scripted"])
    assert code == EXIT_OK
    assert "robot: I will fetch the mug." in capsys.readouterr().out


def test_the_hand_check_reads_plans_with_the_mission_language_s_node_extras():
    from bt_humanoid.language import llm
    from bt_humanoid.mission.schema import NODE_EXTRAS

    assert tuple(llm.NODE_EXTRAS) == tuple(NODE_EXTRAS)
