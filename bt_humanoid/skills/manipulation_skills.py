"""Skills that handle objects: stand near, grasp, put, release, give.

All of them read objects and surfaces from the WorldModel (the robot's
belief), never from the simulator. The pick and place behaviours in
behaviors/ compose them with recovery.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from typing import Literal

import numpy as np
import pinocchio as pin
from pydantic import Field, model_validator

from bt_humanoid.control.grasping import (
    DESCEND_TOLERANCE,
    LIFT_HEIGHT,
    PAD_HALF_HEIGHT,
    ROUND_KINDS,
    GraspError,
    natural_hand_yaw,
    plan_grasp,
)
from bt_humanoid.control.keep_clear import (
    clearance_limits,
    hand_radius,
    over_limit,
    things_on,
    transit_height,
)
from bt_humanoid.control.motion import MotionHandle
from bt_humanoid.control.stance import StanceError, working_stance
from bt_humanoid.control.wbc.limits import BaseBoundsLimit, BaseKeepoutLimit, ClearanceLimit, JointRangeLimit, Limit
from bt_humanoid.control.whole_body import READY_POSTURE, ReachHandle, yaw_rotation
from bt_humanoid.perception.free_space import EDGE_MARGIN, MAX_SHIFT, nearest_free
from bt_humanoid.perception.world_model import SupportSurface, TrackedObject, WorldModel
from bt_humanoid.skills.context import CheckContext, SkillContext
from bt_humanoid.skills.params import check_in_map, check_name, check_object
from bt_humanoid.skills.phased import PhasedSkill, PhaseFailure
from bt_humanoid.skills.registry import skill
from bt_humanoid.strict_model import StrictModel, exactly_one

Side = Literal["left", "right"]
APPROACH_CLEARANCE = 0.06  # m the hand (or what it holds) keeps above a surface while moving over it
KEEPOUT_MARGIN = 0.03  # m added to the footprint radius when the base moves during a reach
DESCEND_SPEED = 0.1  # m/s for the last few centimetres to a grasp or a placement
RELEASE_GAP = 0.005  # m between a placed object's bottom and the surface when the gripper opens
GRASP_WIDTH_TOLERANCE = 0.015  # m: a closed width further than this from the object's size is "something else"
OFF_CENTRE_GRIP = 0.012  # m across the pads from their middle: pressed on the pads' outer fifth alone, held by an edge
TUCKED_POSTURE = "tucked"  # robot.yaml posture for the idle arm near furniture
CARRY_FORWARD = 0.38  # m ahead of the base centre where a held object is carried: clear of the chest
CARRY_SIDE = 0.25  # m to the side of the working hand: outside the shoulder
CARRY_HEIGHT = 0.95  # m above the floor, at least
MAX_CARRY_HEIGHT = 1.2  # m: the arm's comfortable limit (torso lifted)
CARRY_TOLERANCE = (0.05, 0.2)  # m, rad: the carry pose needs no precision (a tall thing held high may fall short)
IN_THE_WAY = math.radians(20)  # a hand this close to an object's line of sight (and not behind it) hides part of it
BEHIND_MARGIN = 0.1  # m beyond the object's centre from which a hand on its line of sight is behind it
ASIDE = 0.18  # m a hand in the camera's way moves outwards: out of a 20° cone at the arm's usual reach
SHORT_REACH = 0.005  # m: a descent that stopped further than this short of its goal (in the plane) fell short
STEP_IN = 0.04  # m the next stance moves, at least, after a reach fell short: enough for the feet to step
STEP_RANGE = 0.2  # m: a step asked for further from the stance than this was for another (the object moved since)
LIFT_OFF = 0.03  # m a robot that balances with what it holds lifts it to weigh it, before the lift proper
LIFT_OFF_TOLERANCE = (0.03, 0.2)  # m, rad: off the surface is all that counts (the arm sags under a weight unknown)
LOAD_TAKEN = 0.5  # share of a held thing's weight the wrist no longer feels when a surface bears it
WALKING_SWAY = 0.03  # m a walking robot's raised hand bobs and sways with its steps: more room over things


def carry_height(belief: WorldModel, held: TrackedObject | None) -> float:
    """How high a hand carries ``held`` (or nothing): what hangs below it clears every known surface's top."""
    below_hand = held.grip_offset + float(held.size[2]) / 2 if held is not None else 0.0
    highest = max((s.height for s in belief.surfaces.values()), default=0.0)
    return max(CARRY_HEIGHT, highest + below_hand + APPROACH_CLEARANCE)


def lift_what_is_held(context: SkillContext) -> MotionHandle | None:
    """Raise a hand whose load hangs lower than the furniture's tops plus a clearance (as a scene may start a
    tall bottle held low), before the base drives past the furniture; nothing when every load is clear."""
    belief = context.world_model
    whole_body = context.robot.whole_body
    for side in context.robot_config.grippers:
        held = belief.held(side)
        if held is None:
            continue
        needed = carry_height(belief, held)
        hand = whole_body.frame_pose(whole_body.hand_frame(side))
        if hand.translation[2] >= needed - 0.02:
            continue
        target = pin.SE3(hand.rotation.copy(), np.array([*hand.translation[:2], min(needed, MAX_CARRY_HEIGHT)]))
        return whole_body.reach(side, target, move_base=False, tolerance=CARRY_TOLERANCE)
    return None


