"""Skills that move the arms and head through the whole-body controller: look_at, reach, give."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
from pydantic import Field, model_validator

from bt_humanoid.control.motion import MotionHandle
from bt_humanoid.control.whole_body import yaw_rotation
from bt_humanoid.skills.context import CheckContext
from bt_humanoid.skills.manipulation_skills import CARRY_TOLERANCE, Side, _ManipulationSkill
from bt_humanoid.skills.params import check_name, check_object
from bt_humanoid.skills.phased import PhaseFailure
from bt_humanoid.skills.registry import skill
from bt_humanoid.strict_model import StrictModel, exactly_one

GIVE_REACH = 0.5  # m ahead of the base, towards the person, where the hand holds the object out
GIVE_HEIGHT = 1.0  # m
# A giver lets go as the taker takes the load (Chan et al. 2012, "Grip forces and load forces in handovers"): the
# wrist's force sensor reads the person's pull towards themselves, or their lifting, against what it read holding
# the thing out still. Only those two count: a person's fingers closing round a mug push it back towards the robot
# by 4 N before they hold it, and a hand let go then dropped it (fetch episode 43).
SETTLE = 0.5  # s the held-out hand is read still before the pull is looked for
PULL_FOR = 0.15  # s the pull is felt for (its size is the gripper's ``taking_pull``, robot.yaml)
# m the fingers open by: off the thing (by 3 cm, a pad the person's pull pressed a cube against stayed on it, and the
# hand rising clear dragged the cube out of their fingers)
LOOSEN = 0.06
LIFT_CLEAR = 0.12  # m the empty hand rises, up out of the person's grip


class LookAtParams(StrictModel):
    object: str | None = Field(None, description="an object from the world model")
    point: tuple[float, float, float] | None = Field(None, description="[x, y, z] in the world (m)")

    @model_validator(mode="after")
    def _one_target(self) -> LookAtParams:
        exactly_one(self, "object", "point")
        return self


# an object no longer where it was seen is looked for again by the steps before (find), once
@skill("look_at", "turn the head so the camera looks at an object or a point", recovery={"replan": 1})
class LookAt(_ManipulationSkill):
    Params = LookAtParams

    @classmethod
    def check(cls, params: LookAtParams, context: CheckContext) -> list[tuple[str, str]]:
        return check_object(params.object, context.world)

    def phases(self):
        return [("look", self._look)]

    def _look(self) -> MotionHandle:
        p: LookAtParams = self.params
        point = self._object(p.object).position if p.object is not None else np.array(p.point)
        return self.context.robot.whole_body.look_at(point)


class ReachParams(StrictModel):
    position: tuple[float, float, float] = Field(description="[x, y, z] of the grip point (m)")
    yaw: float = Field(0.0, ge=-360, le=360, description="hand yaw (degrees), fingers pointing down")
    relative: bool = Field(False, description="position and yaw are in the base frame instead of the world")
    side: Side = Field("right", description="which hand")
    move_base: bool = Field(True, description="let the base help (it stays where it is if false)")


@skill("reach", "move a hand to a pose with the whole body (base, waist, arm, head looking at it)")
class Reach(_ManipulationSkill):
    Params = ReachParams

    def phases(self):
        return [("reach", self._reach)]

    def _reach(self) -> MotionHandle:
        p: ReachParams = self.params
        position, yaw = np.array(p.position, dtype=float), math.radians(p.yaw)
        if p.relative:
            x, y, base_yaw = self.context.robot.base.pose()
            position = np.array([x, y, 0.0]) + yaw_rotation(base_yaw) @ position
            yaw += base_yaw
        target = pin.SE3(yaw_rotation(yaw), position)
        return self.context.robot.whole_body.reach(p.side, target, gaze=position, move_base=p.move_base)


def taking_force(change: np.ndarray, hand_xy: np.ndarray, person_xy: np.ndarray) -> float:
    """N of a change in the wrist's force (world frame, x y z) that is a person at ``person_xy`` taking what the
    hand at ``hand_xy`` holds: the wrist holding it back against their pull towards themselves, and the weight
    they take off it. A push away from them, or sideways, is not taking (their fingers closing round a mug push
    it back at the robot)."""
    towards = np.asarray(person_xy, dtype=float) - np.asarray(hand_xy, dtype=float)
    towards /= max(float(np.linalg.norm(towards)), 1e-9)
    held_back = max(-float(change[:2] @ towards), 0.0)  # the wrist pulls away from them: they pull
    lifted = max(-float(change[2]), 0.0)  # the wrist holds up less: they hold up the rest
    return math.hypot(held_back, lifted)


class GiveParams(StrictModel):
    to: str = Field("person", description="a person of the world (name or alias)")
    side: Side = Field("right", description="the hand holding the object")
    timeout: float = Field(
        20.0, gt=0, le=120, description="s to wait for the person to take it (asked half-way); then it fails, held"
    )
    release_key: str = Field("release", description="blackboard key that, once true, means 'let go now'")


@skill("give", "hold the object out to a person; let go when they take it (felt at the wrist) or when asked")
class Give(_ManipulationSkill):
    """Hand the held object to a person. It is let go when the wrist's force sensor feels them take it (their pull,
    or their hand taking its weight), or when the blackboard's ``release_key`` says so; half-way through the
    timeout the robot asks them to take it, and at the end it fails still holding it: never dropped."""

    Params = GiveParams

    @classmethod
    def check(cls, params: GiveParams, context: CheckContext) -> list[tuple[str, str]]:
        return check_name(params.to, context.world.person_names, "to", "person")

    def phases(self):
        return [
            ("face the person", self._face),
            ("hold out", self._hold_out),
            ("wait", self._wait),
            ("let go", self._let_go),
            ("draw back", self._draw_back),
        ]

    def _face(self) -> MotionHandle:
        """Turn on the spot towards the person: the arm hands things over in front of the body."""
        self.held = self.context.world_model.held(self.params.side)
        if self.held is None:
            raise PhaseFailure(f"the {self.params.side} hand holds nothing to give")
        x, y, _ = self.context.robot.base.pose()
        person = self.context.world_model.person(self.params.to)
        heading = math.atan2(person[1] - y, person[0] - x)
        return self.context.robot.base.move_to(x, y, heading)

    def _hold_out(self) -> MotionHandle:
        x, y, _ = self.context.robot.base.pose()
        person = self.context.world_model.person(self.params.to)
        direction = person[:2] - np.array([x, y])
        heading = math.atan2(direction[1], direction[0])
        distance = float(np.linalg.norm(direction))
        reach = min(GIVE_REACH, max(distance - 0.3, 0.3))
        position = np.array([x + reach * math.cos(heading), y + reach * math.sin(heading), GIVE_HEIGHT])
        target = pin.SE3(yaw_rotation(heading), position)
        return self.context.robot.whole_body.reach(
            self.params.side, target, gaze=person, move_base=False, tolerance=CARRY_TOLERANCE
        )

    def _wait(self) -> MotionHandle:
        # no controller drives this wait: poll() settles the handle from the wrist, the blackboard and the clock
        self.wait_started = self.context.clock()
        self.still: list[np.ndarray] = []  # the wrist's readings while held out still: what no pull reads
        self.pulled_since: float | None = None
        self.asked = False
        return MotionHandle("holding it out")

    def poll(self):
        if self.phase == "wait" and self.motion is not None and not self.motion.done:
            self._watch_the_wait()
        return super().poll()

    def _watch_the_wait(self) -> None:
        p: GiveParams = self.params
        now = self.context.clock()
        waited = now - self.wait_started
        force = self.context.robot.wrist_force(p.side, in_world=True)
        if self.context.blackboard.values.get(p.release_key):
            self.motion.succeed("asked to let go")
            return
        if force is not None and waited < SETTLE:
            self.still.append(force)
        elif force is not None and self.still:
            taking = self._taking(force - np.mean(self.still, axis=0))
            if taking <= self.context.robot_config.grippers[p.side].taking_pull:
                self.pulled_since = None
            elif self.pulled_since is None:
                self.pulled_since = now
            if self.pulled_since is not None and now - self.pulled_since >= PULL_FOR:
                self.motion.succeed(f"{p.to} took it: the wrist felt {taking:.1f} N of pull and lift")
                return
        if waited > p.timeout:
            self.motion.fail(f"{p.to} did not take the {self.held.name} in {p.timeout:.0f} s; still holding it")
        elif waited > p.timeout / 2 and not self.asked:
            self.asked = True
            self.context.speak(f"Please take the {self.held.name}.")
        else:
            self.motion.feedback = f"holding it out for {waited:.0f} s"

    def _taking(self, change: np.ndarray) -> float:
        """N of a change in the wrist's force that is the person taking the thing (``taking_force``)."""
        hand = self.context.robot.whole_body.frame_pose(self.context.robot.whole_body.hand_frame(self.params.side))
        return taking_force(change, hand.translation[:2], self.context.world_model.person(self.params.to)[:2])

    def _let_go(self) -> MotionHandle:
        self.held.held_by = None
        self.held.confidence = 0.0  # handed over: no longer on any surface we know
        return self.context.robot.grippers.loosen(self.params.side, LOOSEN)

    def _draw_back(self) -> MotionHandle:
        """Up, out of the person's grip: the loosened fingers slide off what they now hold."""
        hand = self.context.robot.whole_body.frame_pose(self.context.robot_config.grippers[self.params.side].grip_site)
        target = pin.SE3(hand.rotation, hand.translation + np.array([0.0, 0.0, LIFT_CLEAR]))
        return self.context.robot.whole_body.reach(self.params.side, target, move_base=False, tolerance=CARRY_TOLERANCE)
