"""From a spoken or typed command to a mission: the robot looks, the planner plans, questions get answers.

This sits beside the CLI, above the engine and the language package: the
robot's view at the start comes from a short probe run (the world loaded,
the head camera's first look fused into a WorldModel), and the planner reads
that belief, never the simulator.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from bt_humanoid.language.embedded import EmbeddedPlanner
from bt_humanoid.language.plan import Plan, PlanningContext
from bt_humanoid.mission.loader import MissionLoader
from bt_humanoid.mission.spec import MissionSpec

MAX_QUESTIONS = 3  # a command still unclear after this many answers is refused


@dataclass
class CommandOutcome:
    plan: Plan  # the last answer of the planner
    spec: MissionSpec | None  # the validated mission, when there is one to run
    dialogue: list[tuple[str, str]]  # (robot, person) turns of questions and answers


def context_at_start(world: str, robot: str) -> PlanningContext:
    """What the robot knows when a command arrives: its map, and what one look from its start pose shows."""
    from bt_humanoid.engine.runner import MissionRun

    probe = {"mission": "look", "world": world, "robot": robot, "tree": {"wait": {"seconds": 0}}}
    run = MissionRun(MissionLoader().load_data(probe, name="<look>"))
    try:
        if run.perceiver is not None:
            run.perceiver.look()
        return PlanningContext(run.context.world, run.context.world_model, run.robot.base.pose(), robot)
    finally:
        if run.perceiver is not None:
            run.perceiver.close()


def plan_command(
    text: str,
    context: PlanningContext,
    answers: Callable[[str], str | None],
    planner: EmbeddedPlanner | None = None,
) -> CommandOutcome:
    """Plan ``text``; each question goes to ``answers`` (None: no answer, the question stands)."""
    planner = planner or EmbeddedPlanner()
    plan = planner.plan(text, context)
    dialogue: list[tuple[str, str]] = []
    while plan.kind == "question" and plan.choice is not None and len(dialogue) < MAX_QUESTIONS:
        reply = answers(plan.say)
        if reply is None:
            break
        dialogue.append((plan.say, reply))
        plan = planner.answer(plan.choice, reply, context)
    spec = None
    if plan.kind == "mission" and plan.mission is not None:
        spec = MissionLoader().load_data(plan.mission, name="<command>")
    return CommandOutcome(plan, spec, dialogue)
