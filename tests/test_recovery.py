"""Recovery policies: retry with backoff, replan (start the enclosing sequence over), an alternative, ask."""

import pytest

from bt_humanoid.engine.compiler import resolve_recovery
from bt_humanoid.engine.decorators import Ask, FaultWatch, OrElse, RecoverySteps, Replan, Retry, SafetyGuard
from bt_humanoid.engine.runner import MissionRun
from bt_humanoid.engine.stack import RobotStack
from bt_humanoid.language.questions import Answer, Questions, read_answer
from bt_humanoid.paths import project_root
from bt_humanoid.testing.scenario import Scenario, build_run, load_mission, run_scenario

NEVER = {"check": {"key": "never", "op": "exists"}}  # a leaf that fails every time
READY = {"check": {"key": "ready", "op": "exists"}}


def run(tree, **header):
    return run_scenario({"mission": "t", "tree": tree, **header})


def events(scenario, kind):
    return [e for e in scenario.events if e["event"] == kind]


def test_fields_come_from_the_most_specific_layer_that_sets_them():
    node, mission, skill = (
        ("node", {"retries": 3}),
        ("mission", {"retries": 1, "backoff": 2.0}),
        ("skill", {"replan": 1}),
    )
    robot = ("robot", {"backoff": 0.5})
    resolved = resolve_recovery(node, mission, skill, robot)
    assert resolved.steps == RecoverySteps(retries=3, backoff=2.0, replan=1)
    assert resolved.sources == {"retries": "node", "backoff": "mission", "replan": "skill", "ask": "built-in default"}
    assert resolve_recovery(("node", {}), ("mission", {"retries": None}), robot).steps == RecoverySteps(backoff=0.5)


@pytest.mark.sim
def test_replan_starts_the_enclosing_sequence_over():
    tree = {"sequence": [{"say": {"text": "looking"}}, {**NEVER, "recovery": {"replan": 2, "backoff": 0.5}}]}
    s = run(tree)
    assert s.result.tree_status == "FAILURE"
    assert s.result.said == ["looking"] * 3  # the first run and two replans
    replans = events(s, "replan")
    assert [e["node"] for e in replans] == ["sequence"] * 2
    assert "starting over after check" in replans[0]["message"]
    assert replans[1]["t"] - replans[0]["t"] == pytest.approx(0.5, abs=0.06)


@pytest.mark.sim
def test_replan_reaches_the_nearest_sequence_through_decorators_and_fallbacks():
    inner = {"fallback": [{"invert": {"child": {"say": {"text": "plan a"}}}}, {**NEVER, "recovery": {"replan": 1}}]}
    tree = {"sequence": [{"say": {"text": "start"}}, {"sequence": [{"say": {"text": "inner"}}, inner]}]}
    s = run(tree)
    assert s.result.said == ["start", "inner", "plan a", "inner", "plan a"]  # the inner sequence, not the outer
    assert [e["node"] for e in events(s, "replan")] == ["sequence[1].sequence"]


@pytest.mark.sim
def test_replan_then_succeeds_when_the_world_changed():
    # the condition holds only after 1.2 s: the third start of the sequence finds it set
    tree = {
        "parallel": {
            "policy": "all",
            "children": [
                {"sequence": [{"wait": {"seconds": 1.2}}, {"set": {"key": "ready", "value": True}}]},
                {"sequence": [{"wait": {"seconds": 0.1}}, {**READY, "recovery": {"replan": 3}}]},
            ],
        }
    }
    s = run(tree)
    assert s.result.tree_status == "SUCCESS"
    assert 1 <= len(events(s, "replan")) <= 3


@pytest.mark.sim
def test_the_node_setting_wins_and_conditions_ignore_mission_wide_settings():
    tree = {"sequence": [{"say": {"text": "go"}}, {**NEVER, "recovery": {"replan": 1}}]}
    assert run(tree).result.said == ["go", "go"]
    off = run(tree, recovery={"skills": {"check": {"replan": 0}}})
    assert off.result.said == ["go", "go"], "the node's own setting wins over the mission's per-skill one"
    plain = {"sequence": [{"say": {"text": "go"}}, NEVER]}
    assert run(plain, recovery={"replan": 1}).result.said == ["go"], "conditions ignore mission-wide settings"


