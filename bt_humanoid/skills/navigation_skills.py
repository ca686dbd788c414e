"""Skills that move the base with the navigation stack: navigate_to, turn, rotate_in_place, back_up, clear_map.

``navigate_to`` plans around what the map knows (furniture from the scene,
obstacles the depth camera saw) and replans when the way ahead gets blocked.
The others are the small moves that recovery is made of (Nav2's spin, back
up, clear costmap); behaviors/navigate.yaml composes them.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from pydantic import Field, model_validator

from bt_humanoid.control.motion import MotionHandle
from bt_humanoid.control.stance import StanceError, working_stances
from bt_humanoid.skills.context import CheckContext, SkillContext
from bt_humanoid.skills.manipulation_skills import TUCKED_POSTURE, lift_what_is_held
from bt_humanoid.skills.params import check_in_map, check_name, check_object
from bt_humanoid.skills.phased import PhasedSkill, PhaseFailure
from bt_humanoid.skills.registry import skill
from bt_humanoid.strict_model import StrictModel, exactly_one

LOOK_AHEAD_POSTURE = "look_ahead"  # robot.yaml posture: head level, camera on the way ahead
OBJECT_STANDOFF = 0.35  # m between the footprint and an object on the floor
PERSON_STANDOFF = 0.6  # m between the footprint and a person: arm's length, to hand things over
FACING_TURNS = 120  # degrees either side of the robot's own direction where a pose facing someone may be
FACING_EXTRA = 0.15  # m further off, when no pose at arm's length leaves the base room
STANCE_BACKOFF = 0.35  # m behind the stance for working on an object on a surface
STANCE_ASIDE = (0.2, -0.2, 0.4, -0.4)  # m to the left along the edge, where something stands behind the stance
BACK_UP_SPEED = 0.2  # m/s


class _BaseSkill(PhasedSkill):
    def _navigator(self):
        if self.context.navigator is None:
            raise PhaseFailure("this robot has no navigation stack")
        return self.context.navigator

    def _look_ahead(self) -> MotionHandle | None:
        posture = self.context.robot_config.postures.get(LOOK_AHEAD_POSTURE)
        return self.context.robot.joints.move(dict(posture)) if posture else None

    def _tuck_arms(self) -> MotionHandle | None:
        return tuck_empty_arms(self.context)

    def _lift_load(self) -> MotionHandle | None:
        return lift_what_is_held(self.context)

    def _lower_torso(self) -> MotionHandle | None:
        return lower_empty_torso(self.context)


def tuck_empty_arms(context: SkillContext) -> MotionHandle | None:
    """Fold every empty arm inside the footprint (an arm that carries something keeps its carry pose).

    The torso keeps its height meanwhile: lowering it with a hand still over a table would push the hand into it.
    """
    config = context.robot_config
    tucked = config.postures.get(TUCKED_POSTURE, {})
    joints = {
        j: tucked[j]
        for side in config.grippers
        if context.world_model.held(side) is None
        for j in config.groups.get(f"{side}_arm", [])
        if j in tucked
    }
    return context.robot.joints.move(joints) if joints else None


def lower_empty_torso(context: SkillContext) -> MotionHandle | None:
    """Bring the torso lift down once the arms are folded, unless a hand holds something up."""
    if context.world_model.held_any():
        return None
    joints = {j: 0.0 for j in context.robot_config.groups.get("lift", [])}
    return context.robot.joints.move(joints) if joints else None


def _places_and_objects(params: NavigateToParams | TurnParams, context: CheckContext) -> list[tuple[str, str]]:
    """The named place, object and person of a base skill's parameters exist in the world; a pose is on the map."""
    problems = check_name(params.place, context.world.places, "place", "place")
    problems += check_object(params.object, context.world)
    if isinstance(params, NavigateToParams):
        problems += check_name(params.person, context.world.person_names, "person", "person")
        problems += check_in_map(params.pose[:2] if params.pose else None, context.world, "pose")
    return problems


class NavigateToParams(StrictModel):
    place: str | None = Field(None, description="a named place of the world")
    object: str | None = Field(None, description="an object: a stand-off pose facing it (from the world model)")
    pose: tuple[float, float, float] | None = Field(None, description="[x, y, yaw_deg] in the world")
    person: str | None = Field(None, description="a person (name or alias): arm's length from them, facing them")
    max_speed: float | None = Field(None, gt=0, le=2.0, description="m/s cap, below the robot's and mission's limits")

    @model_validator(mode="after")
    def _one_goal(self) -> NavigateToParams:
        exactly_one(self, "place", "object", "pose", "person")
        return self


