"""Skills that locate things: find.

``find`` asks the WorldModel where an object is believed to be and turns the
head camera onto it. When the robot has a camera in the loop and does not
know the object yet, it looks ahead, left and right first. It fails with the
reason when it still does not know (searching other rooms comes next).
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

LOOK_AROUND = (0.0, 1.0, -1.0)  # head pan (rad) of each look when the object is not known yet


class FindParams(StrictModel):
    object: str = Field(description="the object to find (from the world model)")


@skill("find", "locate an object: recall where it is believed to be, or look around for it, and look at it")
class Find(_ManipulationSkill):
    Params = FindParams

    @classmethod
    def check(cls, params: FindParams, context: CheckContext) -> list[tuple[str, str]]:
        return check_name(params.object, context.world.objects, "object", "object")

    def phases(self):
        phases = [("recall", self._recall)]
        for angle in LOOK_AROUND:  # not known yet: look left, ahead and right with the head camera
            phases += [("look around", lambda a=angle: self._turn_head(a)), ("look around", self._look)]
        return [*phases, ("look at it", self._look_at_it)]

    def _recall(self) -> None:
        self.target = self._known()
        if self.target is None and self.context.perceiver is None:
            self.target = self._object(self.params.object)  # raises with the reason

    def _known(self):
        try:
            target = self.context.world_model.object(self.params.object)
        except KeyError as error:
            self.reason = error.args[0]
            return None
        if target.held_by is None and self.context.world_model.surface_under(target.position) is None:
            self.reason = f"the {target.name} is not on any surface I know"
            return None
        return target

    def _turn_head(self, angle: float) -> MotionHandle | None:
        if self.target is not None:
            return None
        pan = next((j for j in self.context.robot_config.groups.get("head", []) if "pan" in j), None)
        return self.context.robot.joints.move({pan: angle}) if pan else None

    def _look(self) -> None:
        if self.target is None:
            self.context.perceiver.look()
            self.target = self._known()

    def _look_at_it(self) -> MotionHandle | None:
        if self.target is None:
            raise PhaseFailure(f"{self.reason}; looked around from here")
        if self.target.held_by is not None:
            return None  # in hand: found
        return self.context.robot.whole_body.look_at(self.target.position)
