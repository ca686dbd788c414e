"""A 2-D occupancy grid of the floor, and how far every cell is from the nearest obstacle.

Cells are square (``resolution`` metres); cell (row, col) covers
x ∈ [x0 + col·res, x0 + (col+1)·res), y likewise with rows. Two layers make up
what is occupied: the static map (furniture and walls, from the scene) and
what the depth camera saw that the static map does not know (a moved chair,
a box in the corridor). The clearance field is recomputed when a layer
changes; planners and followers ask it whether the robot's disc fits.
"""

from __future__ import annotations

import copy

import cv2
import numpy as np


class OccupancyGrid:
    """Static and observed occupancy over a rectangle of the floor, with a clearance field."""

    def __init__(self, bounds: np.ndarray, resolution: float = 0.05, observed_padding: float = 0.0) -> None:
        self.origin = np.asarray(bounds[0], dtype=float)
        self.resolution = resolution
        size = np.ceil((np.asarray(bounds[1]) - self.origin) / resolution).astype(int)
        self.shape = (int(size[1]), int(size[0]))  # rows (y), cols (x)
        self.static = np.zeros(self.shape, dtype=bool)
        self.observed = np.zeros(self.shape, dtype=bool)
        self.seen_at = np.full(self.shape, -np.inf)  # s: when each observed cell was last seen occupied
        self.observed_padding = observed_padding  # m added around what the camera saw
        self._clearance: np.ndarray | None = None
        self._observed_distance = np.full(self.shape, np.inf)
        self._static_distance: np.ndarray | None = None
        self._static_for = self.static

    # ------------------------------------------------------------------ geometry

    def cell(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(rows, cols) of world points (…, 2); may lie outside the grid."""
        index = np.floor((np.asarray(xy, dtype=float) - self.origin) / self.resolution).astype(int)
        return index[..., 1], index[..., 0]

    def centre(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """World (x, y) of cell centres."""
        return self.origin + (np.stack([cols, rows], axis=-1) + 0.5) * self.resolution

    def inside(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        return (rows >= 0) & (rows < self.shape[0]) & (cols >= 0) & (cols < self.shape[1])

    # ------------------------------------------------------------------ layers

    @property
    def occupied(self) -> np.ndarray:
        return self.static | self.observed

    def mark(self, xy: np.ndarray, now: float = 0.0) -> None:
        """Mark the cells under world points as seen occupied (at time ``now``)."""
        rows, cols = self.cell(xy)
        keep = self.inside(rows, cols)
        rows, cols = rows[keep], cols[keep]
        self.seen_at[rows, cols] = now
        new = ~self.observed[rows, cols] & ~self.static[rows, cols]
        if np.any(new):  # the clearance field is recomputed only when something changed
            self.observed[rows[new], cols[new]] = True
            self._clearance = None

    def clear(self, rows: np.ndarray, cols: np.ndarray) -> None:
        """Forget observed obstacles in these cells (seen free)."""
        keep = self.inside(rows, cols)
        rows, cols = rows[keep], cols[keep]
        if np.any(self.observed[rows, cols]):
            self.observed[rows, cols] = False
            self._clearance = None

    def forget_older_than(self, time: float) -> None:
        """Forget observed cells last seen before ``time``: a person seen there has likely walked on."""
        stale = self.observed & (self.seen_at < time)
        if np.any(stale):
            self.observed[stale] = False
            self._clearance = None

    def clear_observed(self) -> None:
        """Forget everything the camera added (the static map stays)."""
        if np.any(self.observed):
            self.observed[:] = False
            self._clearance = None

    def without_observed(self) -> OccupancyGrid:
        """A copy with only the static map: what the floor would be if everything the camera saw moved away."""
        grid = copy.copy(self)
        grid.observed = np.zeros_like(self.observed)
        grid.seen_at = np.full(self.shape, -np.inf)  # its own: what is marked on the copy stays on the copy
        grid._clearance = None
        return grid

    # ------------------------------------------------------------------ clearance

    @property
    def clearance(self) -> np.ndarray:
        """Metres from each cell centre to the nearest obstacle (outside the grid counts as one).

        Observed obstacles count ``observed_padding`` bigger: the camera sees only their near side, and
        what it saw may be a person who moves.
        """
        if self._clearance is None:
            if self._static_distance is None or not np.array_equal(self._static_for, self.static):
                # the furniture's field once: only what the camera sees changes during a run
                self._static_for = self.static.copy()
                self._static_distance = self._distance(self.static, outside_occupied=True)
            static = self._static_distance
            self._observed_distance = self._distance(self.observed, outside_occupied=False)
            self._clearance = np.maximum(np.minimum(static, self._observed_distance - self.observed_padding), 0.0)
        return self._clearance

    def observed_distance_at(self, xy: np.ndarray) -> np.ndarray:
        """Metres from world points to the nearest obstacle the camera added (inf if none; 0 outside the grid)."""
        self.clearance  # noqa: B018 - refreshes the fields
        rows, cols = self.cell(xy)
        inside = self.inside(rows, cols)
        result = np.zeros(np.shape(rows))
        result[inside] = self._observed_distance[rows[inside], cols[inside]]
        return result

    def _distance(self, occupied: np.ndarray, outside_occupied: bool) -> np.ndarray:
        if not np.any(occupied) and not outside_occupied:
            return np.full(self.shape, np.inf)
        free = np.pad(~occupied, 1, constant_values=not outside_occupied).astype(np.uint8)
        distance = cv2.distanceTransform(free, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)[1:-1, 1:-1]
        # distance to the nearest occupied cell's centre; its near edge is half a cell closer
        return np.maximum(distance - 0.5, 0.0) * self.resolution

    def clearance_at(self, xy: np.ndarray) -> np.ndarray:
        """Clearance (m) at world points; 0 outside the grid."""
        rows, cols = self.cell(xy)
        inside = self.inside(rows, cols)
        result = np.zeros(np.shape(rows))
        result[inside] = self.clearance[rows[inside], cols[inside]]
        return result
