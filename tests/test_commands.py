"""Commands end to end: bt-plan's answers and exit codes, and a typed command run to success in the simulator."""

import queue

import numpy as np
import pytest

from bt_humanoid.cli import EXIT_INVALID, EXIT_OK, plan_main, run_main
from bt_humanoid.commanding import InteractiveSession, plan_command
from bt_humanoid.engine.runner import MissionRun
from bt_humanoid.engine.stack import RobotStack
from bt_humanoid.language.embedded import EmbeddedPlanner
from bt_humanoid.testing.told import told_planning_context


@pytest.mark.sim  # bt-plan looks around before planning a request about things: physics
def test_bt_plan_prints_the_mission_it_would_run(capsys):
    assert plan_main(["pick up the red cube and put it on the counter"]) == EXIT_OK
    out = capsys.readouterr().out
    assert "robot: I will pick up the red cube and put it on the counter." in out
    assert "- take:\n      object: red cube" in out and "surface: counter" in out


@pytest.mark.sim  # bt-plan looks around before planning a request about things: physics
def test_bt_plan_refuses_what_it_cannot_do_with_exit_2(capsys):
    assert plan_main(["do a backflip"]) == EXIT_INVALID
    err = capsys.readouterr().err
    assert "command 'do a backflip' not understood: I can't do a backflip. I can go to a place" in err


@pytest.mark.sim  # bt-plan looks around before planning a request about things: physics
def test_bt_plan_asks_and_takes_the_answer_from_the_command_line(capsys):
    # from the start the robot sees a blue cube and a blue bottle on the table
    assert plan_main(["grab the blue thing"]) == EXIT_INVALID  # a question, and nobody to answer it
    assert "needs an answer (give --answer TEXT): I see a " in capsys.readouterr().err
    assert plan_main(["grab the blue thing", "--answer", "the bottle"]) == EXIT_OK
    out = capsys.readouterr().out
    assert "you: the bottle" in out and "object: water bottle" in out


def _looked() -> RobotStack:
    """The apartment's robot after one look from its start pose: what a command is planned from."""
    stack = RobotStack.load("apartment", "wheeled_humanoid")
    stack.look()
    return stack


def test_the_planner_sees_with_the_camera_and_knows_unseen_things_by_name():
    context = _looked().planning_context()
    seen = {o.name for o in context.belief.objects.values()}
    assert seen and seen <= {"blue cube", "red cube", "blue bottle", "white mug", "yellow ball"}
    assert "coffee mug" not in seen  # in the kitchen, out of sight from the start
    outcome = plan_command("bring me the coffee mug", context, lambda question: None)
    assert outcome.spec is not None  # known by name: take will look for it


@pytest.mark.sim
def test_a_typed_command_puts_the_red_cube_on_the_counter():
    stack = _looked()
    outcome = plan_command("put the red cube on the counter", stack.planning_context(), lambda question: None)
    assert outcome.spec is not None, outcome.plan.say
    run = MissionRun(stack, outcome.spec)
    result = run.execute()
    assert result.tree_status == "SUCCESS", result.summary()
    place = outcome.plan.mission["tree"]["fetch"]
    x, y, _ = run.truth.object_position("red cube")
    assert run.truth.rests_on("red cube", "counter") and np.hypot(x - place["x"], y - place["y"]) < 0.03
    assert result.speed_at_end < 0.01


@pytest.mark.sim
def test_bt_run_with_a_command_builds_one_simulation_from_first_look_to_last_step(monkeypatch, capsys):
    from bt_humanoid.sim import simulation

    built: list[object] = []
    original = simulation.Simulation.__init__

    def counting(self, *args, **kwargs) -> None:
        built.append(self)
        original(self, *args, **kwargs)

    monkeypatch.setattr(simulation.Simulation, "__init__", counting)
    assert run_main(["--command", "turn left", "--no-live"]) == EXIT_OK
    assert len(built) == 1
    assert "I will turn left" in capsys.readouterr().out


@pytest.mark.parametrize("argv", [["--command", "fly to the moon", "--no-live"], ["--command", "  ", "--no-live"]])
def test_bt_run_with_a_command_it_cannot_do_exits_2_and_moves_nothing(argv, capsys):
    assert run_main(argv) == EXIT_INVALID
    assert "error:" in capsys.readouterr().err


