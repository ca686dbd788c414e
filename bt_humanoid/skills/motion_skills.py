"""Skills that move the robot: base, joints, grippers."""

from __future__ import annotations

import math
from typing import Literal

from pydantic import Field, model_validator

from bt_humanoid.control.motion import MotionHandle
from bt_humanoid.skills.base import Skill
from bt_humanoid.skills.context import CheckContext
from bt_humanoid.skills.params import check_in_map, check_name
from bt_humanoid.skills.registry import skill
from bt_humanoid.strict_model import StrictModel, exactly_one


class MoveBaseParams(StrictModel):
    """Either a named place, or a pose (x, y, yaw) in the world or relative to the robot."""

    place: str | None = Field(None, description="named place to drive to; yaw, if given, overrides its heading")
    x: float | None = Field(None, ge=-100, le=100, description="metres; forward when relative")
    y: float | None = Field(None, ge=-100, le=100, description="metres; left when relative")
    yaw: float | None = Field(None, ge=-720, le=720, description="degrees; counter-clockwise; kept if omitted")
    relative: bool = Field(False, description="x, y and yaw are relative to the robot's current pose")
    max_speed: float | None = Field(None, gt=0, le=2.0, description="m/s cap, below the robot's and mission's limits")

    @model_validator(mode="after")
    def _place_or_pose(self) -> MoveBaseParams:
        if self.place is not None and (self.x is not None or self.y is not None or self.relative):
            raise ValueError("give either place or x/y, not both")
        if self.place is None and not self.relative and (self.x is None or self.y is None):
            raise ValueError("give a place, or both x and y (or relative: true)")
        if self.place is None and self.relative and self.x is None and self.y is None and self.yaw is None:
            raise ValueError("a relative move needs x, y or yaw")
        return self


# a drive held up (a protective stop, a bump) is worth one more go once the way may have cleared
@skill(
    "move_base",
    "drive the base to a named place or a pose, world or relative, with smooth limited velocities",
    recovery={"retries": 1, "backoff": 1.0},
)
class MoveBase(Skill):
    Params = MoveBaseParams
    settles = True

    @classmethod
    def check(cls, params: MoveBaseParams, context: CheckContext) -> list[tuple[str, str]]:
        problems = check_name(params.place, context.world.places, "place", "place")
        if not params.relative and params.x is not None and params.y is not None:
            problems += check_in_map((params.x, params.y), context.world, "x, y")
        return problems

    def start(self) -> MotionHandle:
        p: MoveBaseParams = self.params
        x0, y0, yaw0 = self.context.robot.base.pose()
        if p.place is not None:
            x, y, yaw_deg = self.context.world.place(p.place).pose
            yaw = math.radians(p.yaw if p.yaw is not None else yaw_deg)
        elif p.relative:
            dx, dy = p.x or 0.0, p.y or 0.0
            x = x0 + dx * math.cos(yaw0) - dy * math.sin(yaw0)
            y = y0 + dx * math.sin(yaw0) + dy * math.cos(yaw0)
            yaw = yaw0 + math.radians(p.yaw or 0.0)
        else:
            x, y = p.x, p.y
            yaw = math.radians(p.yaw) if p.yaw is not None else yaw0
        outside = self.context.world.outside_map(round(x, 2), round(y, 2))
        if outside is not None:  # a relative move from here would leave the map: refuse before moving
            raise ValueError(f"the goal {outside}")
        return self.context.robot.base.move_to(x, y, yaw, max_speed=p.max_speed)


class MoveJointsParams(StrictModel):
    posture: str | None = Field(None, description="a named posture from robot.yaml")
    joints: dict[str, float] | None = Field(None, description="joint name → position (rad, or m for fingers)")
    speed: float = Field(1.0, gt=0, le=1.0, description="fraction of the joints' velocity and acceleration limits")

    @model_validator(mode="after")
    def _one_target(self) -> MoveJointsParams:
        exactly_one(self, "posture", "joints")
        return self


@skill("move_joints", "move joints to a named posture or to joint positions along jerk-limited trajectories")
class MoveJoints(Skill):
    Params = MoveJointsParams
    settles = True

    @classmethod
    def check(cls, params: MoveJointsParams, context: CheckContext) -> list[tuple[str, str]]:
        config = context.robot_config
        problems = check_name(params.posture, config.postures, "posture", "posture")
        for joint, value in (params.joints or {}).items():
            unknown = check_name(joint, config.actuated_joints, "joints", "joint")
            if unknown:
                problems += unknown
                continue
            low, high = context.joint_ranges[joint]
            if not low <= value <= high:
                problems.append(("joints", f"{joint}={value} is outside its range [{low:.2f}, {high:.2f}]"))
        return problems

    def start(self) -> MotionHandle:
        p: MoveJointsParams = self.params
        targets = self.context.robot_config.postures[p.posture] if p.posture is not None else p.joints
        return self.context.robot.joints.move(dict(targets), speed_scale=p.speed)


class GripperParams(StrictModel):
    action: Literal["open", "close"] = Field(description="open the jaws, or close until they stall on something")
    side: Literal["left", "right"] = Field("right", description="which hand")


@skill("gripper", "open a gripper, or close it until it holds something or shuts")
class Gripper(Skill):
    Params = GripperParams
    settles = True

    def start(self) -> MotionHandle:
        return self.context.robot.grippers.command(self.params.side, self.params.action)

    def poll(self):
        status = super().poll()
        if self.motion is not None and self.motion.done and self.params.action == "close":
            grippers = self.context.robot.grippers
            held = grippers.holding(self.params.side)
            self.feedback_message = (
                f"holding something {grippers.width(self.params.side) * 100:.1f} cm wide" if held else "closed, empty"
            )
        return status