class _ManipulationSkill(PhasedSkill):
    """Shared helpers: reach limits, the carry pose."""

    def _keepout(self, region: np.ndarray) -> list[Limit]:
        """Keep the base's footprint off a rectangle of the floor ([[x0, y0], [x1, y1]]: furniture reached over)
        and off the map's walls, while it helps a reach."""
        radius = self.context.robot_config.base.footprint_radius + KEEPOUT_MARGIN
        base = self.context.robot_config.frames["base"][1]
        walls = BaseBoundsLimit(base, np.array(self.context.world.bounds), radius)
        return [BaseKeepoutLimit(base, region, radius), walls]

    def _open_hand(self, side: str) -> list[Limit]:
        """Limits for a motion with the hand open: its joints within the gripper's open range (the fingers,
        opened wide, would meet the forearm beyond it and jam)."""
        ranges = self.context.robot_config.grippers[side].open_range
        return [JointRangeLimit(ranges)] if ranges else []

    def _hand_yaw(self, side: str) -> float:
        rotation = self.context.robot.whole_body.frame_pose(self.context.robot.whole_body.hand_frame(side)).rotation
        return math.atan2(rotation[1, 0], rotation[0, 0])

    def _carry_xy(self, side: str) -> np.ndarray:
        """Where the carry pose holds the hand, in the plane: ahead of the base, outside the shoulder."""
        x, y, yaw = self.context.robot.base.pose()
        lateral = -CARRY_SIDE if side == "right" else CARRY_SIDE
        forward = np.array([math.cos(yaw), math.sin(yaw)])
        left = np.array([-math.sin(yaw), math.cos(yaw)])
        return np.array([x, y]) + CARRY_FORWARD * forward + lateral * left

    def _is_open(self, side: str) -> bool:
        gripper = self.context.robot_config.grippers[side]
        return self.context.robot.grippers.width(side) > len(gripper.joints) * gripper.open / 2

    def _hand_extent(self, side: str) -> tuple[float, float]:
        """How far below the grip site, and how far across, the hand or what it holds reaches (m)."""
        held = self.context.world_model.held(side)
        if held is not None:
            return held.grip_offset + float(held.size[2]) / 2, hand_radius(held, is_open=False)
        return PAD_HALF_HEIGHT, hand_radius(None, self._is_open(side))

    def _note_short_reach(self, thing: TrackedObject, goal: np.ndarray) -> None:
        """A hand that stopped short of ``goal`` on its way down to take or put ``thing`` asks the next stance
        to stand that much further that way from where the robot stands now (``TrackedObject.step_to``, which
        ``StandNear`` follows nearer the edge only where the robot's ``working_stance.closest`` allows): reaching
        further, a balancing robot would lean until it fell."""
        miss = (goal - self._hand_xyz(self.params.side))[:2]
        length = float(np.linalg.norm(miss))
        if length > SHORT_REACH:
            # from here, not from the stance: a robot that stopped short of (or past) its stance would
            # otherwise step by less than it missed, or not at all
            thing.step_to = self.context.robot.base.pose()[:2] + miss * max(length + SHORT_REACH, STEP_IN) / length

    def _hand_xyz(self, side: str) -> np.ndarray:
        whole_body = self.context.robot.whole_body
        return whole_body.frame_pose(whole_body.hand_frame(side)).translation.copy()

    def _keep_clear(
        self, side: str, surface: SupportSurface, exclude: tuple[str, ...] = (), except_at: np.ndarray | None = None
    ) -> list[ClearanceLimit]:
        """Limits holding the hand (and what it holds) above each thing believed on ``surface``."""
        things = things_on(self.context.world_model, surface, exclude)
        frame = self.context.robot.whole_body.hand_frame(side)
        return clearance_limits(frame, things, *self._hand_extent(side), except_at=except_at)

    def _rise_over(
        self,
        side: str,
        surface: SupportSurface,
        goal_xy: np.ndarray,
        at_least: float,
        exclude: tuple[str, ...] = (),
        start_xy: np.ndarray | None = None,
        margin: float = 0.0,
    ) -> MotionHandle | None:
        """Lift the hand straight up until a straight move to ``goal_xy`` (from ``start_xy``, default where the
        hand is) passes ``margin`` more over the things on ``surface``, and to ``at_least``; nothing when it is
        that high already."""
        hand = self._hand_xyz(side)
        start = hand[:2] if start_xy is None else start_xy
        things = things_on(self.context.world_model, surface, exclude)
        height = max(at_least, transit_height(start, goal_xy, things, *self._hand_extent(side)) + margin)
        if hand[2] >= height - 0.02:
            return None
        whole_body = self.context.robot.whole_body
        rotation = whole_body.frame_pose(whole_body.hand_frame(side)).rotation.copy()
        target = pin.SE3(rotation, np.array([hand[0], hand[1], min(height, MAX_CARRY_HEIGHT)]))
        # an open hand keeps its wrist where the spread fingers clear the forearm; a closed one may go higher
        open_hand = self._open_hand(side) if self._is_open(side) else []
        # as high as the arm goes here: close to the body it may stop a few centimetres short, and the next
        # reach's clearance limits lift it the rest of the way as it moves out over the things
        return whole_body.reach(side, target, move_base=False, limits=open_hand, tolerance=CARRY_TOLERANCE)

    def _carry(self, side: str, clearances: list[ClearanceLimit]) -> MotionHandle:
        """Bring the hand in front of the body, high enough to carry what it holds past furniture.

        ``clearances`` hold the hand up while it is over a surface; the carry
        pose is at least as high as each, since it may lie over the surface's edge.
        The hand also keeps above each thing on the surface it starts over.
        """
        yaw = self.context.robot.base.pose()[2]
        xy = self._carry_xy(side)
        # high enough that what hangs below the hand clears every known surface on the way
        held = self.context.world_model.held(side)
        height = max(carry_height(self.context.world_model, held), *(c.height for c in clearances))
        under = self.context.world_model.surface_under(self._hand_xyz(side))
        if under is not None:  # held up over the things it passes, not carried at their height
            kept_over = self._keep_clear(side, under)
            clearances = [*clearances, *kept_over]
            # a carry pose over one of them (the base close to the counter) is as high as that thing asks
            height = max([height, *(c.height for c in kept_over if c.covers(xy))])
        # an empty hand turns to its natural yaw; a full one keeps its yaw (as grasped) so nothing swings
        hand_yaw = self._hand_yaw(side) if held is not None else natural_hand_yaw(yaw)
        target = pin.SE3(yaw_rotation(hand_yaw), np.array([*xy, min(height, MAX_CARRY_HEIGHT)]))
        return self.context.robot.whole_body.reach(
            side, target, move_base=False, limits=list(clearances), tolerance=CARRY_TOLERANCE
        )

    def _clearance(self, side: str, surface: SupportSurface, below_hand: float) -> ClearanceLimit:
        """Keep the hand high enough over ``surface`` that ``below_hand`` metres beneath it stay clear."""
        frame = self.context.robot.whole_body.hand_frame(side)
        return ClearanceLimit(frame, surface.height + below_hand + APPROACH_CLEARANCE, surface.region)


