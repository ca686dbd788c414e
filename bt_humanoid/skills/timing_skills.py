"""Skills about time."""

from __future__ import annotations

from py_trees.common import Status
from pydantic import Field

from bt_humanoid.skills.base import Skill
from bt_humanoid.skills.registry import skill
from bt_humanoid.strict_model import StrictModel


class WaitParams(StrictModel):
    seconds: float = Field(ge=0, le=3600, description="simulation seconds to wait")


@skill("wait", "wait a number of simulation seconds")
class Wait(Skill):
    Params = WaitParams

    def start(self) -> None:
        self.until = self.context.clock() + self.params.seconds

    def poll(self) -> Status:
        remaining = self.until - self.context.clock()
        if remaining <= 1e-9:
            self.feedback_message = "waited"
            return Status.SUCCESS
        self.feedback_message = f"{remaining:.1f} s left"
        return Status.RUNNING
