"""The world's fixed geometry as polygons on the floor: what a map of the home is drawn from.

Every collidable geom welded to the world (walls, furniture; not objects, people who walk or the robot)
whose bounding box reaches into a band of heights, as the convex outline of that box on the floor. The
navigator's floor plan takes the band the robot's body occupies; localisation's map the thin band its scanner
sweeps.
"""

from __future__ import annotations

import cv2
import mujoco
import numpy as np


def fixed_footprints(model: mujoco.MjModel, data: mujoco.MjData, band: tuple[float, float]) -> list[np.ndarray]:
    """Floor polygons (N × 2, counter-clockwise) of the fixed geoms reaching into ``band`` (m above the floor)."""
    polygons = []
    for geom in range(model.ngeom):
        body = int(model.geom_bodyid[geom])
        if model.body_weldid[body] != 0 or model.geom_type[geom] == mujoco.mjtGeom.mjGEOM_PLANE:
            continue  # moves (robot, objects, people who walk), or the floor itself
        if model.geom_contype[geom] == 0 and model.geom_conaffinity[geom] == 0:
            continue  # visual only
        footprint = _footprint(model, data, geom, band)
        if footprint is not None:
            polygons.append(footprint)
    return polygons


def fill_polygon(cells: np.ndarray, origin: np.ndarray, resolution: float, polygon: np.ndarray) -> None:
    """Set the cells (rows: y, columns: x; cell (0, 0) starts at ``origin``) whose centres lie inside a convex
    polygon (counter-clockwise vertices)."""
    shape = cells.shape
    low, high = polygon.min(axis=0), polygon.max(axis=0)
    c0, r0 = np.floor((low - origin) / resolution).astype(int)
    c1, r1 = np.floor((high - origin) / resolution).astype(int)
    rows, cols = np.mgrid[max(r0, 0) : min(r1, shape[0] - 1) + 1, max(c0, 0) : min(c1, shape[1] - 1) + 1]
    centres = origin + (np.stack([cols, rows], axis=-1) + 0.5) * resolution
    inside = np.ones(rows.shape, dtype=bool)
    for a, b in zip(polygon, np.roll(polygon, -1, axis=0), strict=True):
        edge, offset = b - a, centres - a
        inside &= edge[0] * offset[..., 1] - edge[1] * offset[..., 0] >= -1e-9
    cells[rows[inside], cols[inside]] = True


def _footprint(model: mujoco.MjModel, data: mujoco.MjData, geom: int, band: tuple[float, float]) -> np.ndarray | None:
    """Floor polygon (N, 2) of a geom's bounding box, or None if it is outside the height band."""
    centre = data.geom_xpos[geom]
    rotation = data.geom_xmat[geom].reshape(3, 3)
    aabb_centre, half = model.geom_aabb[geom, :3], model.geom_aabb[geom, 3:]
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
    world = centre + (aabb_centre + corners * half) @ rotation.T
    if world[:, 2].max() < band[0] or world[:, 2].min() > band[1]:
        return None
    hull = cv2.convexHull(world[:, :2].astype(np.float32), clockwise=False)
    return hull.reshape(-1, 2).astype(float)