# --------------------------------------------------------------------------- stand_near


class StandNearParams(StrictModel):
    object: str | None = Field(None, description="an object to work on (from the world model)")
    surface: str | None = Field(None, description="a support surface to work on, at `at` or its nearest spot")
    at: tuple[float, float] | None = Field(None, description="[x, y] spot on the surface (m, world)")
    side: Side = Field("right", description="the hand that will work")
    max_speed: float = Field(0.3, gt=0, le=0.8, description="m/s cap for this short, final approach")

    @model_validator(mode="after")
    def _one_target(self) -> StandNearParams:
        exactly_one(self, "object", "surface")
        return self


STANCE_ARRIVAL = 0.15  # m: the first and last stretch at a stance may graze the map's margin round furniture
STEP_BACK_TO_RAISE = 0.35  # m back from a surface before a folded arm swings out to the ready posture
UNFOLDED = 0.2  # rad: an arm within this of the ready posture in every joint is ready already
READY_TOLERANCE = 0.1  # rad (m for the lift) from the ready posture that counts as arrived there
APPROACH_BACKOFF = 0.3  # m behind a stance, at most, where navigation may end before the straight last stretch


# a stance not reached is tried once more (an arm settles, a passer-by moves on), then from a fresh look
@skill(
    "stand_near",
    "drive (straight, short) to a stance from which one hand reaches an object or a surface spot",
    recovery={"retries": 1, "replan": 1},
)
class StandNear(_ManipulationSkill):
    Params = StandNearParams

    @classmethod
    def check(cls, params: StandNearParams, context: CheckContext) -> list[tuple[str, str]]:
        world = context.world
        named = check_object(params.object, world) + check_name(params.surface, world.surfaces, "surface", "surface")
        return named + check_in_map(params.at, world)

    def phases(self):
        return [
            ("tuck the other arm", self._tuck),
            ("step back to raise the arm", self._step_back),
            ("raise the arm", self._raise_arm),
            ("hand up", self._hand_up),
            ("approach", self._approach),
            ("stance", self._drive),
        ]

    def _ready_posture(self) -> dict[str, float]:
        """Where the empty working arm (and the torso lift) go before the stance: none for a full arm, which stays
        as carried."""
        if self.context.world_model.held(self.params.side) is not None:
            return {}
        config = self.context.robot_config
        joints = [*config.groups.get("lift", []), *config.groups.get(f"{self.params.side}_arm", [])]
        ready = config.postures.get(READY_POSTURE, {})
        return {j: ready[j] for j in joints if j in ready}

    def _step_back(self) -> MotionHandle | None:
        """Away from a surface the robot stands at before a folded arm swings out to the ready posture: beside a
        counter the hand swings into its side, and the arm then lies on its top, straining at the shoulder."""
        from bt_humanoid.skills.navigation_skills import at_a_surface, back_up  # they build on this module

        ready = self._ready_posture()
        if not ready or not at_a_surface(self.context):
            return None
        joints = self.context.robot.joints
        now = joints.position[joints.indices(list(ready))]
        if np.max(np.abs(now - np.array(list(ready.values())))) < UNFOLDED:
            return None  # ready already: nothing swings out
        return back_up(self.context, STEP_BACK_TO_RAISE)

    def _raise_arm(self) -> MotionHandle | None:
        """An empty working arm goes to the ready posture (a good start for reaches); a full one stays as carried.

        Near it is as good a start: a hand that a failed grasp left over the object may rest on it (a mug's
        handle under a pad) a few hundredths of a radian short, and the hand rises over things next."""
        ready = self._ready_posture()
        return self.context.robot.joints.move(ready, tolerance=READY_TOLERANCE) if ready else None

    def _hand_up(self) -> MotionHandle | None:
        """Raise the empty hand, held out at the ready posture, over the things it will pass as the base drives
        to the stance: at the ready height it would sweep through a bag of chips beside the object."""
        side = self.params.side
        if self.context.world_model.held(side) is not None:
            return None
        if self.params.object is not None and self._object(self.params.object).held_by is not None:
            return None
        surface, stance = self._stance()
        x, y, yaw = self.context.robot.base.pose()
        hand = self._hand_xyz(side)
        offset = yaw_rotation(-yaw)[:2, :2] @ (hand[:2] - np.array([x, y]))  # the hand in the base's frame
        arrived = stance[:2] + yaw_rotation(stance[2])[:2, :2] @ offset
        # a walking robot's hand bobs with its steps (a mug on the counter was knocked over)
        sway = WALKING_SWAY if self.context.robot_config.base.floating else 0.0
        return self._rise_over(side, surface, arrived, hand[2], start_xy=hand[:2], margin=sway)

    def _stance(self) -> tuple[SupportSurface, np.ndarray]:
        """The surface worked on and the base pose (x, y, yaw) to work on it from."""
        p: StandNearParams = self.params
        belief = self.context.world_model
        if p.object is not None:
            obj = self._object(p.object)
            surface = belief.surface_under(obj.position) if obj.held_by is None else None
            if surface is None:
                raise PhaseFailure(f"{obj.name} is not on a known surface (held, or fallen?)")
            spot = obj.position[:2]
        else:
            surface = self._surface(p.surface)
            spot = np.array(p.at) if p.at is not None else surface.region.mean(axis=0)
        config = self.context.robot_config
        worked_on = self._worked_on()
        bounds, robot_xy = np.array(self.context.world.bounds), self.context.robot.base.pose()[:2]
        try:
            pose = np.array(working_stance(spot, surface, p.side, config.base, bounds, robot_xy))
            stepping = worked_on is not None and worked_on.step_to is not None  # a hand fell short: step that way
            if stepping and math.dist(worked_on.step_to, pose[:2]) < STEP_RANGE:
                ahead, left = yaw_rotation(-pose[2])[:2, :2] @ (worked_on.step_to - pose[:2])
                shift = (float(ahead), float(left))
                pose = np.array(working_stance(spot, surface, p.side, config.base, bounds, robot_xy, shift=shift))
        except StanceError as error:
            raise PhaseFailure(str(error)) from None
        return surface, pose

    def _worked_on(self) -> TrackedObject | None:
        """The object to take (``object``), or the one the hand holds to put down (at a surface spot)."""
        if self.params.object is not None:
            return self._object(self.params.object)
        return self.context.world_model.held(self.params.side)

    def _tuck(self) -> MotionHandle:
        """Fold the idle arm inside the footprint, where no furniture edge can catch it."""
        config = self.context.robot_config
        other = "left" if self.params.side == "right" else "right"
        joints = config.groups.get(f"{other}_arm", [])
        tucked = config.postures.get(TUCKED_POSTURE, {})
        return self.context.robot.joints.move({j: tucked[j] for j in joints if j in tucked})

    def _approach(self) -> MotionHandle | None:
        """Where furniture stands between the robot and the stance, navigate round it first: to the stance, or
        as near it, straight behind it, as leaves the footprint room (a walking robot works nearer a table than
        its footprint keeps from furniture). The last stretch is then straight (``_drive``)."""
        p: StandNearParams = self.params
        if p.object is not None and self._object(p.object).held_by is not None:
            return None
        _surface, (x, y, yaw) = self._stance()
        navigator = self.context.navigator
        if navigator is None or not self._straight_way_blocked(np.array([x, y])):
            return None
        end = navigator.room_behind(np.array([x, y]), yaw, APPROACH_BACKOFF)
        if end is None:  # no room behind either: the navigator says why
            end = np.array([x, y])
        return navigator.go_to(np.array([*end, yaw]), p.max_speed)

    def _drive(self) -> MotionHandle | None:
        p: StandNearParams = self.params
        if p.object is not None and self._object(p.object).held_by is not None:
            return None  # in the hand already (a pick started over after its carry fell short): here is near
        _surface, (x, y, yaw) = self._stance()
        if self._straight_way_blocked(np.array([x, y])):  # the object moved, or we stand on another side
            return self.context.navigator.go_to(np.array([x, y, yaw]), p.max_speed)
        # after a reach fell short, stepping in by a few centimetres is the point: arrive that precisely
        worked_on = self._worked_on()
        stepping_in = worked_on is not None and worked_on.step_to is not None
        tolerance = STEP_IN / 2 if stepping_in else None
        return self.context.robot.base.move_to(x, y, yaw, max_speed=p.max_speed, tolerance=tolerance)

    def _straight_way_blocked(self, stance: np.ndarray) -> bool:
        """Would the footprint, driven straight to ``stance``, cross furniture on the map before it arrives?"""
        navigator = self.context.navigator
        if navigator is None:
            return False
        here = self.context.robot.base.pose()[:2]
        length = float(np.hypot(*(stance - here)))
        steps = np.arange(STANCE_ARRIVAL, length - STANCE_ARRIVAL, navigator.grid.resolution)
        if steps.size == 0:
            return False
        points = here + steps[:, None] * (stance - here) / max(length, 1e-9)
        return bool(np.min(navigator.grid.clearance_at(points)) < self.context.robot_config.base.footprint_radius)


