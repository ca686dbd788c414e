"""From a spoken or typed command to a mission: the robot looks, the planner plans, questions get answers.

This sits beside the CLI, above the engine and the language package. A command is planned from the belief of
the robot stack that will carry it out (its map, and what its head camera has seen: one look when it starts),
never from the simulator; the planned mission then runs on that same stack.
"""

from __future__ import annotations

import queue
import time
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from bt_humanoid.engine.runner import MissionRun
from bt_humanoid.engine.stack import RobotStack
from bt_humanoid.errors import UserError
from bt_humanoid.language.asr import WAKE_WORD
from bt_humanoid.language.embedded import MAX_STEP, EmbeddedPlanner, is_stop
from bt_humanoid.language.listening import Listener, heard_in
from bt_humanoid.language.llm import LlmPlanner, LlmSettings, PlanRejected
from bt_humanoid.language.plan import Plan, PlanningContext
from bt_humanoid.language.questions import Questions
from bt_humanoid.language.words import is_unclear
from bt_humanoid.mission.loader import MissionLoader
from bt_humanoid.mission.schema import RecoverySettings
from bt_humanoid.mission.spec import MissionSpec, NodeSpec
from bt_humanoid.perception.grounding import resolve
from bt_humanoid.skills.params import named_objects
from bt_humanoid.skills.perception_skills import LOOK_AROUND

MAX_QUESTIONS = 3  # answers taken per command; still unclear after them, the question stands and nothing runs


@dataclass
class CommandOutcome:
    plan: Plan  # the last answer of the planner
    spec: MissionSpec | None  # the validated mission, when there is one to run
    seconds: float = 0.0  # wall time from text to validated mission (questions' answers included)


def look_around(stack: RobotStack) -> None:
    """Look left and right with the head (as ``find`` does), then turn once round on the spot: what a person
    does before answering "recycle all the cans", so that the planner knows what stands around the robot, not
    only in front of it. Real motion in physics (about 10 s of simulated time, the camera looking all the while);
    a robot without a panning head only looks once."""
    pan = stack.robot_config.head_pan
    stack.look()
    if pan is None or stack.perceiver is None:
        return
    turns = [{"move_joints": {"joints": {pan: angle}}} for angle in (*LOOK_AROUND[1:], 0.0)]
    turns.append({"rotate_in_place": {"angle": 360.0}})
    _run_steps(stack, "look around", turns)
    stack.look()


def plan_from_here(
    stack: RobotStack,
    text: str,
    answers: Callable[[str], str | None],
    planner: EmbeddedPlanner | LlmPlanner | None = None,
) -> CommandOutcome:
    """Plan ``text`` on ``stack`` as a person would answer it: one look first; when the answer depends on what
    is around ("recycle all the cans", "bring me a drink"), look around and plan again from what was seen."""
    stack.look()
    first = EmbeddedPlanner().plan(text, stack.planning_context())  # offline and quick, whatever plans after
    if first.involves_things():
        look_around(stack)
    if first.survey or EmbeddedPlanner().plan(text, stack.planning_context()).survey:
        survey(stack)  # "recycle all the cans": look at every surface before counting
    return plan_command(text, stack.planning_context(), answers, planner)


def survey(stack: RobotStack) -> None:
    """Go to each surface's place, nearest first, and look left, ahead and right there: for a request that
    counts things or takes every one of a kind, what the robot saw from afar is not enough."""
    pan = stack.robot_config.head_pan
    if pan is None or stack.perceiver is None or stack.navigator is None:
        return
    here = np.asarray(stack.robot.base.pose()[:2])
    places = sorted(
        {surface.place for surface in stack.world.surfaces.values()},
        key=lambda p: float(np.hypot(*(np.asarray(stack.world.places[p].pose[:2]) - here))),
    )
    steps: list[dict[str, Any]] = []
    for place in places:
        steps.append({"navigate": {"place": place}})
        steps += [{"move_joints": {"joints": {pan: angle}}} for angle in (*LOOK_AROUND[1:], 0.0)]
    _run_steps(stack, "look at every surface", steps)


