"""Decorators the compiler puts in trees: the Safety guard, the recovery steps, and a sim-time Timeout.

Each node of a mission is compiled as (outermost first)::

    safety            SafetyGuard: a violation halts the branch; never recovered
      ask             Ask: once all else failed, ask the person whether to try again (someone can answer)
        or else       OrElse: the node (with its retries), else its alternative
          replan      Replan (on a sequence): start the sequence over when a node below it that may replan failed
            retry     Retry: the same node again, ``backoff`` seconds apart
              faults  FaultWatch (on a skill): a branch monitor's fault halts the skill, which fails with its reason
                node

A step is left out when its setting is off, so the tree shows what will run (``bt-validate --expand``). Each
decorator does one thing in its ``update()``; the waiting ones (a retry's backoff, a question) hold their child
in ``tick()`` until their moment comes.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass

import py_trees
from py_trees.behaviour import Behaviour
from py_trees.common import Status

from bt_humanoid.language.questions import Answer, Questions
from bt_humanoid.safety.monitors import SafetySupervisor

#: (path of the node concerned, "retry" | "replan" | "ask" | "answer", what happens): the event log's entries
RecoveryLog = Callable[[str, str, str], None]


@dataclass(frozen=True)
class RecoverySteps:
    """A node's recovery, resolved by the compiler from the node, the mission, the skill and the robot."""

    retries: int = 0
    backoff: float = 0.5
    replan: int = 0
    ask: bool = False


def failure_reason(node: Behaviour) -> str:
    """The deepest feedback message along the failed branch under ``node`` (a skill's own words)."""
    reason = node.feedback_message
    for failed in failed_chain(node):
        reason = failed.feedback_message or reason
    return reason


def failed_chain(node: Behaviour) -> Iterator[Behaviour]:
    """The nodes below ``node`` along the branch whose failure failed it, from the top down."""
    while node.children:
        failed = [child for child in node.children if child.status is Status.FAILURE]
        if not failed:
            return
        node = failed[-1]  # a sequence stops at its failed child; a fallback fails after its last one
        yield node


class SafetyGuard(py_trees.decorators.Decorator):
    """Halts its branch and fails when the safety supervisor reports a violation.

    The check happens before the child is ticked, so nothing below a tripped guard runs another tick; halting
    the child cancels its motions.
    """

    def __init__(self, name: str, child: Behaviour, supervisor: SafetySupervisor) -> None:
        super().__init__(name=name, child=child)
        self.supervisor = supervisor

    def tick(self) -> Iterator[Behaviour]:
        violation = self.supervisor.violation
        if violation is None:
            yield from super().tick()
            return
        if self.decorated.status is Status.RUNNING:
            self.decorated.stop(Status.INVALID)
        self.feedback_message = f"safety: {violation.monitor}: {violation.message}"
        self.status = Status.FAILURE
        yield self

    def update(self) -> Status:
        return self.decorated.status


class FaultWatch(py_trees.decorators.Decorator):
    """Halts its skill when a branch monitor reports a fault that concerns it (an object dropped, a joint
    straining, no progress); the skill then fails with the monitor's reason, and the recovery above takes over.
    """

    def __init__(self, name: str, child: Behaviour, supervisor: SafetySupervisor) -> None:
        super().__init__(name=name, child=child)
        self.supervisor = supervisor

    def tick(self) -> Iterator[Behaviour]:
        skill = self.decorated
        fault = self.supervisor.fault_for(skill) if skill.status is Status.RUNNING else None
        if fault is None:
            yield from super().tick()
            return
        skill.stop(Status.INVALID)  # cancels its motion
        skill.status, skill.feedback_message = Status.FAILURE, f"{fault.monitor}: {fault.message}"
        self.feedback_message = skill.feedback_message
        self.stop(Status.FAILURE)
        yield self

    def update(self) -> Status:
        return self.decorated.status


class _Recovery(py_trees.decorators.Decorator):
    """What the recovery steps share: the node they concern, the clock, the supervisor and the event log.

    ``waiting_until`` (simulation time) holds the child without ticking it; a failure caused by a safety
    violation is never recovered.
    """

    def __init__(
        self, name: str, child: Behaviour, path: str, clock: Callable[[], float], supervisor: SafetySupervisor
    ) -> None:
        super().__init__(name=name, child=child)
        self.path = path
        self.clock = clock
        self.supervisor = supervisor
        self.log: RecoveryLog | None = None  # the event log's entry point, set by the compiler
        self.waiting_until: float | None = None

    def tick(self) -> Iterator[Behaviour]:
        if self.status is Status.RUNNING and self.waiting_until is not None:
            if self.clock() < self.waiting_until:
                yield self
                return
            self.waiting_until = None
        yield from super().tick()

    def initialise(self) -> None:
        self.waiting_until = None

    def recoverable(self) -> bool:
        """The child failed, and not because of a safety violation."""
        return self.decorated.status is Status.FAILURE and self.supervisor.violation is None

    def report(self, action: str, message: str) -> None:
        self.feedback_message = message
        if self.log is not None:
            self.log(self.path, action, message)


