"""A planar safety laser scanner low on the base: ranges all round the robot at one height.

Mobile robots that work near people carry one (the head camera looks where
the robot goes; the scanner also sees who comes from the side or behind).
Each ray is cast through the scene (``raycast``) from the scanner's
current pose, as a real scanner measures time of flight; the robot's own
base is skipped, as a scanner's housing is. Hits on the robot's own bodies
(``own``) are dropped: legs that cross the scan plane blind those rays, as
they would a real scanner's. A robot with legs therefore carries more than one
head (``ScannerConfig.mounts``: ahead of and behind its legs), as vehicles
whose own structure blinds one scanner carry two at opposite corners; one scan
is all the heads' hits, in the base's frame.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import mujoco
import numpy as np

from bt_humanoid.perception.raycast import cast_rays
from bt_humanoid.sim.robot_config import ScannerConfig


class SafetyScanner:
    """``scan()`` gives the points (x, y) where the rays hit something, in the scanner's frame (the base's: x
    ahead, y to the left, from the base's centre), once per scan period; each fresh scan also goes to
    ``listeners`` (points, time): localisation matches it to the map."""

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        base_body: int,
        config: ScannerConfig,
        own: set[int] | None = None,
        noise: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] | None = None,
    ) -> None:
        """``noise``: exact ranges (m) → reported ranges and which rays returned (the robot's range model)."""
        self.model, self.data = model, data
        self.base_body = base_body
        self._own_geom = np.isin(model.geom_bodyid, sorted(own or ()))  # geoms of the robot's own bodies
        self.config = config
        self._angles = np.linspace(0.0, 2 * math.pi, config.rays, endpoint=False)
        self._units = np.stack([np.cos(self._angles), np.sin(self._angles)], axis=1)  # each ray's way, scanner frame
        self._mounts = np.array(config.mounts, dtype=float)  # (heads, 2): each head on the base, m
        heads = len(self._mounts)
        self._starts = np.repeat(self._mounts, config.rays, axis=0)  # (heads × rays, 2): each ray's head
        self._ray_units = np.tile(self._units, (heads, 1))  # (heads × rays, 2): each ray's way
        self._geom_ids = np.zeros(heads * config.rays, dtype=np.int32)
        self._distances = np.zeros(heads * config.rays)
        self.period = 1.0 / config.rate_hz
        self.last_scan = -math.inf
        self.noise = noise
        self.listeners: list[Callable[[np.ndarray, float], None]] = []

    def scan(self) -> np.ndarray | None:
        """The hits of a fresh scan (the scanner's frame) when one is due, else None."""
        now = self.data.time
        if now - self.last_scan < self.period - 1e-9:
            return None
        self.last_scan = now
        position = self.data.xpos[self.base_body]
        yaw = math.atan2(self.data.xmat[self.base_body][3], self.data.xmat[self.base_body][0])
        rays = self.config.rays
        directions = np.zeros((rays, 3))
        directions[:, 0] = np.cos(self._angles + yaw)
        directions[:, 1] = np.sin(self._angles + yaw)
        cos, sin = math.cos(yaw), math.sin(yaw)
        for head, (ahead, left) in enumerate(self._mounts):
            x, y = position[0] + cos * ahead - sin * left, position[1] + sin * ahead + cos * left
            origin = np.array([x, y, self.config.height])
            cast_rays(
                self.model,
                self.data,
                origin,
                directions,
                self.config.range,
                self._geom_ids[head * rays : (head + 1) * rays],
                self._distances[head * rays : (head + 1) * rays],
                self.base_body,
            )
        hit = self._geom_ids >= 0
        hit[hit] = ~self._own_geom[self._geom_ids[hit]]
        ranges = self._distances
        if self.noise is not None:
            ranges, returned = self.noise(ranges)
            hit &= returned
        # measured along each ray, in the scanner's own frame: where the robot is, it does not know from here
        points = self._starts[hit] + self._ray_units[hit] * ranges[hit, None]
        for listener in self.listeners:
            listener(points, now)
        return points
