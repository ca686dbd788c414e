"""The static map: the scene's fixed collision geometry projected onto the floor.

This is the robot's floor plan of its home, built once from the world file
(like the named places of world.yaml): every collidable geom welded to the
world that reaches into the band of heights the robot occupies
(``sim/fixed_geometry.py``). Free bodies
(objects) and the robot itself are not part of it; moving things are known
only through the depth camera.
"""

from __future__ import annotations

import mujoco
import numpy as np

from bt_humanoid.navigation.occupancy import OccupancyGrid
from bt_humanoid.sim.fixed_geometry import fill_polygon, fixed_footprints

FLOOR_CLEARANCE = 0.03  # m: geoms entirely below this (rugs, the floor) do not block
ROBOT_HEIGHT = 1.9  # m: geoms entirely above this (lamps, shelves overhead) do not block


def static_map(model: mujoco.MjModel, data: mujoco.MjData, bounds: np.ndarray, resolution: float) -> OccupancyGrid:
    """An OccupancyGrid whose static layer holds the fixed geometry between the floor and the robot's height."""
    grid = OccupancyGrid(bounds, resolution)
    for footprint in fixed_footprints(model, data, (FLOOR_CLEARANCE, ROBOT_HEIGHT)):
        fill_polygon(grid.static, grid.origin, grid.resolution, footprint)
    # the bounds are the walls' inner faces: the outermost cells are wall too
    grid.static[[0, -1], :] = True
    grid.static[:, [0, -1]] = True
    return grid