# --------------------------------------------------------------------------- grasp


class GraspParams(StrictModel):
    object: str = Field(description="the object to pick up (from the world model)")
    side: Side = Field("right", description="which hand")


# a missed grasp is tried again from the same stance (re-reading the object's pose), then from a new approach
@skill(
    "grasp",
    "pick up an object within reach: pre-grasp above it, descend, close, lift, verify, carry",
    recovery={"retries": 1, "replan": 1},
)
class Grasp(_ManipulationSkill):
    Params = GraspParams
    handles_faults = frozenset({"dropped"})  # it verifies its hold after lifting and leaves the hand ready again

    @classmethod
    def check(cls, params: GraspParams, context: CheckContext) -> list[tuple[str, str]]:
        return check_object(params.object, context.world)

    def phases(self):
        return [
            ("clear the view", self._clear_view),
            ("step aside", self._step_aside),
            ("plan", self._plan),
            ("raise", self._unless_held(self._raise)),
            ("pre-grasp", self._unless_held(self._pre_grasp)),
            ("descend", self._unless_held(self._descend)),
            ("close", self._unless_held(self._close)),
            ("check grasp", self._unless_held(self._check_grasp)),
            ("lift off", self._unless_held(self._lift_off)),
            ("weigh", self._unless_held(self._weigh)),
            ("lift", self._unless_held(self._lift)),
            ("verify", self._unless_held(self._verify)),
            # held askew (slid down to a bottle's neck, turned in the pads): set it down where it was taken from
            ("set it down again", self._if_askew(self._set_down_askew)),
            ("let go of it", self._if_askew(lambda: self.context.robot.grippers.command(self.params.side, "open"))),
            ("clear it", self._if_askew(self._clear_askew)),
            ("grasp it afresh", self._if_askew(self._fail_askew)),
            ("carry", self._carry_taken),
        ]

    def _if_askew(self, phase: Callable[[], MotionHandle | None]) -> Callable[[], MotionHandle | None]:
        """A phase that runs only when the verify found the object held, but not as it was grasped."""
        return lambda: phase() if self.askew else None

    def _unless_held(self, phase: Callable[[], MotionHandle | None]) -> Callable[[], MotionHandle | None]:
        """A phase that is skipped when the hand already holds the object (a retry after the carry failed)."""
        return lambda: None if self._held_already else phase()

    def _carry_taken(self) -> MotionHandle:
        surface = self.surface or self.context.world_model.surface_under(self._hand_xyz(self.params.side))
        clearances = [self._clearance(self.params.side, surface, 0.0)] if surface is not None else []
        return self._carry(self.params.side, clearances)

    def _in_view(self) -> bool:
        """Is the hand on the camera's line of sight to the object (and not behind it)?

        A hand over the object (after a failed attempt) or beside it (the ready posture) hides part of it: the
        rest reads as a smaller thing off-centre, and the cut edge can pass for a mug's handle.
        """
        target = self._object(self.params.object)
        whole_body = self.context.robot.whole_body
        eye = whole_body.frame_pose(self.context.robot_config.frames["head_camera"][1]).translation
        to_hand = self._hand_xyz(self.params.side) - eye
        to_object = target.position - eye
        cosine = float(to_hand @ to_object) / max(float(np.linalg.norm(to_hand) * np.linalg.norm(to_object)), 1e-9)
        behind = np.linalg.norm(to_hand) > np.linalg.norm(to_object) + BEHIND_MARGIN
        return cosine >= math.cos(IN_THE_WAY) and not behind

    def _clear_view(self) -> MotionHandle | None:
        """Before the close look, lift an empty hand that is in the camera's way over the things near it ..."""
        side = self.params.side
        self._hidden = (
            self.context.perceiver is not None and self.context.world_model.held(side) is None and self._in_view()
        )
        if not self._hidden:
            return None
        hand = self._hand_xyz(side)
        surface = self.context.world_model.surface_under(hand)
        return self._rise_over(side, surface, hand[:2], hand[2]) if surface is not None else None

    def _step_aside(self) -> MotionHandle | None:
        """... and then move it outwards, away from the body's centre line, until it no longer hides the object."""
        if not self._hidden:
            return None
        side = self.params.side
        yaw = self.context.robot.base.pose()[2]
        outwards = np.array([math.sin(yaw), -math.cos(yaw)]) * (1.0 if side == "right" else -1.0)
        hand = self.context.robot.whole_body.frame_pose(self.context.robot.whole_body.hand_frame(side))
        target = pin.SE3(hand.rotation.copy(), hand.translation + np.array([*(ASIDE * outwards), 0.0]))
        under = self.context.world_model.surface_under(hand.translation)
        limits = self._keep_clear(side, under) if under is not None else []
        # as far as the arm goes that way (a wall, the end of its reach): part of the way clears part of the view
        return self.context.robot.whole_body.reach(
            side, target, move_base=False, limits=limits, tolerance=(ASIDE, CARRY_TOLERANCE[1])
        )

    def _plan(self) -> None:
        side = self.params.side
        held = self.context.world_model.held(side)
        self._held_already, self.surface, self.askew = False, None, False
        if held is not None and held.id == self._object(self.params.object).id:
            self._held_already = True  # taken already (a carry that fell short): only the carry is left to do
            return
        if held is not None:
            raise PhaseFailure(f"the {side} hand already holds the {held.name}")
        if self.context.perceiver is not None:
            self.context.perceiver.look()  # a fresh, close look: a mug's handle shows from here if anywhere
        self.target = self._object(self.params.object)
        surface = self.context.world_model.surface_under(self.target.position)
        if surface is None:
            raise PhaseFailure(f"{self.target.name} is not on a known surface")
        self.surface = surface
        try:
            gripper = self.context.robot_config.grippers[side]
            opening = len(gripper.joints) * gripper.open  # pads touch at 0: each finger adds its travel
            base_yaw = self.context.robot.base.pose()[2]
            self.grasp = plan_grasp(self.target, surface.height, natural_hand_yaw(base_yaw), opening)
        except GraspError as error:
            raise PhaseFailure(str(error)) from None

    def _pose(self, position: np.ndarray) -> pin.SE3:
        return pin.SE3(yaw_rotation(self.grasp.yaw), position)

    def _raise(self) -> MotionHandle | None:
        """Lift the hand straight up first: to the pre-grasp height, so it clears the surface's edge, and over
        the things between it and the object."""
        side, goal = self.params.side, self.grasp.pre_grasp  # the hand opens on its way to the pre-grasp
        return self._rise_over(side, self.surface, goal[:2], goal[2], exclude=(self.target.id,))

    def _pre_grasp(self) -> MotionHandle:
        robot = self.context.robot
        robot.grippers.command(self.params.side, "open")  # opens while the hand travels
        limits = [*self._keepout(self.surface.region), self._clearance(self.params.side, self.surface, 0.0)]
        limits += self._open_hand(self.params.side)
        limits += self._keep_clear(self.params.side, self.surface, (self.target.id,), except_at=self.grasp.pre_grasp)
        # the pads pass over the object's own top on the way (a bag of chips tips at a touch)
        limits.append(over_limit(robot.whole_body.hand_frame(self.params.side), self.target, PAD_HALF_HEIGHT, margin=0))
        return robot.whole_body.reach(
            self.params.side, self._pose(self.grasp.pre_grasp), gaze=self.target.position, limits=limits
        )

    def _descend(self) -> MotionHandle:
        return self.context.robot.whole_body.reach(
            self.params.side,
            self._pose(self.grasp.position),
            speed=DESCEND_SPEED,
            gaze=self.target.position,
            limits=[*self._keepout(self.surface.region), *self._open_hand(self.params.side)],
            tolerance=DESCEND_TOLERANCE,
        )

    def settle_for(self, motion: MotionHandle) -> bool:
        """A descent that the arm's reach stopped short of its grip, but near enough that the grip still holds (a
        little higher, or off along the line the pads close on), closes where it is: no stance gets nearer."""
        if self.phase != "descend" or not (isinstance(motion, ReachHandle) and motion.out_of_reach):
            return False
        side = self.params.side
        hand = self._hand_xyz(side)
        if not self.grasp.closes_from(hand, self._hand_yaw(side)):
            return False
        self.grasp = replace(self.grasp, position=hand)  # where it holds: what the put lowers by
        return True

    def _close(self) -> MotionHandle:
        # a round thing felt at the pads' edge is let go at once: closing on, the edges push it away or over
        round_thing = self.target.kind in ROUND_KINDS
        return self.context.robot.grippers.grasp(self.params.side, edge=OFF_CENTRE_GRIP if round_thing else None)

    def _check_grasp(self) -> None:
        width = self.context.robot.grippers.width(self.params.side)
        if abs(width - self.grasp.width) > GRASP_WIDTH_TOLERANCE:
            self.context.robot.grippers.command(self.params.side, "open")
            raise PhaseFailure(
                f"closed {width * 100:.1f} cm wide where the {self.target.name} is {self.grasp.width * 100:.1f} cm: "
                "not holding it"
            )
        off_centre = self._felt_at_the_edge()
        if off_centre is not None:
            # held by the pads' edge (it was not where the camera put it): lifted, it would hang by a few
            # millimetres, and a person taking it would find the robot's pads where their fingers go
            self.context.robot.grippers.command(self.params.side, "open")
            self._felt_off_centre(off_centre)
            raise PhaseFailure(
                f"the {self.target.name} presses on the pads {abs(off_centre) * 100:.1f} cm off their middle "
                "(felt by the pads): let go to grasp it afresh"
            )
        self.target.held_by = self.params.side
        self.target.grip_offset = self.grasp.position[2] - self.target.position[2]

    def _felt_at_the_edge(self) -> float | None:
        """Where across the pads the object presses (m from their middle), when that is at their edge."""
        felt = self.context.robot.grippers.pressure_centre(self.params.side)
        return felt if felt is not None and abs(felt) > OFF_CENTRE_GRIP else None

    def _felt_off_centre(self, off_centre: float) -> None:
        """Move the belief of where the object stands the way the pads felt it: along the hand's y axis (across
        the pads, level in a top-down grasp), by where it pressed; the next look refines it."""
        whole_body = self.context.robot.whole_body
        across = whole_body.frame_pose(whole_body.hand_frame(self.params.side)).rotation[:, 1].copy()
        across[2] = 0.0
        across /= max(float(np.linalg.norm(across)), 1e-9)
        self.target.position = self.target.position + off_centre * across

    def _lift_off(self) -> MotionHandle | None:
        """A robot that balances with what it holds lifts it just off the surface first, to weigh it: lifted
        higher with a weight the dynamics do not know, the arm sags short of its goal."""
        side = self.params.side
        if not self.context.robot.weighs(side):
            return None
        return self.context.robot.whole_body.reach(
            side,
            self._pose(self.grasp.position + np.array([0.0, 0.0, LIFT_OFF])),
            speed=DESCEND_SPEED,
            limits=self._keepout(self.surface.region),
            tolerance=LIFT_OFF_TOLERANCE,
        )

    def _weigh(self) -> None:
        """Off the surface: weigh it (the wrist's sensor), and balance and lift with that weight from now on."""
        if self.context.robot.weighs(self.params.side):
            self.target.weight = self.context.robot.weigh(self.params.side)

    def _lift(self) -> MotionHandle:
        # high enough that what the hand now holds passes over the things between here and the carry pose
        side = self.params.side
        things = things_on(self.context.world_model, self.surface, (self.target.id,))
        over = transit_height(self.grasp.position[:2], self._carry_xy(side), things, *self._hand_extent(side))
        lifted = self.grasp.lifted.copy()
        lifted[2] = min(max(lifted[2], over), MAX_CARRY_HEIGHT)
        # the base may help a stretched arm up, but not by driving under the surface's edge
        return self.context.robot.whole_body.reach(
            side,
            self._pose(lifted),
            speed=DESCEND_SPEED,
            limits=self._keepout(self.surface.region),
        )

    def _verify(self) -> None:
        """Still held: the pads are held apart by something the object's width.

        Not the width they first stalled at: a light, tall thing pushed askew by the first pad to touch it
        (a bag of chips) is caught tilted, a centimetre wider, and hangs straight once it is off the surface.
        """
        grippers = self.context.robot.grippers
        if not grippers.holding(self.params.side):
            self.target.held_by = None
            self.target.confidence = 0.0  # where it went is unknown until it is seen again
            raise PhaseFailure(f"the {self.target.name} slipped out of the {self.params.side} hand")
        self.width_held = grippers.width(self.params.side)
        if abs(self.width_held - self.grasp.width) > GRASP_WIDTH_TOLERANCE:
            self.askew = True  # something is still between the pads: carried like this it would fall, or be put crooked
            return
        self._weigh()  # again, held still and clear of everything: the better reading
        # reached: wherever it is put next, its stance starts afresh
        self.target.step_to = None

    def _set_down_askew(self) -> MotionHandle:
        """Lower the hand to where it closed, stopping as soon as what it holds meets the surface."""
        return self.context.robot.whole_body.reach(
            self.params.side,
            self._pose(self.grasp.position),
            speed=DESCEND_SPEED / 2,
            limits=self._keepout(self.surface.region),
            stop_on_contact=True,
            tolerance=(0.008, 0.1),
        )

    def _clear_askew(self) -> MotionHandle:
        """Straight up, clear of its top, so the next look sees it and the next grasp starts from above."""
        self.target.held_by = None
        self.target.confidence = 0.0  # where it stands now is for the camera to say
        hand = self._hand_xyz(self.params.side)
        return self.context.robot.whole_body.reach(
            self.params.side,
            self._pose(hand + np.array([0.0, 0.0, LIFT_HEIGHT])),
            speed=DESCEND_SPEED,
            move_base=False,
            tolerance=CARRY_TOLERANCE,
        )

    def _fail_askew(self) -> None:
        raise PhaseFailure(
            f"the {self.target.name} slipped in the {self.params.side} hand (held {self.width_held * 100:.1f} cm "
            f"wide, grasped at {self.grasp.width * 100:.1f} cm): set it down to grasp it afresh"
        )

    def on_failure(self) -> None:
        # a failed grasp leaves the hand open and above the object, ready for another attempt
        felt = self._felt_at_the_edge() if self.phase == "close" else None
        if felt is not None:
            self._felt_off_centre(felt)  # stopped at the pads' edge: it stands that way
        if self.phase in ("descend", "close", "set it down again"):
            self.context.robot.grippers.command(self.params.side, "open")
        if self.phase == "descend":
            self._note_short_reach(self.target, self.grasp.position)
        out_of_reach = isinstance(self.motion, ReachHandle) and self.motion.out_of_reach
        if self.phase == "descend" and self.target.kind == "mug" and not self.target.yaw_known and not out_of_reach:
            # blocked on the way down: most likely a finger on the handle, which is not where it was guessed
            self.target.yaw += math.pi / 2