def _run_steps(stack: RobotStack, name: str, steps: list[dict[str, Any]]) -> None:
    """Run a few steps on ``stack`` as a mission of their own (checked, with safety), before planning."""
    header = {"mission": name, "world": stack.world.name, "robot": stack.robot_config.name}
    spec = MissionLoader.for_plans().load_data({**header, "tree": {"sequence": steps}}, name=f"<{name}>")
    MissionRun(stack, spec).execute()


def make_planner(settings: LlmSettings | None) -> EmbeddedPlanner | LlmPlanner:
    """The embedded planner, or an LLM planner (falling back to the embedded one) when settings are given."""
    embedded = EmbeddedPlanner()
    if settings is None:
        return embedded
    from bt_humanoid.docs import reference

    catalogue = "\n".join(line for line in reference().splitlines() if line.startswith("| `"))
    return LlmPlanner(settings, catalogue, validate_planned_mission, fallback=embedded)


def validate_planned_mission(mission: dict[str, Any], context: PlanningContext) -> dict[str, Any]:
    """A planner's mission checked like a file and against what the robot believes; PlanRejected says what.

    The loader runs every skill's own checks (names, the map, joint ranges), inside behaviours too, as for a
    mission file; then each step is held to what only a planner is held to (``_belief_problems``).
    """
    mission = {**mission, "world": context.world.name, "robot": context.robot}
    try:
        spec = MissionLoader.for_plans().load_data(mission, name="<plan>")
    except UserError as error:
        raise PlanRejected(str(error)) from None
    for problem in _belief_problems(spec.tree, context):
        raise PlanRejected(problem)
    return mission


def _belief_problems(node: NodeSpec, context: PlanningContext, step: str | None = None) -> Iterator[str]:
    """What a plan asks that the skills' own checks allow but a planner must not: an object the robot has
    neither seen nor been told of (a description fits no object it knows: the model made it up), and a relative
    move longer than a planned step. Each names the plan step it is in."""
    step = node.where if node.where.startswith("<") else step  # the deepest node the plan itself wrote
    if node.category == "skill" and node.settings is not None:
        where = step or node.where
        for parameter, value in named_objects(node.settings, node.raw):
            if context.world.object_of(value) is not None:  # a world object, or one of a scene's ("coke 2")
                continue
            try:
                resolve(value, context.belief, context.robot_pose)
            except KeyError as error:
                names = ", ".join(context.world.objects)
                yield f"{where}: {node.kind}.{parameter}: unknown object {value!r} ({error.args[0]}); known: {names}"
        move = node.settings
        if node.kind == "move_base" and getattr(move, "relative", False) and abs(getattr(move, "x", 0) or 0) > MAX_STEP:
            yield f"{where}: a relative move of {move.x:g} m; at most {MAX_STEP:.0f} m (use navigate)"
    for child in [*node.children, *([node.alternative] if node.alternative else [])]:
        yield from _belief_problems(child, context, step)


def plan_command(
    text: str,
    context: PlanningContext,
    answers: Callable[[str], str | None],
    planner: EmbeddedPlanner | LlmPlanner | None = None,
) -> CommandOutcome:
    """Plan ``text``; each question goes to ``answers`` (None: no answer, the question stands).

    Speech the recogniser could not make out (``UNCLEAR`` in a transcript) is refused before any planner sees
    it: the robot does not guess at the words it did not know.
    """
    if is_unclear(text):
        return CommandOutcome(Plan("refusal", "I could not make out all the words. Please say it another way."), None)
    started = time.perf_counter()
    planner = planner or EmbeddedPlanner()
    plan = planner.plan(text, context)
    for _ in range(MAX_QUESTIONS):
        if plan.kind != "question" or plan.choice is None:
            break
        reply = answers(plan.say)
        if reply is None:
            break
        plan = planner.answer(plan.choice, reply, context)
    spec = None
    if plan.kind == "mission" and plan.mission is not None:
        spec = MissionLoader.for_plans().load_data(plan.mission, name="<command>")
    return CommandOutcome(plan, spec, time.perf_counter() - started)


def ask_before_giving_up(spec: MissionSpec) -> MissionSpec:
    """A planned mission, told to ask whether to try again when it has failed (someone is there to answer).

    The question goes on the root, named after the command: "I could not bring me the coffee mug: …". Lower
    nodes keep their own recovery; a safety stop is never asked about.
    """
    tree = spec.tree
    if tree.recovery is None or tree.recovery.ask is None:
        settings = tree.recovery.model_copy(update={"ask": True}) if tree.recovery else RecoverySettings(ask=True)
        tree.recovery = settings
    tree.name = tree.name or spec.header.mission
    return spec


