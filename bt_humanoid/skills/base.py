"""Base class of every leaf skill: goals in initialise(), polling in update(), cancel in terminate()."""

from __future__ import annotations

from typing import Any, ClassVar

import py_trees
from py_trees.common import Status
from pydantic import BaseModel, ValidationError

from bt_humanoid.control.motion import REST_SPEED, MotionHandle, MotionStatus
from bt_humanoid.errors import describe_validation_error
from bt_humanoid.skills.context import CheckContext, SkillContext
from bt_humanoid.skills.params import resolve_references

SETTLE_LIMIT = 1.5  # s a moving skill waits, once its motion has ended, for the robot to come to rest


class Skill(py_trees.behaviour.Behaviour):
    """A non-blocking leaf.

    Subclasses define ``Params`` (a pydantic model), ``start()`` (send the goal,
    may return a MotionHandle to poll) and optionally ``poll()`` and ``check()``.
    Parameters may reference blackboard values as ``"$key"``; they are resolved
    and validated when the leaf starts.
    """

    Params: ClassVar[type[BaseModel]]
    skill_name: ClassVar[str] = ""
    #: branch monitors whose faults this skill notices and handles itself (its guard leaves it running)
    handles_faults: ClassVar[frozenset[str]] = frozenset()
    #: a skill that moves the robot succeeds once the robot has come to rest (up to SETTLE_LIMIT after its
    #: motion ended): a tree never reports done while an arm still swings or the base still rolls
    settles: ClassVar[bool] = False

    def __init__(self, name: str, raw_params: dict[str, Any], context: SkillContext, path: str) -> None:
        super().__init__(name=name)
        self.raw_params = raw_params
        self.context = context
        self.path = path
        self.params: Any = None
        self.motion: MotionHandle | None = None
        self.error: str | None = None
        self.done_at: float | None = None  # when the motion ended, while the robot settles

    @classmethod
    def check(cls, params: BaseModel, context: CheckContext) -> list[tuple[str, str]]:
        """Compile-time checks against the robot and world: (parameter, message) pairs."""
        return []

    def start(self) -> MotionHandle | None:
        """Send the goal. Return a handle when there is a motion to poll."""
        return None

    def poll(self) -> Status:
        """Progress of the goal; the default follows the motion handle."""
        if self.motion is None:
            return Status.SUCCESS
        self.feedback_message = self.motion.feedback
        if self.motion.status is MotionStatus.RUNNING:
            return Status.RUNNING
        self.feedback_message = self.motion.result
        return Status.SUCCESS if self.motion.status is MotionStatus.SUCCEEDED else Status.FAILURE

    # py_trees hooks -------------------------------------------------------

    def initialise(self) -> None:
        self.error, self.motion, self.done_at = None, None, None
        try:
            resolved = resolve_references(self.raw_params, self.context.blackboard)
            self.params = self.Params.model_validate(resolved)
        except KeyError as missing:
            self.error = f"{self.path}: blackboard has no {missing.args[0]!r}"
            return
        except ValidationError as error:
            self.error = f"{self.path}: {describe_validation_error(error)[1]}"
            return
        try:
            self.motion = self.start()
        except ValueError as error:
            self.error = f"{self.path}: {error}"

    def update(self) -> Status:
        if self.error is not None:
            self.feedback_message = self.error
            return Status.FAILURE
        status = self.poll()
        if status is not Status.SUCCESS or not self.settles:
            return status
        now = self.context.clock()
        self.done_at = now if self.done_at is None else self.done_at
        if self.context.robot.max_speed() >= REST_SPEED and now - self.done_at < SETTLE_LIMIT:
            self.feedback_message = "settling"
            return Status.RUNNING
        return status

    def terminate(self, new_status: Status) -> None:
        # halted while running (pre-empted, stopped, timed out): brake what this leaf started
        if new_status is Status.INVALID and self.motion is not None and not self.motion.done:
            self.motion.cancel()
            self.feedback_message = "halted"