# --------------------------------------------------------------------------- put


class PutParams(StrictModel):
    surface: str = Field(description="the support surface to put the held object on")
    at: tuple[float, float] | None = Field(None, description="[x, y] spot (m, world); default: straight ahead")
    side: Side = Field("right", description="the hand holding the object")


# a put that failed (the spot blocked, out of reach) is tried again from a new stance
@skill(
    "put",
    "put the held object down on a surface: above the spot, lower until contact, release, retreat",
    recovery={"replan": 1},
)
class Put(_ManipulationSkill):
    Params = PutParams

    @classmethod
    def check(cls, params: PutParams, context: CheckContext) -> list[tuple[str, str]]:
        world = context.world
        return check_name(params.surface, world.surfaces, "surface", "surface") + check_in_map(params.at, world)

    def phases(self):
        return [
            ("plan", self._plan),
            ("raise", lambda: self._rise_over(self.params.side, self.surface, self.release[:2], 0.0)),
            ("above the spot", self._above),
            ("lower", self._lower),
            ("release", self._release),
            ("retreat", self._retreat),
            ("carry", self._carry_away),
        ]

    def _plan(self) -> None:
        side = self.params.side
        self.held = self.context.world_model.held(side)
        if self.held is None:
            raise PhaseFailure(f"the {side} hand holds nothing")
        self.surface = self._surface(self.params.surface)
        whole_body = self.context.robot.whole_body
        hand = whole_body.frame_pose(whole_body.hand_frame(side))
        if self.params.at is not None:
            spot = np.array(self.params.at, dtype=float)
        else:
            spot = self._spot_ahead(hand.translation[:2])
        if not self.surface.contains(spot, margin=EDGE_MARGIN):
            raise PhaseFailure(f"spot ({spot[0]:.2f}, {spot[1]:.2f}) is not on the {self.surface.name}")
        # a spot something already stands on (as believed) moves aside to the nearest free one
        free = nearest_free(self.surface, self.context.world_model, spot, self.held.footprint_radius, (self.held.id,))
        if free is None:
            raise PhaseFailure(
                f"spot ({spot[0]:.2f}, {spot[1]:.2f}) on the {self.surface.name} is taken, and nothing within "
                f"{MAX_SHIFT * 100:.0f} cm of it is free"
            )
        spot = free
        # the hand sits this far above the object's bottom (as grasped)
        self.below_hand = self.held.grip_offset + float(self.held.size[2]) / 2
        release_z = self.surface.height + RELEASE_GAP + self.below_hand
        self.rotation = hand.rotation.copy()
        self.release = np.array([spot[0], spot[1], release_z])

    def _spot_ahead(self, hand_xy: np.ndarray) -> np.ndarray:
        """The nearest point of the surface to the hand, 12 cm in from the edge."""
        region = self.surface.region
        return np.clip(hand_xy, region[0] + 0.12, region[1] - 0.12)

    def _above(self) -> MotionHandle:
        limits = [*self._keepout(self.surface.region), self._clearance(self.params.side, self.surface, self.below_hand)]
        limits += self._keep_clear(self.params.side, self.surface, except_at=self.release)
        target = pin.SE3(self.rotation, self.release + np.array([0.0, 0.0, APPROACH_CLEARANCE + 0.02]))
        return self.context.robot.whole_body.reach(self.params.side, target, gaze=self.release, limits=limits)

    def _lower(self) -> MotionHandle:
        target = pin.SE3(self.rotation, self.release)
        robot, side, weight = self.context.robot, self.params.side, self.held.weight or 0.0
        touched = None
        if robot.weighs(side):  # the wrist feels the surface take the weight (a balancing arm lags as it moves)

            def touched() -> bool:  # a thing too light to feel is lowered all the way: its release is that low
                return robot.load(side) < (1.0 - LOAD_TAKEN) * weight

        return robot.whole_body.reach(
            side,
            target,
            speed=DESCEND_SPEED / 2,
            gaze=self.release,
            limits=self._keepout(self.surface.region),
            stop_on_contact=True,
            touched=touched,
        )

    def _release(self) -> MotionHandle:
        hand = self.context.robot.whole_body.frame_pose(self.context.robot.whole_body.hand_frame(self.params.side))
        self.held.held_by = None
        x, y, _ = hand.translation
        self.held.position = np.array([x, y, self.surface.height + self.held.size[2] / 2])
        self.held.last_seen = self.context.clock()
        # put down: wherever it is taken from next, its stance starts afresh
        self.held.step_to = None
        return self.context.robot.grippers.command(self.params.side, "open")

    def on_failure(self) -> None:
        if self.phase == "lower":
            self._note_short_reach(self.held, self.release)

    def _retreat(self) -> MotionHandle:
        """Straight up until the open pads clear the top of what was just put down."""
        top_above_grip = float(self.held.size[2]) - self.below_hand
        rise = max(LIFT_HEIGHT, top_above_grip + PAD_HALF_HEIGHT + APPROACH_CLEARANCE / 2)
        # and over the things between here and the carry pose
        things = things_on(self.context.world_model, self.surface, (self.held.id,))
        over = transit_height(self.release[:2], self._carry_xy(self.params.side), things, PAD_HALF_HEIGHT)
        rise = min(max(rise, over - self.release[2]), MAX_CARRY_HEIGHT - self.release[2])
        target = pin.SE3(self.rotation, self.release + np.array([0.0, 0.0, rise]))
        return self.context.robot.whole_body.reach(
            self.params.side, target, speed=DESCEND_SPEED, move_base=False, tolerance=CARRY_TOLERANCE
        )

    def _carry_away(self) -> MotionHandle:
        """Back to the carry pose, the pads kept above the placed object while the hand is over the surface."""
        clearance = self._clearance(self.params.side, self.surface, float(self.held.size[2]) + PAD_HALF_HEIGHT)
        return self._carry(self.params.side, [clearance])


