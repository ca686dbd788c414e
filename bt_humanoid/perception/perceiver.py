"""The robot's perception loop: capture the head camera, detect, fuse into the WorldModel.

It runs at a low rate while a mission runs (a rendered frame costs about
20 ms of wall time) and on demand when a skill needs a fresh look
(``look()``). The robot's own body is masked out of every frame from its
kinematic model (a segmentation render of the robot's geoms), as a real
robot filters itself out of its point cloud.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import mujoco
import numpy as np

from bt_humanoid.perception.detector import Detection, detect
from bt_humanoid.perception.fusion import integrate
from bt_humanoid.perception.rgbd_camera import RgbdCamera, RgbdFrame
from bt_humanoid.perception.world_model import WorldModel
from bt_humanoid.sim.simulation import Simulation

LOOK_RATE = 1.0  # Hz of background looks while a mission runs


class Perceiver:
    """Keeps the WorldModel's objects up to date from the head camera."""

    def __init__(self, sim: Simulation, world_model: Callable[[], WorldModel], camera: str, robot_root: str) -> None:
        config = sim.robot.cameras[camera]
        self.camera = RgbdCamera(sim, camera, config.width, config.height)
        self.world_model = world_model
        self.period = 1.0 / LOOK_RATE
        self.last_look = -math.inf
        self.sim = sim
        root = sim.model.body(robot_root).id
        self._robot_geoms = np.array(
            [sim.model.body_rootid[sim.model.geom_bodyid[g]] == root for g in range(sim.model.ngeom)]
        )
        self._segmentation = mujoco.Renderer(sim.model, config.height, config.width)
        self._segmentation.enable_segmentation_rendering()
        self.frames = 0
        self.look_times: list[float] = []  # wall seconds per look (capture, detection, fusion), for benchmarks

    def step(self) -> None:
        if self.sim.time - self.last_look >= self.period - 1e-9:
            self.look()

    def halt(self) -> None:
        pass  # nothing moves

    def close(self) -> None:
        """Free the renderers; ``look()`` cannot be called afterwards."""
        self.camera.close()
        self._segmentation.close()
        self.period = math.inf  # no more background looks

    def look(self) -> list[Detection]:
        """Capture a frame now, detect objects in it and fuse them into the WorldModel."""
        self.last_look = self.sim.time
        started = time.perf_counter()
        frame = self.camera.capture()
        if frame is None:
            return []  # no frame: the belief keeps what it had
        self._mask_robot(frame)
        belief = self.world_model()
        detections = detect(frame, list(belief.surfaces.values()))
        integrate(belief, detections, frame)
        self.frames += 1
        self.look_times.append(time.perf_counter() - started)
        return detections

    def _mask_robot(self, frame: RgbdFrame) -> None:
        """The robot's own pixels read as far away: nothing there for the detector."""
        renderer = self._segmentation
        renderer.update_scene(self.sim.data, camera=self.camera.camera)
        segmentation = renderer.render()
        geom = segmentation[..., 0]
        is_geom = segmentation[..., 1] == int(mujoco.mjtObj.mjOBJ_GEOM)
        robot = is_geom & self._robot_geoms[np.clip(geom, 0, len(self._robot_geoms) - 1)]
        frame.hide(robot)
