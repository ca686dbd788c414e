"""The static map: the scene's fixed collision geometry projected onto the floor.

This is the robot's floor plan of its home, built once from the world file
(like the named places of world.yaml): every collidable geom welded to the
world that reaches into the band of heights the robot occupies. Free bodies
(objects) and the robot itself are not part of it; moving things are known
only through the depth camera.
"""

from __future__ import annotations

import cv2
import mujoco
import numpy as np

from bt_humanoid.navigation.occupancy import OccupancyGrid

FLOOR_CLEARANCE = 0.03  # m: geoms entirely below this (rugs, the floor) do not block
ROBOT_HEIGHT = 1.9  # m: geoms entirely above this (lamps, shelves overhead) do not block


def static_map(model: mujoco.MjModel, data: mujoco.MjData, bounds: np.ndarray, resolution: float) -> OccupancyGrid:
    """An OccupancyGrid whose static layer holds the fixed geometry between the floor and the robot's height."""
    grid = OccupancyGrid(bounds, resolution)
    for geom in range(model.ngeom):
        body = int(model.geom_bodyid[geom])
        if model.body_weldid[body] != 0 or model.geom_type[geom] == mujoco.mjtGeom.mjGEOM_PLANE:
            continue  # moves (robot, objects, people who walk), or the floor itself
        if model.geom_contype[geom] == 0 and model.geom_conaffinity[geom] == 0:
            continue  # visual only
        footprint = _footprint(model, data, geom)
        if footprint is None:
            continue
        _fill(grid, footprint)
    # the bounds are the walls' inner faces: the outermost cells are wall too
    grid.static[[0, -1], :] = True
    grid.static[:, [0, -1]] = True
    return grid


def _fill(grid: OccupancyGrid, polygon: np.ndarray) -> None:
    """Mark the cells whose centres lie inside a convex polygon (counter-clockwise vertices)."""
    low, high = polygon.min(axis=0), polygon.max(axis=0)
    (r0, c0), (r1, c1) = (np.array(grid.cell(p)) for p in (low, high))
    rows, cols = np.mgrid[max(r0, 0) : min(r1, grid.shape[0] - 1) + 1, max(c0, 0) : min(c1, grid.shape[1] - 1) + 1]
    centres = grid.centre(rows, cols)
    inside = np.ones(rows.shape, dtype=bool)
    for a, b in zip(polygon, np.roll(polygon, -1, axis=0), strict=True):
        edge, offset = b - a, centres - a
        inside &= edge[0] * offset[..., 1] - edge[1] * offset[..., 0] >= -1e-9
    grid.static[rows[inside], cols[inside]] = True


def _footprint(model: mujoco.MjModel, data: mujoco.MjData, geom: int) -> np.ndarray | None:
    """Floor polygon (N, 2) of a geom's bounding box, or None if it is outside the robot's height band."""
    centre = data.geom_xpos[geom]
    rotation = data.geom_xmat[geom].reshape(3, 3)
    aabb_centre, half = model.geom_aabb[geom, :3], model.geom_aabb[geom, 3:]
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
    world = centre + (aabb_centre + corners * half) @ rotation.T
    if world[:, 2].max() < FLOOR_CLEARANCE or world[:, 2].min() > ROBOT_HEIGHT:
        return None
    hull = cv2.convexHull(world[:, :2].astype(np.float32), clockwise=False)
    return hull.reshape(-1, 2).astype(float)
