"""Skills that locate things: find.

``find`` asks the WorldModel where an object is believed to be and turns the
head camera onto it. It fails when the belief is gone (the object slipped
away or was never known), so recovery can react. The RGB-D pipeline of the
perception issue will confirm the object in the image and search when the
belief is stale; callers and behaviours stay the same.
"""

from __future__ import annotations

from pydantic import Field

from bt_humanoid.control.motion import MotionHandle
from bt_humanoid.skills.context import CheckContext
from bt_humanoid.skills.manipulation_skills import _ManipulationSkill
from bt_humanoid.skills.params import check_name
from bt_humanoid.skills.phased import PhaseFailure
from bt_humanoid.skills.registry import skill
from bt_humanoid.strict_model import StrictModel


class FindParams(StrictModel):
    object: str = Field(description="the object to find (from the world model)")


@skill("find", "locate an object: recall where it is believed to be and look at it")
class Find(_ManipulationSkill):
    Params = FindParams

    @classmethod
    def check(cls, params: FindParams, context: CheckContext) -> list[tuple[str, str]]:
        return check_name(params.object, context.world.objects, "object", "object")

    def phases(self):
        return [("recall", self._recall), ("look", self._look)]

    def _recall(self) -> None:
        self.target = self._object(self.params.object)
        if self.target.held_by is not None:
            return
        if self.target.confidence <= 0.0:
            raise PhaseFailure(f"I do not know where the {self.target.name} is now")
        if self.context.world_model.surface_under(self.target.position) is None:
            raise PhaseFailure(f"the {self.target.name} is not on any surface I know")

    def _look(self) -> MotionHandle | None:
        if self.target.held_by is not None:
            return None  # in hand: found
        return self.context.robot.whole_body.look_at(self.target.position)
