"""The map a planar scan is matched against: signed distance to the fixed geometry at the scanner's height.

Built once from the world (the same fixed geoms as the navigator's floor plan, cut at the scanner's height:
a table's legs, not its top). A scan point that lies on a surface reads 0, one in free space the distance to
the nearest surface, one inside geometry minus its depth; the field is smooth across surfaces, so a
Gauss-Newton matcher can follow its gradient (the likelihood-field idea of AMCL and Hector SLAM).
"""

from __future__ import annotations

from functools import lru_cache

import cv2
import mujoco
import numpy as np

from bt_humanoid.sim.fixed_geometry import fill_polygon, fixed_footprints
from bt_humanoid.sim.simulation import Simulation

RESOLUTION = 0.01  # m per cell: a scan point's noise (1.5 cm) is coarser
BAND = 0.05  # m above and below the scanner's height: geometry the beam can touch
WALL = 0.3  # m of wall beyond the map's bounds


class ScanMap:
    """Signed distance (m) from every point of the floor to the fixed geometry at one height; outside the map's
    bounds, as far as ``outside`` (the walls enclose it)."""

    def __init__(self, occupied: np.ndarray, origin: np.ndarray, resolution: float, outside: float = 1.0) -> None:
        self.origin = np.asarray(origin, dtype=float)
        self.resolution = resolution
        self.outside = outside
        free = (~occupied).astype(np.uint8)
        # distance from each free cell's centre to the nearest occupied cell's centre, and the other way round;
        # surfaces lie half a cell short of either
        to_occupied = cv2.distanceTransform(free, cv2.DIST_L2, cv2.DIST_MASK_PRECISE) * resolution
        to_free = cv2.distanceTransform(1 - free, cv2.DIST_L2, cv2.DIST_MASK_PRECISE) * resolution
        half = 0.5 * resolution
        self.distance = np.where(occupied, -(to_free - half), to_occupied - half).astype(np.float64)
        gradient_y, gradient_x = np.gradient(self.distance, resolution)
        # one array of (distance, ∂/∂x, ∂/∂y) per cell: a lookup gathers each corner's three at once
        self._fields = np.stack([self.distance, gradient_x, gradient_y], axis=-1)
        self.occupied = occupied
        for field in (self.distance, self._fields, self.occupied):  # robots may share one map: never written
            field.flags.writeable = False

    @classmethod
    def from_world(cls, model: mujoco.MjModel, data: mujoco.MjData, bounds: np.ndarray, height: float) -> ScanMap:
        """The fixed geometry of the world ``model`` that a scanner at ``height`` m sees, within ``bounds``."""
        (x0, y0), (x1, y1) = np.asarray(bounds, dtype=float)
        pad = round(WALL / RESOLUTION)  # the bounds are the walls' inner faces: solid beyond them
        origin = np.array([x0, y0]) - pad * RESOLUTION
        columns, rows = round((x1 - x0) / RESOLUTION) + 2 * pad, round((y1 - y0) / RESOLUTION) + 2 * pad
        occupied = np.ones((rows, columns), dtype=bool)
        occupied[pad:-pad, pad:-pad] = False
        for footprint in fixed_footprints(model, data, (height - BAND, height + BAND)):
            fill_polygon(occupied, origin, RESOLUTION, footprint)
        return _built(occupied.tobytes(), occupied.shape, (float(origin[0]), float(origin[1])))

    @classmethod
    def for_robot(cls, sim: Simulation) -> ScanMap:
        """The map the robot's base scanner is matched against, in the robot's world."""
        assert sim.robot.scanner is not None
        return cls.from_world(sim.model, sim.data, np.array(sim.world.bounds), sim.robot.scanner.height)

    def lookup(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(distance, ∂/∂x, ∂/∂y) at world points (N, 2), bilinear between cell centres; a point off the map
        reads ``outside`` with no gradient."""
        rows, cols = self.distance.shape
        grid = (np.asarray(points, dtype=float) - self.origin) / self.resolution - 0.5
        col0, row0 = np.floor(grid[:, 0]).astype(int), np.floor(grid[:, 1]).astype(int)
        on_map = (col0 >= 0) & (row0 >= 0) & (col0 < cols - 1) & (row0 < rows - 1)
        values = np.zeros((len(grid), 3))
        values[:, 0] = self.outside
        if on_map.any():
            c, r = col0[on_map], row0[on_map]
            fx, fy = (grid[on_map, 0] - c)[:, None], (grid[on_map, 1] - r)[:, None]
            fields = self._fields
            values[on_map] = (1 - fy) * ((1 - fx) * fields[r, c] + fx * fields[r, c + 1]) + fy * (
                (1 - fx) * fields[r + 1, c] + fx * fields[r + 1, c + 1]
            )
        return values[:, 0], values[:, 1], values[:, 2]


@lru_cache(maxsize=2)
def _built(cells: bytes, shape: tuple[int, int], origin: tuple[float, float]) -> ScanMap:
    """The map of one floor plan, made once per process: every episode of a suite in one world has the same fixed
    geometry (its fields are never written, so the robots of those episodes share it)."""
    occupied = np.frombuffer(cells, dtype=bool).reshape(shape).copy()
    return ScanMap(occupied, np.array(origin), RESOLUTION)
