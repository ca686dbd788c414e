"""Where the base should stand to work on a spot of a support surface.

The robot faces the surface edge nearest the spot (walls permitting), its
footprint a small clearance from the edge, shifted sideways so the spot lies
in front of the working hand. A spot too deep into the surface is refused.
"""

from __future__ import annotations

import math

import numpy as np

from bt_humanoid.perception.world_model import SupportSurface
from bt_humanoid.sim.robot_config import BaseConfig

EDGE_CLEARANCE = 0.05  # m between the footprint and the surface edge
HAND_LATERAL = 0.18  # m: the working hand reaches this far to its side of the base centre line
MAX_DEPTH = 0.42  # m: the deepest spot behind an edge the arm reaches


class StanceError(ValueError):
    """No stance reaches the spot."""


def stances_for(
    spot: np.ndarray,
    surface: SupportSurface,
    side: str,
    footprint_radius: float,
    bounds: np.ndarray,
    robot_xy: np.ndarray,
    standoff: float | None = None,
    max_depth: float = MAX_DEPTH,
    hand_lateral: float = HAND_LATERAL,
    closest: float | None = None,
    nearer: float = 0.0,
    aside: float = 0.0,
) -> list[tuple[float, float, float]]:
    """Base poses (x, y, yaw rad) from which ``side``'s hand reaches ``spot`` on ``surface``, one per edge that
    reaches it, nearest the robot first (the next ones are where to work from when something stands on the
    first): ``standoff`` m from the edge (default: the footprint ``EDGE_CLEARANCE`` clear of it), the spot at
    most ``max_depth`` behind it and ``hand_lateral`` to the working hand's side. With ``closest``, a deeper
    spot brings the stance nearer the edge by as much, down to ``closest`` m from it: the hand then reaches as
    far ahead of the base; and ``nearer`` m more, still not past ``closest``, and ``aside`` m to its left along
    the edge (a hand that fell short from there: ahead, and to a side)."""
    (x0, y0), (x1, y1) = surface.region
    x, y = float(spot[0]), float(spot[1])
    standoff = footprint_radius + EDGE_CLEARANCE if standoff is None else standoff
    nearest = standoff if closest is None else min(closest, standoff)
    reach = _reach(max_depth, standoff, closest)
    # (depth of the spot behind the edge, the edge's point on the line through the spot, facing yaw)
    edges = [(x - x0, (x0, y), 0.0), (x1 - x, (x1, y), math.pi), (y - y0, (x, y0), math.pi / 2)]
    edges.append((y1 - y, (x, y1), -math.pi / 2))
    lateral = hand_lateral if side == "right" else -hand_lateral
    options = []
    for depth, edge, yaw in edges:
        facing = np.array([math.cos(yaw), math.sin(yaw)])
        distance = float(np.clip(min(standoff, standoff - (depth - max_depth)) - nearer, nearest, standoff))
        left = np.array([-math.sin(yaw), math.cos(yaw)])
        stance = np.array(edge) - distance * facing + (lateral + aside) * left  # the spot on the working hand's side
        inside = np.all(stance >= bounds[0] + footprint_radius) and np.all(stance <= bounds[1] - footprint_radius)
        if inside:
            options.append((depth, stance, yaw))
    if not options:
        raise StanceError(f"no room to stand beside the {surface.name}")
    reachable = [option for option in options if option[0] <= reach]
    if not reachable:
        depth = min(option[0] for option in options)
        raise StanceError(
            f"spot ({x:.2f}, {y:.2f}) is {depth:.2f} m behind the nearest free edge of the {surface.name}; "
            f"the arm reaches {reach:.2f} m"
        )
    reachable.sort(key=lambda option: float(np.linalg.norm(option[1] - robot_xy)))
    return [(float(stance[0]), float(stance[1]), yaw) for _, stance, yaw in reachable]


def working_stance(
    spot: np.ndarray,
    surface: SupportSurface,
    side: str,
    base: BaseConfig,
    bounds: np.ndarray,
    robot_xy: np.ndarray,
    shift: tuple[float, float] = (0.0, 0.0),
) -> tuple[float, float, float]:
    """The nearest stance of ``stances_for`` where the robot's own ``base.working_stance`` says (robot.yaml),
    moved by ``shift`` (m ahead, nearer the edge where its ``closest`` allows; m to the left)."""
    return working_stances(spot, surface, side, base, bounds, robot_xy, shift)[0]


def working_stances(
    spot: np.ndarray,
    surface: SupportSurface,
    side: str,
    base: BaseConfig,
    bounds: np.ndarray,
    robot_xy: np.ndarray,
    shift: tuple[float, float] = (0.0, 0.0),
) -> list[tuple[float, float, float]]:
    """``stances_for`` where the robot's own ``base.working_stance`` says: one per edge, nearest first."""
    stance = base.working_stance
    return stances_for(
        spot,
        surface,
        side,
        base.footprint_radius,
        bounds,
        robot_xy,
        standoff=stance.standoff,
        max_depth=stance.reach_depth,
        hand_lateral=stance.hand_lateral,
        closest=stance.closest,
        nearer=shift[0],
        aside=shift[1],
    )


def deepest_reach(base: BaseConfig) -> float:
    """How far behind a surface's edge the robot's hand reaches from its working stance (robot.yaml
    ``base.working_stance``): what ``working_stance`` refuses beyond."""
    stance = base.working_stance
    standoff = base.footprint_radius + EDGE_CLEARANCE if stance.standoff is None else stance.standoff
    return _reach(stance.reach_depth, standoff, stance.closest)


def _reach(max_depth: float, standoff: float, closest: float | None) -> float:
    """The deepest spot reached: ``max_depth`` from ``standoff``, deeper by what coming to ``closest`` adds."""
    return max_depth + (max(standoff - closest, 0.0) if closest is not None else 0.0)
