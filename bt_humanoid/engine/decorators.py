"""Decorators the compiler puts in trees: Safety guard, Recovery policy, and a sim-time Timeout."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import py_trees
from py_trees.behaviour import Behaviour
from py_trees.common import Status

from bt_humanoid.safety.monitors import SafetySupervisor


class SafetyGuard(py_trees.decorators.Decorator):
    """Halts its branch and fails when the safety supervisor reports a violation.

    The check happens before the child is ticked, so nothing below a tripped
    guard runs another tick; halting the child cancels its motions.
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


class RecoveryPolicy(py_trees.decorators.Decorator):
    """Retries a failed child up to ``retries`` times, ``backoff`` simulation seconds apart.

    A failure caused by a safety violation is never retried.
    """

    def __init__(
        self,
        name: str,
        child: Behaviour,
        retries: int,
        backoff: float,
        clock: Callable[[], float],
        supervisor: SafetySupervisor,
        on_retry: Callable[[RecoveryPolicy], None] | None = None,
    ) -> None:
        super().__init__(name=name, child=child)
        self.on_retry = on_retry
        self.retries = retries
        self.backoff = backoff
        self.clock = clock
        self.supervisor = supervisor
        self.failures = 0
        self.resume_at: float | None = None

    def initialise(self) -> None:
        self.failures = 0
        self.resume_at = None

    def tick(self) -> Iterator[Behaviour]:
        if self.status is not Status.RUNNING:
            self.initialise()
        if self.resume_at is not None and self.clock() < self.resume_at:
            self.status = Status.RUNNING
            yield self
            return
        self.resume_at = None
        yield from self.decorated.tick()
        self.status = self.update()
        if self.status is not Status.RUNNING:
            self.stop(self.status)
        yield self

    def update(self) -> Status:
        status = self.decorated.status
        if status is not Status.FAILURE:
            return status
        if self.supervisor.violation is not None or self.failures >= self.retries:
            return Status.FAILURE
        self.failures += 1
        self.resume_at = self.clock() + self.backoff
        self.feedback_message = (
            f"retry {self.failures}/{self.retries} in {self.backoff:.1f} s after: {self.decorated.feedback_message}"
        )
        if self.on_retry is not None:
            self.on_retry(self)
        return Status.RUNNING


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