# --------------------------------------------------------------------------- drop


class DropParams(StrictModel):
    into: str = Field(description="an open bin of the world to drop the held object into")
    side: Side = Field("right", description="the hand holding the object")


DROP_CLEARANCE = 0.05  # m between the bottom of what the hand holds and the top of the bin's walls, when let go
WALL_MARGIN = 0.03  # m round a bin's opening: its walls, which the hand and base keep clear of
OPEN_ENOUGH = 0.9  # of the gripper's full opening: pads this far apart hold nothing


# a drop that failed (the opening out of reach from where the robot stands) is tried again once
@skill(
    "drop",
    "drop the held object into an open bin: hold it over the opening, let go, check the hand is empty",
    recovery={"replan": 1},
)
class Drop(_ManipulationSkill):
    Params = DropParams

    @classmethod
    def check(cls, params: DropParams, context: CheckContext) -> list[tuple[str, str]]:
        return check_name(params.into, context.world.containers, "into", "container")

    def phases(self):
        return [
            ("plan", self._plan),
            ("over the opening", self._over),
            ("let go", self._let_go),
            ("check the hand", self._check_empty),
            ("carry", lambda: self._carry(self.params.side, [self.walls])),
        ]

    def _plan(self) -> None:
        side = self.params.side
        self.held = self.context.world_model.held(side)
        if self.held is None:
            raise PhaseFailure(f"the {side} hand holds nothing")
        container = self.context.world.containers[self.params.into]  # the map's bins, like its surfaces
        opening = np.array(container.opening, dtype=float)
        self.opening = opening
        self.footprint = opening + np.array([[-WALL_MARGIN, -WALL_MARGIN], [WALL_MARGIN, WALL_MARGIN]])
        self.bin_height = container.height
        # what hangs below the hand clears the walls on the way in, and is let go just above them
        below_hand = self.held.grip_offset + float(self.held.size[2]) / 2
        frame = self.context.robot.whole_body.hand_frame(side)
        self.walls = ClearanceLimit(frame, container.height + below_hand + APPROACH_CLEARANCE / 2, self.footprint)
        centre = opening.mean(axis=0)
        self.release = np.array([*centre, container.height + below_hand + DROP_CLEARANCE])

    def _over(self) -> MotionHandle:
        hand = self.context.robot.whole_body.frame_pose(self.context.robot.whole_body.hand_frame(self.params.side))
        target = pin.SE3(hand.rotation.copy(), self.release)  # as held: nothing swings
        # to be let go, the hand must open fully here: within the gripper's open range
        limits = [*self._keepout(self.footprint), self.walls, *self._open_hand(self.params.side)]
        return self.context.robot.whole_body.reach(self.params.side, target, gaze=self.release, limits=limits)

    def _let_go(self) -> MotionHandle:
        self.held.held_by = None
        # believed in the bin (somewhere on its floor) until it is seen again
        self.held.position = np.array([*self.opening.mean(axis=0), float(self.held.size[2]) / 2])
        self.held.last_seen = self.context.clock()
        return self.context.robot.grippers.command(self.params.side, "open")

    def _check_empty(self) -> None:
        side = self.params.side
        gripper = self.context.robot_config.grippers[side]
        full = len(gripper.joints) * gripper.open
        width = self.context.robot.grippers.width(side)
        if width < OPEN_ENOUGH * full or self.context.world_model.held(side) is not None:
            raise PhaseFailure(f"the {side} hand opened only {width * 100:.1f} cm: something is still in it")


# --------------------------------------------------------------------------- release, look_at, give


class ReleaseParams(StrictModel):
    side: Side = Field("right", description="which hand opens")


@skill("release", "open a hand and let go of what it holds, wherever it is")
class Release(_ManipulationSkill):
    Params = ReleaseParams

    def phases(self):
        return [("open", self._open)]

    def _open(self) -> MotionHandle:
        held = self.context.world_model.held(self.params.side)
        if held is not None:
            held.held_by = None
            held.confidence = 0.0  # it falls somewhere: unknown until seen
        return self.context.robot.grippers.command(self.params.side, "open")
