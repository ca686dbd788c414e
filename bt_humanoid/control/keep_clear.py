"""Keeping the hand, and what it holds, clear of the other things on a surface.

The things the robot believes stand on a surface are obstacles to a hand
moving over it: a hand swept sideways at the height of their tops knocks them
over (a bag of chips weighs 40 g). Two tools, both from the belief:

- ``transit_height``: how high the grip site must be for a straight move to
  pass over every thing near its way. A hand rises to it first, straight up,
  then moves across: it never enters the space above a thing from the side.
- ``clearance_limits``: one limit per thing, holding the hand above it while
  the hand is over it, so a reach that starts high does not dip onto it on its
  way down to a lower target.

A thing's footprint is the circle round its extents, widened by the hand's
reach across: the open hand's spread pads, or what a closed one holds.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from bt_humanoid.control.wbc.limits import ClearanceLimit
from bt_humanoid.perception.world_model import SupportSurface, TrackedObject, WorldModel

OPEN_HAND_RADIUS = 0.07  # m from the grip site to the open hand's furthest edge across (spread pads, palm corners)
CLOSED_HAND_RADIUS = 0.05  # m: the palm's half-length, round a closed hand or the grip site of what it holds
THING_MARGIN = 0.02  # m kept between a thing's top and the lowest point of the hand or what it holds
ON_SURFACE = 0.05  # m: a thing whose bottom is this close to a surface's height stands on it


def things_on(world_model: WorldModel, surface: SupportSurface, exclude: Iterable[str] = ()) -> list[TrackedObject]:
    """The things believed to stand on ``surface`` (not held), except those whose ids are in ``exclude``."""
    skip = set(exclude)
    return [
        thing
        for thing in world_model.present()
        if thing.held_by is None
        and thing.id not in skip
        and surface.contains(thing.position[:2])
        and abs(thing.bottom - surface.height) < ON_SURFACE
    ]


def hand_radius(held: TrackedObject | None, is_open: bool) -> float:
    """How far across the hand reaches from its grip site: spread pads, the palm, or what it holds."""
    if held is not None:
        return max(held.footprint_radius, CLOSED_HAND_RADIUS)
    return OPEN_HAND_RADIUS if is_open else CLOSED_HAND_RADIUS


def reach_radius(thing: TrackedObject, hand: float = OPEN_HAND_RADIUS) -> float:
    """How near the grip site may come to ``thing``'s centre, across, before a hand ``hand`` wide touches it."""
    return thing.footprint_radius + hand


def clear_height(thing: TrackedObject, below_hand: float, margin: float = THING_MARGIN) -> float:
    """The grip-site height at which ``below_hand`` metres beneath it pass ``margin`` over ``thing``."""
    return thing.top + below_hand + margin


def over_limit(
    frame: str, thing: TrackedObject, below_hand: float, hand: float = OPEN_HAND_RADIUS, margin: float = THING_MARGIN
) -> ClearanceLimit:
    """A limit holding ``frame`` high enough over ``thing`` while it is over its widened footprint."""
    radius = reach_radius(thing, hand)
    region = np.array([thing.position[:2] - radius, thing.position[:2] + radius])
    return ClearanceLimit(frame, clear_height(thing, below_hand, margin), region)


def distance_to_segment(point: np.ndarray, start: np.ndarray, end: np.ndarray) -> float:
    """Distance (m) in the plane from ``point`` to the segment ``start``–``end``."""
    along = end - start
    length_squared = float(along @ along)
    t = 0.0 if length_squared < 1e-12 else float(np.clip((point - start) @ along / length_squared, 0.0, 1.0))
    return float(np.linalg.norm(point - (start + t * along)))


def transit_height(
    start_xy: np.ndarray,
    end_xy: np.ndarray,
    things: list[TrackedObject],
    below_hand: float,
    hand: float = OPEN_HAND_RADIUS,
) -> float:
    """The lowest grip-site height from which a straight move ``start_xy`` → ``end_xy`` passes over every thing
    near its way, with ``below_hand`` metres hanging beneath the grip site and ``hand`` metres to its sides;
    -inf when nothing is in the way."""
    start, end = np.asarray(start_xy, dtype=float)[:2], np.asarray(end_xy, dtype=float)[:2]
    heights = [
        clear_height(thing, below_hand)
        for thing in things
        if distance_to_segment(thing.position[:2], start, end) < reach_radius(thing, hand)
    ]
    return max(heights, default=-np.inf)


def clearance_limits(
    frame: str,
    things: list[TrackedObject],
    below_hand: float,
    hand: float = OPEN_HAND_RADIUS,
    *,
    except_at: np.ndarray | None = None,
) -> list[ClearanceLimit]:
    """Limits that hold ``frame`` above each of ``things`` while it is over its widened footprint.

    A thing whose widened footprint covers ``except_at`` (the hand's goal: a grasp or a placement beside it)
    gets none: the hand has to come down there anyway, and the last straight move is planned to miss it.
    """

    def covers_goal(thing: TrackedObject) -> bool:
        near = np.abs(except_at[:2] - thing.position[:2]) <= reach_radius(thing, hand) if except_at is not None else [0]
        return bool(np.all(near))

    return [over_limit(frame, thing, below_hand, hand) for thing in things if not covers_goal(thing)]