def test_bt_run_needs_a_mission_or_a_command(capsys):
    with pytest.raises(SystemExit) as exit_info:
        run_main([])
    assert exit_info.value.code == EXIT_INVALID
    assert "give a mission file, --command TEXT, --audio FILE.wav, --interactive or --listen" in capsys.readouterr().err


@pytest.mark.sim
def test_a_typed_stop_in_mid_motion_brings_the_robot_to_rest_and_it_says_so():
    stack = _looked()
    context = stack.planning_context()
    outcome = plan_command("walk forward three meters", context, lambda question: None)
    run = MissionRun(stack, outcome.spec)
    planner = EmbeddedPlanner()
    stopped: list[float] = []

    def type_stop_after_a_second() -> None:
        if not stopped and run.sim.time > 1.5 and planner.plan("stop!", context).kind == "stop":
            assert run.robot.max_speed() > 0.1  # in mid-motion
            run.request_stop("stop (typed)")
            stopped.append(run.sim.time)

    stack.observers.append(type_stop_after_a_second)
    result = run.execute()
    assert stopped and result.tree_status == "FAILURE" and result.safety == "stop: stop (typed)"
    assert run.robot.max_speed() < 0.01 and result.said[-1] == "I have stopped."
    assert any(e["event"] == "rest" for e in result.events.events)  # how fast: python -m bt_humanoid.benchmarks.stop
    x, _, _ = run.truth.robot_pose()
    assert x < 2.5  # stopped well short of the 3 m it was told to walk


@pytest.mark.sim
def test_an_interactive_session_takes_commands_answers_and_a_stop_on_one_simulation():
    lines: queue.Queue = queue.Queue()
    said: list[str] = []
    stack = RobotStack.load("apartment", "wheeled_humanoid", speak=said.append)
    session = InteractiveSession(stack, lines, said.append)
    drive_started: list[float] = []

    def type_stop_two_seconds_into_the_drive() -> None:  # typed while the robot works
        if said and said[-1] == "I will go to the kitchen." and not drive_started:
            drive_started.append(stack.sim.time)
        if len(drive_started) == 1 and stack.sim.time > drive_started[0] + 2.0:
            lines.put("stop")
            drive_started.append(stack.sim.time)

    stack.observers.append(type_stop_two_seconds_into_the_drive)
    for line in ["grab the blue thing", "the bottle", "go to the kitchen", "do a backflip", None]:
        lines.put(line)
    session.serve()
    assert said[0].startswith("I see a") and "blue cube" in said[0] and "water bottle" in said[0]
    assert said[1] == "I will pick up the water bottle." and "Done." in said
    assert stack.truth.in_hand("water bottle") == "right"  # still holding it: one simulation throughout
    assert "I will go to the kitchen." in said and "I have stopped." in said
    assert session.results[-1].safety == "stop: stop (typed)"
    assert said[-1].startswith("I can't do a backflip.")
    assert stack.robot.max_speed() < 0.01


def test_a_transcript_with_unclear_speech_is_refused_but_a_typed_ellipsis_is_not():
    context = told_planning_context("apartment")
    # The embedded planner alone would pick up the red cube and wave: it skips words it does not know
    for heard in ("pick up the red …", "wave and …"):
        outcome = plan_command(heard, context, lambda _: None)
        assert outcome.plan.kind == "refusal" and outcome.spec is None
        assert "could not make out" in outcome.plan.say
    assert plan_command("pick up the red cube…", context, lambda _: None).plan.kind == "mission"


@pytest.mark.sim
def test_a_result_holds_its_own_missions_events_and_words_not_those_before_it_on_the_stack():
    from bt_humanoid.testing.scenario import load_mission

    stack = RobotStack.load("apartment", "wheeled_humanoid")
    first = MissionRun(
        stack,
        load_mission(
            {"mission": "a", "tree": {"sequence": [{"say": {"text": "one"}}, {"wait": {"seconds": "$missing"}}]}}
        ),
    ).execute()
    assert first.tree_status == "FAILURE" and "missing" in first.cause and first.said == ["one"]
    second = MissionRun(
        stack, load_mission({"mission": "b", "safety": {"time_budget": 1.0}, "tree": {"wait": {"seconds": 5}}})
    ).execute()
    assert second.said == [] and first.said == ["one"], "each result keeps its own words"
    assert second.cause is None or "missing" not in second.cause, "not the failure of the mission before"
    assert [e["mission"] for e in second.events.events if e["event"] == "start"] == ["b"]
    stack.close()
