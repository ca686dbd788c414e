"""Where the base should stand to work on a spot of a support surface.

The robot faces the surface edge nearest the spot (walls permitting), its
footprint a small clearance from the edge, shifted sideways so the spot lies
in front of the working hand. A spot too deep into the surface is refused.
"""

from __future__ import annotations

import math

import numpy as np

from bt_humanoid.perception.world_model import SupportSurface

EDGE_CLEARANCE = 0.05  # m between the footprint and the surface edge
HAND_LATERAL = 0.18  # m: the working hand reaches this far to its side of the base centre line
MAX_DEPTH = 0.42  # m: the deepest spot behind an edge the arm reaches


class StanceError(ValueError):
    """No stance reaches the spot."""


def stance_for(
    spot: np.ndarray,
    surface: SupportSurface,
    side: str,
    footprint_radius: float,
    bounds: np.ndarray,
    robot_xy: np.ndarray,
) -> tuple[float, float, float]:
    """Base pose (x, y, yaw rad) from which ``side``'s hand reaches ``spot`` on ``surface``.

    Of the edges that reach the spot, the one whose stance is nearest the robot wins.
    """
    (x0, y0), (x1, y1) = surface.region
    x, y = float(spot[0]), float(spot[1])
    standoff = footprint_radius + EDGE_CLEARANCE
    # (depth of the spot behind the edge, stance position on the line through the spot, facing yaw)
    edges = [
        (x - x0, np.array([x0 - standoff, y]), 0.0),
        (x1 - x, np.array([x1 + standoff, y]), math.pi),
        (y - y0, np.array([x, y0 - standoff]), math.pi / 2),
        (y1 - y, np.array([x, y1 + standoff]), -math.pi / 2),
    ]
    lateral = HAND_LATERAL if side == "right" else -HAND_LATERAL
    options = []
    for depth, position, yaw in edges:
        left = np.array([-math.sin(yaw), math.cos(yaw)])
        stance = position + lateral * left  # the spot ends up on the working hand's side
        inside = np.all(stance >= bounds[0] + footprint_radius) and np.all(stance <= bounds[1] - footprint_radius)
        if inside:
            options.append((depth, stance, yaw))
    if not options:
        raise StanceError(f"no room to stand beside the {surface.name}")
    reachable = [option for option in options if option[0] <= MAX_DEPTH]
    if reachable:
        depth, stance, yaw = min(reachable, key=lambda option: float(np.linalg.norm(option[1] - robot_xy)))
    else:
        depth, stance, yaw = min(options, key=lambda option: option[0])
    if depth > MAX_DEPTH:
        raise StanceError(
            f"spot ({x:.2f}, {y:.2f}) is {depth:.2f} m behind the nearest free edge of the {surface.name}; "
            f"the arm reaches {MAX_DEPTH:.2f} m"
        )
    return float(stance[0]), float(stance[1]), yaw
