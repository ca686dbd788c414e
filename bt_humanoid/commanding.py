"""From a spoken or typed command to a mission: the robot looks, the planner plans, questions get answers.

This sits beside the CLI, above the engine and the language package: the
robot's view at the start comes from a short probe run (the world loaded,
the head camera's first look fused into a WorldModel), and the planner reads
that belief, never the simulator.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from bt_humanoid.errors import UserError
from bt_humanoid.language.embedded import MAX_STEP, EmbeddedPlanner
from bt_humanoid.language.llm import LlmPlanner, LlmSettings, PlanRejected
from bt_humanoid.language.plan import Plan, PlanningContext
from bt_humanoid.mission.loader import MissionLoader
from bt_humanoid.mission.spec import MissionSpec
from bt_humanoid.perception.grounding import resolve

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


def make_planner(settings: LlmSettings | None) -> EmbeddedPlanner | LlmPlanner:
    """The embedded planner, or an LLM planner (falling back to the embedded one) when settings are given."""
    embedded = EmbeddedPlanner()
    if settings is None:
        return embedded
    from bt_humanoid.docs import reference

    catalogue = "\n".join(line for line in reference().splitlines() if line.startswith("| `"))
    return LlmPlanner(settings, catalogue, validate_planned_mission, fallback=embedded)


def validate_planned_mission(mission: dict[str, Any], context: PlanningContext) -> dict[str, Any]:
    """A planner's mission checked like a file and against the world; PlanRejected says what is wrong."""
    mission = {**mission, "world": context.world.name, "robot": context.robot}
    try:
        MissionLoader().load_data(mission, name="<plan>")
    except UserError as error:
        raise PlanRejected(str(error)) from None
    for problem in _world_problems(mission["tree"], context):
        raise PlanRejected(problem)
    return mission


def _world_problems(node: Any, context: PlanningContext, path: str = "tree"):
    """Objects nobody has seen or named, and goals off the map, anywhere in a plan's tree."""
    if isinstance(node, list):
        for index, child in enumerate(node):
            yield from _world_problems(child, context, f"{path}[{index}]")
        return
    if not isinstance(node, dict):
        return
    (x0, y0), (x1, y1) = context.world.bounds
    for key, value in node.items():
        where = f"{path}.{key}"
        if key == "object" and isinstance(value, str) and not value.startswith("$"):
            if value not in context.world.objects:
                try:
                    resolve(value, context.belief, context.robot_pose)
                except KeyError as error:
                    names = ", ".join(context.world.objects)
                    yield f"{where}: unknown object {value!r} ({error.args[0]}); known objects: {names}"
        elif (
            key == "pose"
            and isinstance(value, list)
            and len(value) >= 2
            and all(isinstance(v, int | float) for v in value[:2])
        ):
            if not (x0 <= value[0] <= x1 and y0 <= value[1] <= y1):
                yield f"{where}: ({value[0]}, {value[1]}) is outside the map [{x0}, {x1}] × [{y0}, {y1}]"
        elif key == "move_base" and isinstance(value, dict):
            x, y = value.get("x"), value.get("y")
            if value.get("relative"):
                if isinstance(x, int | float) and abs(x) > MAX_STEP:
                    yield f"{where}.x: a relative move of {x} m; at most {MAX_STEP:.0f} m (use navigate)"
            elif isinstance(x, int | float) and isinstance(y, int | float) and not (x0 <= x <= x1 and y0 <= y <= y1):
                yield f"{where}: ({x}, {y}) is outside the map [{x0}, {x1}] × [{y0}, {y1}]"
        yield from _world_problems(value, context, where)


def plan_command(
    text: str,
    context: PlanningContext,
    answers: Callable[[str], str | None],
    planner: EmbeddedPlanner | LlmPlanner | None = None,
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
