"""The verdict on a mission: its success conditions checked against the simulator's ground truth at the end.

This is judging, not the mission language: only the engine (after a run), tests and evaluation read ground truth.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from bt_humanoid.control.base_driver import wrap_angle
from bt_humanoid.mission.schema import (
    AtCondition,
    DeliveredCondition,
    GripperCondition,
    InHandCondition,
    InsideCondition,
    NearCondition,
    OnCondition,
    SuccessCondition,
    UprightCondition,
)
from bt_humanoid.sim.ground_truth import GroundTruth


@dataclass(frozen=True)
class ConditionResult:
    condition: str
    holds: bool
    detail: str


def check_condition(condition: SuccessCondition, truth: GroundTruth) -> ConditionResult:
    if isinstance(condition, OnCondition):
        obj, surface = condition.on
        holds = truth.rests_on(obj, surface)
        x, y, z = truth.object_position(obj)
        return ConditionResult(f"{obj} on {surface}", holds, f"{obj} at ({x:.2f}, {y:.2f}, {z:.2f})")
    if isinstance(condition, InsideCondition):
        named, container = condition.inside
        obj = _any(named, truth, lambda o: truth.inside(o, container))
        x, y, z = truth.object_centre(obj)
        return ConditionResult(
            f"{named} in the {container}", truth.inside(obj, container), f"{obj} at ({x:.2f}, {y:.2f}, {z:.2f})"
        )
    if isinstance(condition, AtCondition):
        target = condition.at
        place, tolerance, yaw_tolerance = (
            (target, 0.15, 15.0) if isinstance(target, str) else (target.place, target.tolerance, target.yaw_tolerance)
        )
        px, py, pyaw = truth.sim.world.places[place].pose
        x, y, yaw = truth.robot_pose()
        distance = math.hypot(x - px, y - py)
        heading = abs(math.degrees(wrap_angle(yaw - math.radians(pyaw))))
        holds = distance <= tolerance and heading <= yaw_tolerance
        return ConditionResult(f"robot at {place}", holds, f"{distance:.3f} m and {heading:.1f}° from its pose")
    if isinstance(condition, InHandCondition):
        side = truth.in_hand(_any(condition.in_hand, truth, lambda o: truth.in_hand(o) is not None))
        return ConditionResult(f"{condition.in_hand} in hand", side is not None, f"held by {side or 'no'} gripper")
    if isinstance(condition, UprightCondition):
        holds = truth.upright(condition.upright)
        return ConditionResult(f"{condition.upright} upright", holds, "upright" if holds else "tipped over")
    if isinstance(condition, NearCondition):
        spot = condition.near
        position = truth.object_position(spot.object)
        distance = math.hypot(position[0] - spot.position[0], position[1] - spot.position[1])
        return ConditionResult(
            f"{spot.object} within {spot.within * 100:.0f} cm of ({spot.position[0]:.2f}, {spot.position[1]:.2f})",
            distance <= spot.within,
            f"{distance * 100:.1f} cm away",
        )
    if isinstance(condition, GripperCondition):
        side, state = condition.gripper
        width = truth.gripper_width(side)
        open_width = 2 * truth.sim.robot.grippers[side].open
        holds = width > 0.9 * open_width if state == "open" else width < 0.5 * open_width
        return ConditionResult(f"{side} gripper {state}", holds, f"jaws {width * 100:.1f} cm apart")
    if isinstance(condition, DeliveredCondition):
        named = condition.delivered
        obj = _any(named, truth, lambda o: _handed_over(o, truth)[0])
        holds, detail = _handed_over(obj, truth)
        return ConditionResult(f"{named} handed over", holds, detail if obj == named else f"{obj}: {detail}")
    raise AssertionError(f"unhandled condition {condition!r}")


def _handed_over(obj: str, truth: GroundTruth) -> tuple[bool, str]:
    """In a person's hand (both their fingers on it); else where it is instead."""
    taker = truth.held_by_person(obj)
    if taker is not None:
        return True, f"in the {taker}'s hand"
    held = truth.in_hand(obj)
    if held is not None:
        return False, f"in the robot's {held} hand"
    x, y, _ = truth.object_position(obj)
    distance, person = min((math.dist((x, y), truth.person_position(p)[:2]), p) for p in truth.sim.world.people)
    return False, f"not in a hand: {distance:.2f} m from the {person}"


def _any(named: str, truth: GroundTruth, holds: Callable[[str], bool]) -> str:
    """The object a condition judges: ``named`` itself, or, where a scene has several of it ("coke", "coke 2"),
    the first of them for which ``holds`` (any coke brought is a coke brought), else ``named``."""
    alike = [name for name, kind in truth.sim.object_kinds.items() if kind == named]
    return next((name for name in alike if holds(name)), named) if len(alike) > 1 else named
