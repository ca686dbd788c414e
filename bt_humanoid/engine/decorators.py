"""Decorators the compiler puts in trees: Safety guard, Recovery policy, and a sim-time Timeout."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass

import py_trees
from py_trees.behaviour import Behaviour
from py_trees.common import Status

from bt_humanoid.language.questions import Answer, Questions
from bt_humanoid.safety.monitors import SafetySupervisor


class SafetyGuard(py_trees.decorators.Decorator):
    """Halts its branch and fails when the safety supervisor reports a violation.

    The check happens before the child is ticked, so nothing below a tripped
    guard runs another tick; halting the child cancels its motions. The guard
    of a leaf (``leaf=True``) also halts it on a branch fault that concerns it
    (an object dropped, a joint straining, no progress): the leaf then fails
    with the monitor's reason and its recovery policy takes over.
    """

    def __init__(self, name: str, child: Behaviour, supervisor: SafetySupervisor, leaf: bool = False) -> None:
        super().__init__(name=name, child=child)
        self.supervisor = supervisor
        self.leaf = leaf

    def tick(self) -> Iterator[Behaviour]:
        violation = self.supervisor.violation
        if violation is None:
            policy = self.decorated
            if self.leaf and isinstance(policy, RecoveryPolicy) and policy.decorated.status is Status.RUNNING:
                fault = self.supervisor.fault_for(policy.decorated)
                if fault is not None:
                    policy.interrupt(f"{fault.monitor}: {fault.message}")
            yield from super().tick()
            return
        if self.decorated.status is Status.RUNNING:
            self.decorated.stop(Status.INVALID)
        self.feedback_message = f"safety: {violation.monitor}: {violation.message}"
        self.status = Status.FAILURE
        yield self

    def update(self) -> Status:
        return self.decorated.status


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
    while node.children:
        failed = [child for child in node.children if child.status is Status.FAILURE]
        if not failed:
            break
        node = failed[-1]
        reason = node.feedback_message or reason
    return reason


class RecoveryPolicy(py_trees.decorators.Decorator):
    """What happens after the child fails, in this order:

    1. **retry**: run it again, up to ``retries`` times, ``backoff`` simulation seconds apart;
    2. **replan**: fail, and have the enclosing sequence (``replan_target``, set by the compiler) start over
       from its first step, up to ``replan`` times: perception looks again, routes and grasps are planned anew
       from what the robot now believes;
    3. **ask**: ask the person whether to try again (only when someone can answer); yes starts the child
       afresh, no fails.

    An alternative behaviour is structure the compiler builds around the child (a fallback), not a step here.
    A failure caused by a safety violation is never recovered.
    """

    def __init__(
        self,
        name: str,
        child: Behaviour,
        steps: RecoverySteps,
        clock: Callable[[], float],
        supervisor: SafetySupervisor,
        questions: Questions | None = None,
        on_recovery: Callable[[RecoveryPolicy, str], None] | None = None,
        what: str = "",
    ) -> None:
        super().__init__(name=name, child=child)
        self.steps = steps
        self.clock = clock
        self.supervisor = supervisor
        self.questions = questions
        self.on_recovery = on_recovery
        self.what = what or child.name
        self.replan_target: RecoveryPolicy | None = None
        self.failures = 0
        self.resume_at: float | None = None
        self.replans_done: dict[int, int] = {}  # per node below that asked: restarts made for it
        self.replan_request: tuple[RecoveryPolicy, float] | None = None  # (who, when)
        self.asking = False
        self.interrupted = False

    @property
    def retries(self) -> int:
        return self.steps.retries

    def initialise(self) -> None:
        self.failures = 0
        self.resume_at = None
        self.replans_done = {}
        self.replan_request = None
        self.asking = False

    def tick(self) -> Iterator[Behaviour]:
        if self.status is not Status.RUNNING:
            self.initialise()
        if self.asking:
            answer = self._answer()
            if answer is None:
                self.status = Status.RUNNING
                yield self
                return
            if answer is Answer.NO:
                self.stop(Status.FAILURE)
                yield self
                return
        if self.resume_at is not None and self.clock() < self.resume_at:
            self.status = Status.RUNNING
            yield self
            return
        self.resume_at = None
        if self.interrupted:  # its guard halted the child for a fault: recover from that failure
            self.interrupted = False
        else:
            yield from self.decorated.tick()
        self.status = self.update()
        if self.status is not Status.RUNNING:
            self.stop(self.status)
        yield self

    def update(self) -> Status:
        status = self.decorated.status
        if status is not Status.FAILURE:
            return status
        if self.supervisor.violation is not None:
            return Status.FAILURE
        reason = failure_reason(self.decorated)
        if self.failures < self.steps.retries:
            self.failures += 1
            self.resume_at = self.clock() + self.steps.backoff
            self._report(
                "retry", f"retry {self.failures}/{self.steps.retries} in {self.steps.backoff:.1f} s after: {reason}"
            )
            return Status.RUNNING
        request, self.replan_request = self.replan_request, None
        if request is not None and request[1] == self.clock():  # a node below failed this tick and asked
            asker = request[0]
            done = self.replans_done.get(id(asker), 0) + 1
            self.replans_done[id(asker)] = done
            self.resume_at = self.clock() + self.steps.backoff
            self._report("replan", f"replan {done}/{asker.steps.replan}: starting over after {asker.what}: {reason}")
            return Status.RUNNING
        target = self.replan_target
        if target is not None and target.replans_done.get(id(self), 0) < self.steps.replan:
            target.replan_request = (self, self.clock())
            self.feedback_message = f"failed, asking {target.what} to start over: {reason}"
            return Status.FAILURE
        if self.steps.ask and self.questions is not None:
            self.asking = True
            self.questions.ask(f"I could not {self.what}: {reason}. Shall I try again?")
            self._report("ask", f"asked whether to try {self.what} again")
            return Status.RUNNING
        return Status.FAILURE

    def interrupt(self, reason: str) -> None:
        """Halt the running child (cancelling its motion); it fails with ``reason`` at this tick."""
        child = self.decorated
        child.stop(Status.INVALID)
        child.status, child.feedback_message = Status.FAILURE, reason
        self.interrupted = True

    def _answer(self) -> Answer | None:
        """The person's answer once given; yes starts the child afresh."""
        assert self.questions is not None
        answer = self.questions.take()
        if answer is None:
            return None
        self.asking = False
        self.failures = 0
        self._report("answer", f"told {'' if answer is Answer.YES else 'not '}to try {self.what} again")
        return answer

    def _report(self, action: str, message: str) -> None:
        self.feedback_message = message
        if self.on_recovery is not None:
            self.on_recovery(self, action)

    def terminate(self, new_status: Status) -> None:
        if self.asking and new_status is Status.INVALID and self.questions is not None:
            self.questions.withdraw()  # halted while waiting for an answer: the question is moot
            self.asking = False


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
