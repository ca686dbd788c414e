"""The head camera's depth channel, as rays: where each pixel's ray meets the scene.

A depth camera measures, per pixel, the distance along its ray to the first
surface. Casting those rays (``raycast``) gives the same numbers a
rendered depth image would, at a fraction of the cost, so mapping can run at
the camera rate. The rays sample the image on a coarse grid (mapping needs
no more); hits on the robot's own body are dropped. RGB detection renders
the camera image itself (perception).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np

from bt_humanoid.perception.raycast import cast_rays

MAX_RANGE = 6.0  # m: beyond this a depth camera of this kind returns nothing


@dataclass
class DepthScan:
    """One depth frame: the camera position and, per ray, its unit direction and range (inf: nothing in range)."""

    origin: np.ndarray  # (3,) world
    directions: np.ndarray  # (N, 3) world, unit
    ranges: np.ndarray  # (N,) m
    own_body: np.ndarray  # (N,) bool: the ray hit the robot itself

    @property
    def hits(self) -> np.ndarray:
        """World points of the rays that hit the scene (not the robot) within range."""
        seen = np.isfinite(self.ranges) & ~self.own_body
        return self.origin + self.directions[seen] * self.ranges[seen, None]


class DepthCamera:
    """Ray-cast depth for one MuJoCo camera, sampled on a ``columns`` × ``rows`` grid of its image."""

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        camera: str,
        robot_root: str,
        columns: int = 48,
        rows: int = 36,
        noise: Callable[[np.ndarray], np.ndarray] | None = None,
        on_map: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]] | None = None,
    ) -> None:
        """``noise``: exact ranges (m, inf: nothing) → what the sensor reports (the robot's depth model);
        ``on_map``: places the camera's world pose on the robot's map (``Simulation.on_map``; none: exact)."""
        self.on_map = on_map
        self.model, self.data = model, data
        self.camera = model.camera(camera).id
        fovy = math.radians(float(model.cam_fovy[self.camera]))
        width, height = 4, 3  # aspect of the robot's 320 × 240 camera
        half_h = math.tan(fovy / 2)
        half_w = half_h * width / height
        u = np.linspace(-half_w, half_w, columns)
        v = np.linspace(-half_h, half_h, rows)
        uu, vv = np.meshgrid(u, v)
        # camera frame: x right, y up, looking along -z
        rays = np.stack([uu.ravel(), vv.ravel(), -np.ones(uu.size)], axis=1)
        self._rays = rays / np.linalg.norm(rays, axis=1, keepdims=True)
        root = model.body(robot_root).id
        self._robot_geoms = np.array(
            [model.body_rootid[model.geom_bodyid[g]] == root for g in range(model.ngeom)], dtype=bool
        )
        self._geom_ids = np.zeros(len(self._rays), dtype=np.int32)
        self._distances = np.zeros(len(self._rays))
        self.dropped_until = -math.inf  # s of simulation time: the camera delivers no frames before then
        self.noise = noise

    def scan(self) -> DepthScan | None:
        """Cast every ray from the camera's current pose; None while the camera is dropped out."""
        if self.data.time < self.dropped_until:
            return None
        origin = self.data.cam_xpos[self.camera].copy()
        rotation = self.data.cam_xmat[self.camera].reshape(3, 3)
        directions = self._rays @ rotation.T
        cast_rays(self.model, self.data, origin, directions, MAX_RANGE, self._geom_ids, self._distances)
        ranges = np.where(self._geom_ids >= 0, self._distances, np.inf)
        if self.on_map is not None:  # rays cast where the camera is; reported where the robot believes it is
            origin, rotation = self.on_map(origin, rotation)
            directions = self._rays @ rotation.T
        if self.noise is not None:
            ranges = self.noise(ranges)
        own = (self._geom_ids >= 0) & self._robot_geoms[np.maximum(self._geom_ids, 0)]
        return DepthScan(origin, directions, ranges, own)