def test_grasp_defaults_to_one_retry_then_one_replan():
    compiled = build_run({"mission": "t", "tree": {"sequence": [{"grasp": {"object": "red cube"}}]}}).compiled
    assert compiled.recovery["sequence[0].grasp"].steps == RecoverySteps(retries=1, replan=1)
    grasp = next(node for node, path in compiled.nodes if path.endswith("grasp"))
    assert [type(step) for step in _steps_above(grasp)] == [FaultWatch, Retry, SafetyGuard]
    replan = compiled.root.decorated
    assert isinstance(replan, Replan) and [b.node for b in replan.budgets.values()] == ["sequence[0].grasp"]
    alone = {"mission": "t", "recovery": {"retries": 0}, "tree": {"grasp": {"object": "red cube"}}}
    compiled = build_run(alone).compiled
    assert compiled.recovery["grasp"].steps.retries == 0, "mission-wide beats the skill's default"
    assert [type(step) for step in _steps_above(compiled.nodes[0][0])] == [FaultWatch, SafetyGuard], "no sequence"


@pytest.mark.sim
def test_an_alternative_runs_when_the_node_still_fails():
    tree = {"sequence": [{**NEVER, "recovery": {"retries": 1, "alternative": {"say": {"text": "plan b"}}}}]}
    s = run(tree)
    assert s.result.tree_status == "SUCCESS" and s.result.said == ["plan b"]
    assert len(events(s, "retry")) == 1, "the node's retries come before its alternative"
    assert "SUCCESS" in s.statuses("sequence[0].check.alternative.say")


def test_a_per_skill_alternative_is_compiled_wherever_the_skill_is_used():
    tree = {"sequence": [NEVER, {"check": {"key": "also_never", "op": "exists"}}]}
    s = run(tree, recovery={"skills": {"check": {"alternative": {"say": {"text": "instead"}}}}})
    assert s.result.tree_status == "SUCCESS" and s.result.said == ["instead", "instead"]


def test_a_failed_alternative_fails_the_node_with_its_reason():
    tree = {"sequence": [{**NEVER, "recovery": {"alternative": {"check": {"key": "nope", "op": "exists"}}}}]}
    s = run(tree)
    assert s.result.tree_status == "FAILURE"
    assert "nope" in s.result.cause


def ask_run(tree, answers):
    """Run with someone to ask, who gives ``answers`` in turn as each question comes."""
    stack = build_run({"mission": "t", "tree": tree}).stack
    said: list[str] = []
    questions = Questions(said.append)
    stack.context.questions = questions
    run_ = MissionRun(stack, load_mission({"mission": "t", "tree": tree}))  # compiled with the question channel
    replies = list(answers)

    def answer() -> None:
        if questions.awaiting and replies:
            questions.answer(replies.pop(0))

    stack.observers.append(answer)
    return Scenario(run_, run_.execute()), said


@pytest.mark.sim
def test_ask_tries_again_on_yes_and_fails_on_no():
    tree = {"sequence": [{**NEVER, "recovery": {"retries": 1, "ask": True}}]}
    s, said = ask_run(tree, ["maybe", "yes please", "no"])
    assert s.result.tree_status == "FAILURE"
    assert said[0] == "I could not check: never is not on the blackboard. Shall I try again?"
    assert said[1].startswith("Please answer yes or no.")
    assert [e["message"] for e in events(s, "answer")] == ["told to try check again", "told not to try check again"]
    assert len(events(s, "retry")) == 2, "yes gives the node its retries afresh"


def test_ask_is_skipped_when_no_one_can_answer():
    s = run({"sequence": [{**NEVER, "recovery": {"ask": True}}]})
    assert s.result.tree_status == "FAILURE" and events(s, "ask") == []


@pytest.mark.sim
def test_a_stop_while_asking_withdraws_the_question():
    tree = {"sequence": [{**NEVER, "recovery": {"ask": True}}]}
    stack = build_run({"mission": "t", "tree": tree}).stack
    questions = Questions(lambda text: None)
    stack.context.questions = questions
    run_ = MissionRun(stack, load_mission({"mission": "t", "tree": tree}))
    stack.observers.append(lambda: questions.pending and run_.request_stop("stop (typed)"))
    result = run_.execute()
    assert result.safety.startswith("stop") and questions.pending is None


