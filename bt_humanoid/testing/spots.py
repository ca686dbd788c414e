"""Random spots for set-up: where an object stands that the hand reaches, how furniture is nudged.

Everything here is set-up, done before the first simulation step; what it
draws comes from one numpy Generator, so an episode's scene follows from its
seed alone.
"""

from __future__ import annotations

import math

import numpy as np

from bt_humanoid.control.stance import MAX_DEPTH, StanceError, stances_for
from bt_humanoid.perception.world_model import SupportSurface

EDGE_MARGIN = 0.2  # m between a spot and any edge it is not reached across (the base clears the corners)
MIN_DEPTH = 0.1  # m behind the edge it is reached across: room for the pads
REACH_SLACK = 0.06  # m short of the arm's deepest reach
SPACING = 0.15  # m between an object's spot and any other object
STANCE_ROOM = 0.03  # m of free floor around the base's footprint at every stance that reaches the spot
ATTEMPTS = 2000


def reachable_spot(
    surface: SupportSurface,
    grid,
    footprint: float,
    bounds: np.ndarray,
    others: list[np.ndarray],
    rng: np.random.Generator,
    max_depth: float = MAX_DEPTH,
) -> np.ndarray:
    """A random (x, y) on ``surface`` that the right hand reaches from every free stance beside it: at most
    ``max_depth`` behind the edge (less some slack; the robot's ``deepest_reach``).

    The spot keeps ``EDGE_MARGIN`` from the edges, ``SPACING`` from ``others``, and each edge it can be
    reached across has a stance with free floor around the base.
    """
    (x0, y0), (x1, y1) = surface.region
    centre = (surface.region[0] + surface.region[1]) / 2
    outward = [np.array(v) for v in ((-1.0, 0.0), (1.0, 0.0), (0.0, -1.0), (0.0, 1.0))]
    for _ in range(ATTEMPTS):
        spot = np.array(
            [rng.uniform(x0 + EDGE_MARGIN, x1 - EDGE_MARGIN), rng.uniform(y0 + EDGE_MARGIN, y1 - EDGE_MARGIN)]
        )
        if any(np.hypot(*(spot - other[:2])) < SPACING for other in others):
            continue
        depths = [spot[0] - x0, x1 - spot[0], spot[1] - y0, y1 - spot[1]]
        reached, blocked = 0, False
        for depth, direction in zip(depths, outward, strict=True):
            if depth > max_depth - REACH_SLACK:
                continue
            try:
                x, y, yaw = stances_for(spot, surface, "right", footprint, bounds, centre + 3.0 * direction)[0]
            except StanceError:
                continue
            facing = -np.array([math.cos(yaw), math.sin(yaw)])
            if not np.allclose(facing, direction, atol=1e-6):
                continue  # this edge's stance is off the map: another edge was chosen
            if depth < MIN_DEPTH or grid.clearance_at(np.array([[x, y]]))[0] < footprint + STANCE_ROOM:
                blocked = True
                break
            reached += 1
        if reached and not blocked:
            return spot
    raise ValueError(f"no reachable free spot found on the {surface.name}")


def nudge(position: np.ndarray, shift: float, rng: np.random.Generator) -> np.ndarray:
    """``position`` moved by up to ``shift`` in x and y."""
    return position + np.array([rng.uniform(-shift, shift), rng.uniform(-shift, shift), 0.0])
