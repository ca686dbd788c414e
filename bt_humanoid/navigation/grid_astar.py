"""A* over the occupancy grid: the reference route length the benchmark compares OMPL's routes with.

8-connected cells whose clearance fits the base; the cost is Euclidean
distance. Grid routes zig-zag at 45°, so this is a slight overestimate of
the true shortest route; it is the yardstick, not a planner the robot uses.
"""

from __future__ import annotations

import heapq
import math

import numpy as np

from bt_humanoid.navigation.occupancy import OccupancyGrid

_MOVES = [(dr, dc, math.hypot(dr, dc)) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if dr or dc]


def grid_route_length(grid: OccupancyGrid, start: np.ndarray, goal: np.ndarray, clearance: float) -> float | None:
    """Length (m) of the shortest 8-connected route between the cells of two points, or None if there is none."""
    free = grid.clearance >= clearance
    (r0,), (c0,) = (np.atleast_1d(v) for v in grid.cell(np.asarray(start[:2])[None, :]))
    (r1,), (c1,) = (np.atleast_1d(v) for v in grid.cell(np.asarray(goal[:2])[None, :]))
    free[r0, c0] = free[r1, c1] = True  # the ends may be tighter than the way between them
    rows, cols = free.shape
    best = {(r0, c0): 0.0}
    frontier = [(math.hypot(r1 - r0, c1 - c0), 0.0, r0, c0)]
    while frontier:
        _, cost, r, c = heapq.heappop(frontier)
        if (r, c) == (r1, c1):
            return cost * grid.resolution
        if cost > best.get((r, c), math.inf):
            continue
        for dr, dc, step in _MOVES:
            nr, nc = r + dr, c + dc
            if 0 <= nr < rows and 0 <= nc < cols and free[nr, nc]:
                new = cost + step
                if new < best.get((nr, nc), math.inf):
                    best[(nr, nc)] = new
                    heapq.heappush(frontier, (new + math.hypot(r1 - nr, c1 - nc), new, nr, nc))
    return None
