"""Skills made of phases run one after another (pre-grasp, descend, close, lift, ...).

Each phase sends a goal and returns its handle (or None when it is done at
once); the skill moves on when the handle succeeds and fails with the phase
named when it fails, so the event log says exactly what went wrong where.
"""

from __future__ import annotations

from collections.abc import Callable

from py_trees.common import Status

from bt_humanoid.control.motion import MotionHandle, MotionStatus
from bt_humanoid.perception.grounding import resolve
from bt_humanoid.perception.world_model import SupportSurface, TrackedObject
from bt_humanoid.skills.base import Skill

Phase = tuple[str, Callable[[], MotionHandle | None]]


class PhaseFailure(ValueError):
    """Raised by a phase that finds it cannot go on (nothing grasped, object slipped)."""


class PhasedSkill(Skill):
    """Runs ``phases()`` in order; feedback is "phase: progress"."""

    settles = True

    def phases(self) -> list[Phase]:
        raise NotImplementedError

    def start(self) -> MotionHandle | None:
        self._phases = self.phases()
        self._index = -1
        self._phase_failure: str | None = None
        return self._next()

    def _next(self) -> MotionHandle | None:
        while self._index + 1 < len(self._phases):
            self._index += 1
            name, begin = self._phases[self._index]
            try:
                handle = begin()
            except PhaseFailure as failure:
                self._phase_failure = f"{name}: {failure}"
                return None
            if handle is not None:
                return handle
        return None

    @property
    def phase(self) -> str:
        return self._phases[self._index][0] if 0 <= self._index < len(self._phases) else "done"

    def poll(self) -> Status:
        while True:
            if self._phase_failure is not None:
                self.feedback_message = self._phase_failure
                return Status.FAILURE
            if self.motion is None:
                self.feedback_message = "done"
                return Status.SUCCESS
            if self.motion.status is MotionStatus.RUNNING:
                self.feedback_message = f"{self.phase}: {self.motion.feedback}"
                return Status.RUNNING
            if self.motion.status is not MotionStatus.SUCCEEDED and not self.settle_for(self.motion):
                self.feedback_message = f"{self.phase}: {self.motion.result}"
                self.on_failure()
                return Status.FAILURE
            self.motion = self._next()

    def _object(self, phrase: str) -> TrackedObject:
        """The object a name, an id or a phrase means in the robot's belief; a phase failure that says why if none.

        An object looked for where it was believed to be, and not seen there, is gone: acting on it would grasp air.
        """
        try:
            target = resolve(phrase, self.context.world_model, viewer=self.context.robot.base.pose())
        except KeyError as error:
            raise PhaseFailure(error.args[0]) from None
        if target.confidence <= 0.0 and target.held_by is None:
            raise PhaseFailure(f"the {target.name} is no longer where I saw it")
        return target

    def _surface(self, name: str) -> SupportSurface:
        try:
            return self.context.world_model.surface(name)
        except KeyError as error:
            raise PhaseFailure(error.args[0]) from None

    def settle_for(self, motion: MotionHandle) -> bool:
        """Whether the current phase may go on from where its failed ``motion`` left the robot (a reach that
        stopped short, but near enough for what comes next); by default it may not."""
        return False

    def on_failure(self) -> None:
        """Called once when a phase's motion fails; leave the robot safe (e.g. open an empty gripper)."""
