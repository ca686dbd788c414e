"""Typed commands in the kitchen, end to end: the learned detector tells a coke from five other cans."""

import pytest

from bt_humanoid.cli import EXIT_OK, run_main


@pytest.mark.sim
def test_bring_me_a_coke_brings_the_coke_not_another_can(monkeypatch, capsys):
    from bt_humanoid.sim import simulation

    built: list[simulation.Simulation] = []
    original = simulation.Simulation.__init__

    def keeping(self, *args, **kwargs) -> None:
        built.append(self)
        original(self, *args, **kwargs)

    monkeypatch.setattr(simulation.Simulation, "__init__", keeping)
    argv = ["--world", "kitchen", "--scene", "cans_on_table", "--command", "bring me a coke", "--no-live"]
    assert run_main(argv) == EXIT_OK
    assert "I will pick up the coke and bring it to you" in capsys.readouterr().out
    (sim,) = built  # judged on the run's own simulation, after it ended
    from bt_humanoid.sim.ground_truth import GroundTruth

    truth = GroundTruth(sim)
    assert truth.held_by_person("coke") == "person"  # handed over: in the person's hand
    for other in ("pepsi", "7up", "red bull", "lime soda", "grapefruit soda"):
        assert truth.rests_on(other, "table") and truth.upright(other), f"the {other} was moved"


def test_a_coke_among_three_alike_is_any_of_them_not_a_question():
    from bt_humanoid.commanding import plan_command
    from bt_humanoid.engine.stack import RobotStack

    stack = RobotStack.load("kitchen", "wheeled_humanoid", scene="three_cokes")
    try:
        stack.look()
        seen = [o.name for o in stack.context.world_model.present()]
        assert seen.count("coke") == 3  # told apart from the pepsi and the 7up, alike among themselves
        outcome = plan_command("bring me a coke", stack.planning_context(), lambda question: None)
        assert outcome.spec is not None, outcome.plan.say
        assert outcome.plan.mission["tree"]["sequence"][0] == {"take": {"object": "coke"}}
        asked = plan_command("bring me the can", stack.planning_context(), lambda question: None)
        assert asked.plan.kind == "question"  # "the can", and cans that differ: which one is a fair question
        any_can = plan_command("bring me a can", stack.planning_context(), lambda question: None)
        taken = any_can.plan.mission["tree"]["sequence"][0]["take"]["object"]  # "a can": any will do, it says which
        assert taken in ("coke", "pepsi", "7up") and f"the {taken}" in any_can.plan.say
    finally:
        stack.close()


def test_a_condition_on_one_of_several_alike_holds_for_any_of_them():
    from bt_humanoid.engine.stack import RobotStack
    from bt_humanoid.engine.verdict import _any

    stack = RobotStack.load("kitchen", "wheeled_humanoid", scene="three_cokes")
    try:
        assert _any("coke", stack.truth, lambda name: name == "coke 3") == "coke 3"  # any coke brought is a coke
        assert _any("coke", stack.truth, lambda name: False) == "coke"  # none: judged (and reported) on the named one
        assert _any("coke 2", stack.truth, lambda name: True) == "coke 2"  # an instance named is that one
        assert _any("pepsi", stack.truth, lambda name: False) == "pepsi"
    finally:
        stack.close()