@skill(
    "navigate_to",
    "plan a route around obstacles to a place, an object, a person or a pose, follow it, replan if blocked",
)
class NavigateTo(_BaseSkill):
    Params = NavigateToParams

    @classmethod
    def check(cls, params: NavigateToParams, context: CheckContext) -> list[tuple[str, str]]:
        return _places_and_objects(params, context)

    def phases(self):
        return [
            ("look ahead", self._look_ahead),
            ("tuck the arms", self._tuck_arms),
            ("lower the torso", self._lower_torso),
            ("lift what is held", self._lift_load),
            ("navigate", self._navigate),
        ]

    def _navigate(self) -> MotionHandle:
        navigator = self._navigator()
        goal, what = self._goal()
        handle = navigator.go_to(goal, self.params.max_speed, choose_goal=lambda: self._goal_again(goal))
        if handle.done and handle.result:
            raise PhaseFailure(f"{what}: {handle.result}")
        self.what = what
        return handle

    def poll(self):
        status = super().poll()
        if status.name == "FAILURE" and hasattr(self, "what") and self.what not in self.feedback_message:
            self.feedback_message = f"{self.feedback_message} (going to {self.what})"
        return status

    def _goal(self) -> tuple[np.ndarray, str]:
        p: NavigateToParams = self.params
        if p.place is not None:
            x, y, yaw = self.context.world.place(p.place).pose
            return np.array([x, y, math.radians(yaw)]), f"place '{p.place}'"
        if p.pose is not None:
            x, y, yaw = p.pose
            return np.array([x, y, math.radians(yaw)]), f"pose ({x:.2f}, {y:.2f}, {yaw:.0f}°)"
        if p.person is not None:
            return self._facing(self._person(p.person), PERSON_STANDOFF), f"the {p.person}"
        return self._standoff(p.object), f"the {p.object}"

    def _goal_again(self, goal: np.ndarray) -> np.ndarray:
        """The goal chosen on the navigator's map as it is now (``goal`` where it can no longer be chosen)."""
        try:
            return self._goal()[0]
        except PhaseFailure:
            return goal

    def _person(self, name: str) -> np.ndarray:
        try:
            return self.context.world_model.person(name)
        except KeyError as error:
            raise PhaseFailure(error.args[0]) from None

    def _facing(self, position: np.ndarray, standoff: float) -> np.ndarray:
        """A pose ``standoff`` from the footprint's edge to ``position``, facing it: on the robot's side, or as
        near that side as leaves the base room (a person by a wall or a chair is met from the open side)."""
        here = self.context.robot.base.pose()
        away = here[:2] - position[:2]
        towards_robot = math.atan2(away[1], away[0])
        distance = self.context.robot_config.base.footprint_radius + standoff
        turns = np.radians(sorted(range(-FACING_TURNS, FACING_TURNS + 1, 15), key=abs))
        angles = np.concatenate([towards_robot + turns] * 2)
        radii = np.repeat([distance, distance + FACING_EXTRA], len(turns))
        xy = position[:2] + radii[:, None] * np.column_stack([np.cos(angles), np.sin(angles)])
        poses = np.column_stack([xy, np.arctan2(-np.sin(angles), -np.cos(angles))])
        navigator = self.context.navigator
        if navigator is not None:
            free = np.flatnonzero(navigator.has_room(poses))
            if free.size:
                return poses[free[0]]
        return poses[0]

    def _standoff(self, name: str) -> np.ndarray:
        """Facing the object: at the nearest edge of the surface it stands on, or beside it on the floor."""
        belief = self.context.world_model
        obj = self._object(name)
        config = self.context.robot_config
        here = self.context.robot.base.pose()
        surface = belief.surface_under(obj.position) if obj.held_by is None else None
        if surface is not None:
            bounds = np.array(self.context.world.bounds)
            try:
                stances = working_stances(obj.position[:2], surface, "right", config.base, bounds, here[:2])
            except StanceError as error:
                raise PhaseFailure(str(error)) from None
            # a step back from the working stance: room to raise the arms before the last approach (stand_near),
            # shorter where furniture behind leaves less room; to a side of it, or at the next edge that reaches
            # the object, where something stands on the way in (a parcel dropped there): the last approach then
            # drives in from there
            steps = np.linspace(STANCE_BACKOFF, 0.0, 5)
            options = [
                _moved(stance, -step, aside)
                for stance in stances
                for step, aside in [(step, 0.0) for step in steps] + list(itertools.product(steps, STANCE_ASIDE))
            ]
            navigator = self.context.navigator
            if navigator is not None:
                room = navigator.has_room(np.array(options))
                fits = [pose for pose, free in zip(options, room, strict=True) if free]
                options = fits or options
            return options[0]
        return self._facing(obj.position, OBJECT_STANDOFF)