@pytest.mark.parametrize(
    ("reply", "answer"),
    [("yes", Answer.YES), ("Sure, go ahead", Answer.YES), ("no thanks", Answer.NO), ("don't", Answer.NO)],
)
def test_yes_and_no(reply, answer):
    assert read_answer(reply) is answer


def test_neither_yes_nor_no():
    assert read_answer("the blue one") is None


def _steps_above(node):
    """The decorators from ``node`` up to and including its Safety guard."""
    steps = []
    while not isinstance(node, SafetyGuard):
        node = node.parent
        steps.append(node)
    return steps


@pytest.mark.sim
def test_the_recovery_example_compiles_as_written_and_runs(run_mission):
    mission = project_root() / "missions" / "recovery.yaml"
    compiled = build_run(mission).compiled
    nodes = dict((path, node) for node, path in compiled.nodes)
    grasp = compiled.recovery["sequence[3].sequence[2].grasp"]
    assert (grasp.steps.retries, grasp.steps.replan, grasp.steps.ask) == (1, 1, True)
    assert grasp.sources["ask"] == "node recovery:" and grasp.sources["backoff"] == "robot.yaml recovery:"
    # the sequence that starts over for the grasp wears the replan step; the grasp wears its retry and question
    assert isinstance(nodes["sequence[3].sequence"].parent, Replan)
    steps = _steps_above(nodes["sequence[3].sequence[2].grasp"])
    assert [type(step) for step in steps] == [FaultWatch, Retry, Ask, SafetyGuard]
    assert steps[2].replan.sequence == "sequence[3].sequence" and steps[2].replan.limit == 1
    assert compiled.recovery["sequence[1].move_base"].steps == RecoverySteps(retries=2, backoff=1.0)
    assert "sequence[4].sequence[1].put.or_else" in nodes, "the per-skill alternative of put"
    scenario = run_mission(mission)
    assert scenario.result.success, scenario.result.summary()
    assert scenario.truth.rests_on("red cube", "table")


def test_an_interactive_session_routes_typed_lines_to_the_robots_question():
    import queue

    from bt_humanoid.commanding import InteractiveSession

    lines: queue.Queue = queue.Queue()
    said: list[str] = []
    session = InteractiveSession(RobotStack.load("apartment", "wheeled_humanoid"), lines, said.append)
    session.questions.ask("I could not grasp: it slipped. Shall I try again?")
    assert session.awaiting_answer
    lines.put("yes")
    session._listen_while_busy()  # what the executor calls between control steps
    assert session.questions.take() is Answer.YES and not session.awaiting_answer
    lines.put("say hello")
    lines.put(None)
    session.serve()
    root = session.mission.compiled.root.decorated
    assert isinstance(root, Ask) and root.what == "say hello", "a planned command asks at its root before giving up"
    assert "Done." in said


@pytest.mark.parametrize("name", ["pick_and_place.yaml", "recovery.yaml"])
def test_bt_validate_expand_prints_every_wrapper_with_its_resolved_values(name, capsys):
    from bt_humanoid.cli import validate_main
    from bt_humanoid.mission.loader import MissionLoader

    mission = project_root() / "missions" / name
    assert validate_main(["--expand", str(mission)]) == 0
    out = capsys.readouterr().out
    compiled = build_run(mission).compiled
    for _node, path in compiled.nodes:
        if path.endswith(".or_else"):
            continue
        line = next(line for line in out.splitlines() if f"[{path}]" in line)
        steps, sources = compiled.recovery[path].steps, compiled.recovery[path].sources
        assert (
            f"retries {steps.retries} ({sources['retries']})" in line
            and f"ask {'yes' if steps.ask else 'no'} (" in line
        )
    shown_as = {
        SafetyGuard: "safety guard\n",
        Retry: "retry ×",
        Replan: "replan: start this sequence over",
        FaultWatch: "fault watch\n",
        Ask: "ask whether to try",
        OrElse: "or else: the alternative",
    }
    for step, shown in shown_as.items():
        count = sum(1 for node in compiled.root.iterate() if isinstance(node, step))
        assert out.count(shown) == count, shown
    limits = MissionLoader().load_file(mission).header.safety
    assert f"max_base_speed {limits.max_base_speed:g} m/s (from mission safety:)" in out
    if name == "recovery.yaml":  # it has every kind of step
        assert all(any(isinstance(node, step) for node in compiled.root.iterate()) for step in shown_as)