class Retry(_Recovery):
    """Runs the child again after it fails, up to ``retries`` times, ``backoff`` simulation seconds apart."""

    def __init__(self, child: Behaviour, path: str, retries: int, backoff: float, clock, supervisor) -> None:
        super().__init__(f"retry ×{retries}", child, path, clock, supervisor)
        self.retries, self.backoff = retries, backoff
        self.failures = 0

    def initialise(self) -> None:
        super().initialise()
        self.failures = 0

    def update(self) -> Status:
        if not self.recoverable() or self.failures >= self.retries:
            return self.decorated.status
        self.failures += 1
        self.waiting_until = self.clock() + self.backoff
        reason = failure_reason(self.decorated)
        self.report("retry", f"retry {self.failures}/{self.retries} in {self.backoff:.1f} s after: {reason}")
        return Status.RUNNING


@dataclass
class ReplanBudget:
    """How often a node may have the sequence above it start over; shared by that sequence's Replan (which
    spends it) and the node's Ask (which asks only once it is spent)."""

    node: str  # the node's path
    what: str  # how the robot names it
    limit: int
    used: int = 0
    sequence: str | None = None  # the path of the sequence that starts over; None: there is none above it

    @property
    def spent(self) -> bool:
        return self.sequence is None or self.used >= self.limit


class Replan(_Recovery):
    """Starts its sequence over when it failed because a node below it failed that may replan.

    The sequence watches its own children: the node whose failure failed it is found along the failed branch
    (the first there with a budget), and its budget is spent. Starting over means ``find`` looks again and
    stances, routes and grasps are planned anew from what the robot now believes.
    """

    def __init__(self, child: Behaviour, path: str, what: str, backoff: float, clock, supervisor) -> None:
        super().__init__("replan", child, path, clock, supervisor)
        self.what, self.backoff = what, backoff
        self.budgets: dict[int, ReplanBudget] = {}  # id(the node's outermost wrapper) → its budget

    def watch(self, wrapper: Behaviour, budget: ReplanBudget) -> None:
        self.budgets[id(wrapper)] = budget
        budget.sequence = self.path

    def initialise(self) -> None:
        super().initialise()
        for budget in self.budgets.values():
            budget.used = 0

    def update(self) -> Status:
        if not self.recoverable():
            return self.decorated.status
        failed = (self.budgets.get(id(node)) for node in failed_chain(self.decorated))
        budget = next((b for b in failed if b is not None), None)
        if budget is None or budget.spent:
            return Status.FAILURE
        budget.used += 1
        self.waiting_until = self.clock() + self.backoff
        reason = failure_reason(self.decorated)
        self.report("replan", f"replan {budget.used}/{budget.limit}: starting over after {budget.what}: {reason}")
        return Status.RUNNING


class Ask(_Recovery):
    """Once everything else has failed, asks whether to try again: yes starts the child afresh (its retries
    too), no fails it. Only when someone can answer (``questions``); otherwise the failure passes up."""

    def __init__(
        self,
        child: Behaviour,
        path: str,
        what: str,
        questions: Questions | None,
        replan: ReplanBudget | None,
        clock,
        supervisor,
    ) -> None:
        super().__init__("ask", child, path, clock, supervisor)
        self.what, self.questions, self.replan = what, questions, replan
        self.asking = False

    def initialise(self) -> None:
        super().initialise()
        self.asking = False

    def tick(self) -> Iterator[Behaviour]:
        if self.asking and self.questions is not None:
            answer = self.questions.take()
            if answer is None:
                yield self
                return
            self.asking = False
            self.report("answer", f"told {'' if answer is Answer.YES else 'not '}to try {self.what} again")
            if answer is Answer.NO:
                self.stop(Status.FAILURE)
                yield self
                return
            self.decorated.stop(Status.INVALID)  # afresh: the retries below start again too
        yield from super().tick()

    def update(self) -> Status:
        replanning = self.replan is not None and not self.replan.spent  # the sequence above starts over first
        if not self.recoverable() or self.questions is None or replanning:
            return self.decorated.status
        self.asking = True
        self.questions.ask(f"I could not {self.what}: {failure_reason(self.decorated)}. Shall I try again?")
        self.report("ask", f"asked whether to try {self.what} again")
        return Status.RUNNING

    def terminate(self, new_status: Status) -> None:
        if self.asking and new_status is Status.INVALID and self.questions is not None:
            self.questions.withdraw()  # halted while waiting for an answer: the question is moot
            self.asking = False


class OrElse(py_trees.composites.Selector):
    """The node (with its retries), or else its alternative once those failed: a fallback with memory."""

    def __init__(self, what: str, node: Behaviour, alternative: Behaviour) -> None:
        super().__init__(f"{what}, or else", memory=True, children=[node, alternative])


#: the decorators a node's recovery is made of, between its Safety guard and the node
RECOVERY_STEPS = (Ask, OrElse, Retry, Replan, FaultWatch)


class SimTimeout(py_trees.decorators.Decorator):
    """Fails and halts the child when it runs longer than ``seconds`` of simulation time."""

    def __init__(self, name: str, child: Behaviour, seconds: float, clock: Callable[[], float]) -> None:
        super().__init__(name=name, child=child)
        self.seconds = seconds
        self.clock = clock
        self.deadline = 0.0

    def initialise(self) -> None:
        self.deadline = self.clock() + self.seconds

    def update(self) -> Status:
        if self.decorated.status is Status.RUNNING and self.clock() >= self.deadline:
            self.feedback_message = f"timed out after {self.seconds:g} s"
            return Status.FAILURE
        return self.decorated.status