class InteractiveSession:
    """Typed commands and answers, one after another, on one simulation: the robot keeps its place and belief.

    ``lines`` delivers what the person types (None when they are done). While a mission runs, a typed "stop"
    stops it at once, a line while the robot asks whether to try again answers that, and anything else typed
    meanwhile waits until the robot is free.
    """

    def __init__(
        self,
        stack: RobotStack,
        lines: queue.Queue[str | None],
        say: Callable[[str], None],
        planner: EmbeddedPlanner | LlmPlanner | None = None,
    ) -> None:
        self.stack = stack
        self.lines = lines
        self.say = say
        self.planner = planner or EmbeddedPlanner()
        self.pending: deque[str] = deque()
        self.questions = Questions(say)  # a recovery that asks whether to try again, while a mission runs
        stack.context.questions = self.questions
        stack.observers.append(self._listen_while_busy)
        self.mission: MissionRun | None = None  # the one running, or the last one
        self.results: list[Any] = []
        self.finished = False
        self.planner_asking = False  # the planner's question is out: the next line is its answer
        stack.look()

    def serve(self) -> None:
        """Take commands until the person is done; every mission runs to its end and the robot to rest."""
        try:
            while (text := self._next_line()) is not None:
                if text.strip():
                    self._command(text)
        finally:
            self.stack.close()

    def request_stop(self, reason: str) -> None:
        """Stop the mission that runs now, if one does."""
        if self.mission is not None:
            self.mission.request_stop(reason)

    def _command(self, text: str) -> None:
        outcome = plan_command(text, self.stack.planning_context(), self._ask, self.planner)
        plan = outcome.plan
        if plan.kind == "stop":
            self.say("I am not moving.")
            return
        if outcome.spec is None:
            self.say(plan.say)
            return
        self.say(plan.say)
        self.mission = MissionRun(self.stack, ask_before_giving_up(outcome.spec))
        result = self.mission.execute()
        self.results.append(result)
        if result.safety and result.safety.startswith("stop"):
            return  # it said that it stopped
        self.say("Done." if result.success else f"I could not finish: {result.cause or result.tree_status}.")

    @property
    def awaiting_answer(self) -> bool:
        """A question is out (the planner's, or a recovery's): the next line is its answer."""
        return self.planner_asking or self.questions.pending is not None

    def _ask(self, question: str) -> str | None:
        self.say(question)
        self.planner_asking = True
        try:
            return self._next_line()
        finally:
            self.planner_asking = False

    def _next_line(self) -> str | None:
        if self.pending:
            return self.pending.popleft()
        if self.finished:
            return None
        line = self.lines.get()
        self.finished = line is None
        return line

    def _listen_while_busy(self) -> None:
        """Between control steps: a typed "stop" stops the mission now; other lines wait their turn."""
        while True:
            try:
                line = self.lines.get_nowait()
            except queue.Empty:
                return
            if line is None:
                self.finished = True
                return
            if self.mission is not None and self.mission.stop_monitor.reason is None and is_stop(line):
                self.mission.request_stop("stop (typed)")
            elif self.questions.pending is not None:
                self.questions.answer(line)
            else:
                self.pending.append(line)


def relay_heard(
    blocks: Iterable[np.ndarray],
    listener: Listener,
    lines: queue.Queue[str | None],
    awaiting_answer: Callable[[], bool],
    show: Callable[[str, str], None],
) -> None:
    """Pass what the listener hears in ``blocks`` on as lines a person would type; None when the sound ends.

    A stop goes on at once. An utterance goes on when it starts with the wake word ("hey robot, …") or answers
    a question; anything else was not said to the robot. ``show(label, words)`` reports each.
    """
    for heard in heard_in(listener, blocks):
        transcript = heard.transcript
        if heard.kind == "stop":
            show("heard", heard.text)
            lines.put("stop")
        elif transcript.woken or awaiting_answer():
            show("heard", transcript.shown)
            lines.put(transcript.command)
        else:
            show(f"heard (no '{WAKE_WORD}', not for me)", heard.text)
    lines.put(None)
