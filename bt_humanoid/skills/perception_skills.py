"""Skills that locate things: find.

``find`` asks the WorldModel where an object is believed to be and turns the
head camera onto it. A phrase that is not a name is grounded
(``perception/grounding.py``): "the cup on the counter" finds the mug, "the
cube" asks which one. When the robot has a camera in the loop and does not
know the object yet, it looks ahead, left and right first, then searches the
named places, nearest first, looking around at each. It fails with the
reason when it still does not know. The found object's id goes to the
blackboard (``remember_as``) for later leaves.
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import Field

from bt_humanoid.control.motion import MotionHandle
from bt_humanoid.perception.grounding import resolve
from bt_humanoid.skills.context import CheckContext
from bt_humanoid.skills.manipulation_skills import _ManipulationSkill
from bt_humanoid.skills.navigation_skills import at_a_surface, back_up, lower_empty_torso, tuck_empty_arms
from bt_humanoid.skills.params import check_object
from bt_humanoid.skills.phased import PhaseFailure
from bt_humanoid.skills.registry import skill
from bt_humanoid.strict_model import StrictModel

LOOK_AROUND = (0.0, 1.0, -1.0)  # head pan (rad) of each look when the object is not known yet
SEARCH_SPEED = 0.6  # m/s between places while searching
VIEW_NEAR = 1.0  # m from a place where a search may look from instead, when something stands on the place
STEP_BACK = 0.35  # m back from a surface before folding the arms to search


class FindParams(StrictModel):
    object: str = Field(description='a name ("red cube") or a phrase ("the cup on the counter", "something to drink")')
    remember_as: str = Field("found", description="blackboard key that gets the found object's id, for later leaves")
    search: bool = Field(True, description="if it is not in sight, go through the named places looking for it")


@skill("find", "locate an object: recall where it is believed to be, or look around for it, and look at it")
class Find(_ManipulationSkill):
    Params = FindParams

    @classmethod
    def check(cls, params: FindParams, context: CheckContext) -> list[tuple[str, str]]:
        return check_object(params.object, context.world)

    def phases(self):
        phases = [("recall", self._recall), *self._look_around("here")]
        if self.params.search and self.context.navigator is not None and self.context.perceiver is not None:
            # still not seen: fold the arms, go through the named places, nearest first, and look around at each
            here = self.context.robot.base.pose()[:2]

            def distance(item) -> float:
                return float(np.hypot(*(np.array(item[1].pose[:2]) - here)))

            phases += [
                ("step back to search", self._until_found(self._step_back)),
                ("fold the arms to search", self._until_found(lambda: tuck_empty_arms(self.context))),
                ("lower the torso", self._until_found(lambda: lower_empty_torso(self.context))),
            ]
            for name, place in sorted(self.context.world.places.items(), key=distance):
                phases += [(f"search the {name}", lambda p=place: self._go(p)), *self._look_around(name)]
        return [*phases, ("look at it", self._look_at_it)]

    def _until_found(self, action):
        """A search phase that does nothing once the object has been found."""
        return lambda: None if self.target is not None else action()

    def _step_back(self) -> MotionHandle | None:
        """Away from a table before folding the arms: a hand over it would hit it on the way down."""
        return back_up(self.context, STEP_BACK) if at_a_surface(self.context) else None

    def _look_around(self, where: str) -> list:
        label = f"look around {where}"
        phases = []
        for angle in LOOK_AROUND:  # look ahead, left and right with the head camera
            phases += [(label, lambda a=angle: self._turn_head(a)), (label, self._look)]
        return phases

    def _go(self, place) -> MotionHandle | None:
        if self.target is not None:
            return None
        x, y, yaw = place.pose
        goal = np.array([x, y, math.radians(yaw)])
        navigator = self.context.navigator
        # any spot near the place looks at it as well: one someone stands on (or a box was dropped on) is moved
        handle = navigator.go_to(goal, SEARCH_SPEED, choose_goal=lambda: navigator.free_pose_near(goal, VIEW_NEAR))
        return None if handle.done else handle  # a place it cannot reach is skipped

    def _recall(self) -> None:
        self.target = self._known()
        if self.target is None and self.context.perceiver is None:
            raise PhaseFailure(self.reason)  # no camera to look around with

    def _known(self):
        try:
            target = resolve(self.params.object, self.context.world_model, viewer=self.context.robot.base.pose())
        except KeyError as error:
            self.reason = error.args[0]
            return None
        if target.held_by is None and target.confidence <= 0.0:  # looked for where it was, and not there: search
            self.reason = f"I do not know where the {target.name} is now"
            return None
        if target.held_by is None and self.context.world_model.surface_under(target.position) is None:
            self.reason = f"the {target.name} is not on any surface I know"
            return None
        return target

    def _turn_head(self, angle: float) -> MotionHandle | None:
        if self.target is not None:
            return None
        pan = self.context.robot_config.head_pan
        return self.context.robot.joints.move({pan: angle}) if pan else None

    def _look(self) -> None:
        if self.target is None:
            self.context.perceiver.look()
            self.target = self._known()

    def _look_at_it(self) -> MotionHandle | None:
        if self.target is None:
            where = "here and in every place I know" if self.params.search and self.context.navigator else "from here"
            raise PhaseFailure(f"{self.reason}; looked around {where}")
        self.context.blackboard.set(self.params.remember_as, self.target.id)
        if self.target.held_by is not None or not self._within_head_turn(self.target.position):
            return None  # in hand, or behind the robot (remembered from an earlier look): found all the same
        return self.context.robot.whole_body.look_at(self.target.position)

    def _within_head_turn(self, point: np.ndarray) -> bool:
        x, y, yaw = self.context.robot.base.pose()
        bearing = math.remainder(math.atan2(point[1] - y, point[0] - x) - yaw, math.tau)
        pan = self.context.robot_config.head_pan
        low, high = self.context.joint_ranges[pan] if pan else (0.0, 0.0)
        return low <= bearing <= high