def _moved(pose: tuple[float, float, float], ahead: float, left: float) -> np.ndarray:
    """``pose`` (x, y, yaw) moved ``ahead`` m along its heading and ``left`` m to its left, facing the same way."""
    x, y, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([x + ahead * c - left * s, y + ahead * s + left * c, yaw])


class TurnParams(StrictModel):
    yaw: float | None = Field(None, ge=-360, le=360, description="heading to turn to (degrees, world)")
    place: str | None = Field(None, description="a named place to face")
    object: str | None = Field(None, description="an object to face (from the world model)")

    @model_validator(mode="after")
    def _one_target(self) -> TurnParams:
        exactly_one(self, "yaw", "place", "object")
        return self


@skill("turn", "turn on the spot to a heading, or to face a place or an object")
class Turn(_BaseSkill):
    Params = TurnParams

    @classmethod
    def check(cls, params: TurnParams, context: CheckContext) -> list[tuple[str, str]]:
        return _places_and_objects(params, context)

    def phases(self):
        return [("turn", self._turn)]

    def _turn(self) -> MotionHandle:
        p: TurnParams = self.params
        x, y, _ = self.context.robot.base.pose()
        if p.yaw is not None:
            heading = math.radians(p.yaw)
        else:
            if p.place is not None:
                target = np.array(self.context.world.place(p.place).pose[:2])
            else:
                target = self._object(p.object).position[:2]
            heading = math.atan2(target[1] - y, target[0] - x)
        return self.context.robot.base.move_to(x, y, heading)


class RotateInPlaceParams(StrictModel):
    angle: float = Field(360.0, ge=-720, le=720, description="degrees, counter-clockwise (a full turn by default)")


@skill("rotate_in_place", "spin on the spot by an angle (lets the camera see all around, to refresh the map)")
class RotateInPlace(_BaseSkill):
    Params = RotateInPlaceParams

    def phases(self):
        return [("look ahead", self._look_ahead), ("rotate", self._rotate)]

    def _rotate(self) -> MotionHandle:
        x, y, yaw = self.context.robot.base.pose()
        return self.context.robot.base.move_to(x, y, yaw + math.radians(self.params.angle), shortest_turn=False)


class BackUpParams(StrictModel):
    distance: float = Field(0.3, gt=0, le=2.0, description="metres straight back")


@skill("back_up", "drive straight back a short distance, if the map shows room behind")
class BackUp(_BaseSkill):
    Params = BackUpParams

    def phases(self):
        return [("back up", self._back_up)]

    def _back_up(self) -> MotionHandle:
        self._navigator()
        handle = back_up(self.context, self.params.distance)
        if handle is None:
            raise PhaseFailure(f"no room to back up {self.params.distance:.2f} m")
        return handle


def back_up(context: SkillContext, distance: float) -> MotionHandle | None:
    """Drive straight back ``distance`` metres if the navigation map shows room behind; None if not."""
    navigator = context.navigator
    x, y, yaw = context.robot.base.pose()
    behind = np.array([x, y]) - distance * np.array([math.cos(yaw), math.sin(yaw)])
    if navigator is None:
        return None
    path = np.linspace([x, y], behind, 20)[5:]  # the first points are where the robot stands
    # a walking robot works nearer a table than a route may pass it: backing away, the clearance only grows, so
    # the way back is free where it keeps at least what the robot has where it stands
    here = float(navigator.grid.clearance_at(np.array([[x, y]]))[0])
    if np.any(navigator.grid.clearance_at(path) < min(navigator.clearance.minimum, here)):
        return None
    return context.robot.base.move_to(behind[0], behind[1], yaw, max_speed=BACK_UP_SPEED)


def at_a_surface(context: SkillContext, within: float = 0.3) -> bool:
    """Whether the base stands within ``within`` metres of a support surface (its hands may be over it)."""
    x, y, _ = context.robot.base.pose()
    reach = context.robot_config.base.footprint_radius + within
    for surface in context.world_model.surfaces.values():
        nearest = np.clip([x, y], surface.region[0], surface.region[1])
        if float(np.hypot(x - nearest[0], y - nearest[1])) < reach:
            return True
    return False


class ClearMapParams(StrictModel):
    pass


@skill("clear_map", "forget the obstacles the camera added to the map (the next looks add back what is there)")
class ClearMap(_BaseSkill):
    Params = ClearMapParams

    def phases(self):
        return [("clear", self._clear)]

    def _clear(self) -> None:
        self._navigator().clear_map()
