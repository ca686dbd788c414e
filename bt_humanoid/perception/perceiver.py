"""The robot's perception loop: capture the head camera, detect, fuse into the WorldModel.

It runs at a low rate while a mission runs (a rendered frame costs about
15 ms of CPU time) and on demand when a skill needs a fresh look
(``look()``). The camera's depth comes with its noise and holes (the robot's
sensor models); small holes are filled (``depth_filter.py``) and the detector
allows for the noise. The robot's own body is masked out of every frame from its
kinematic model (the camera's segmentation pass, read for the robot's geoms only), as a real
robot filters itself out of its point cloud. A world whose world.yaml names a
trained detector has its objects recognised by it (``learned_detector.py``);
any other world's by shape rules (``detector.py``).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

from bt_humanoid.perception.depth_filter import cleaned_depth
from bt_humanoid.perception.detector import Detection, detect
from bt_humanoid.perception.fusion import integrate
from bt_humanoid.perception.learned_detector import LearnedDetector
from bt_humanoid.perception.rgbd_camera import RgbdCamera, RgbdFrame
from bt_humanoid.perception.world_model import WorldModel
from bt_humanoid.sim.simulation import Simulation

LOOK_RATE = 1.0  # Hz of background looks while a mission runs


class Perceiver:
    """Keeps the WorldModel's objects up to date from the head camera."""

    def __init__(self, sim: Simulation, world_model: Callable[[], WorldModel], camera: str) -> None:
        config = sim.robot.cameras[camera]
        self.camera = RgbdCamera(sim, camera, config.width, config.height)
        self.world_model = world_model
        self.period = 1.0 / LOOK_RATE
        self.last_look = -math.inf
        self.sim = sim
        self.learned = LearnedDetector.for_world(sim.world) if sim.world.detector is not None else None
        self.frames = 0
        self.look_times: list[float] = []  # wall seconds per look (capture, detection, fusion), for benchmarks
        #: called after each look with its frame and detections (a recorder), the WorldModel already updated
        self.look_listeners: list[Callable[[RgbdFrame, list[Detection]], None]] = []

    def step(self) -> None:
        if self.sim.time - self.last_look >= self.period - 1e-9:
            self.look()

    def halt(self) -> None:
        pass  # nothing moves

    def close(self) -> None:
        """Free the camera; ``look()`` cannot be called afterwards."""
        self.camera.close()
        self.period = math.inf  # no more background looks

    def look(self) -> list[Detection]:
        """Capture a frame now, detect objects in it and fuse them into the WorldModel."""
        self.last_look = self.sim.time
        started = time.perf_counter()
        frame = self.camera.capture()
        if frame is None:
            return []  # no frame: the belief keeps what it had
        frame.depth = cleaned_depth(frame.depth)
        if frame.own_body is not None:  # the robot's own pixels read as far away: nothing there for the detector
            frame.hide(frame.own_body)
        belief = self.world_model()
        surfaces = list(belief.surfaces.values())
        detections = self.learned.detect(frame, surfaces) if self.learned is not None else detect(frame, surfaces)
        integrate(belief, detections, frame)
        self.frames += 1
        self.look_times.append(time.perf_counter() - started)
        for listener in self.look_listeners:
            listener(frame, detections)
        return detections
