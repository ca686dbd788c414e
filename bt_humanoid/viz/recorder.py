"""Off-screen video of a run from a scene camera (EGL, no display needed)."""

from __future__ import annotations

from pathlib import Path

import cv2
import mujoco

from bt_humanoid.errors import UserError
from bt_humanoid.sim.simulation import Simulation


class VideoRecorder:
    """Grabs a frame every 1/fps of simulation time; call ``capture()`` often, ``close()`` at the end."""

    def __init__(
        self, sim: Simulation, path: Path, camera: str = "overview", fps: int = 30, size: tuple[int, int] = (640, 360)
    ) -> None:
        if path.suffix.lower() not in (".mp4", ".avi"):
            raise UserError(f"--record {path}: unsupported video type", hint="use a .mp4 or .avi file name")
        if camera not in [sim.model.camera(i).name for i in range(sim.model.ncam)]:
            raise UserError(f"--record: the world has no camera '{camera}'")
        self.sim = sim
        self.camera = camera
        self.period = 1.0 / fps
        self.next_frame = 0.0
        width, height = size
        self.renderer = mujoco.Renderer(sim.model, height, width)
        path.parent.mkdir(parents=True, exist_ok=True)
        codec = cv2.VideoWriter_fourcc(*("mp4v" if path.suffix.lower() == ".mp4" else "MJPG"))
        self.writer = cv2.VideoWriter(str(path), codec, fps, (width, height))
        if not self.writer.isOpened():
            raise UserError(f"--record {path}: cannot open the video file for writing")
        self.frames = 0

    def capture(self) -> None:
        if self.sim.time + 1e-9 < self.next_frame:
            return
        self.next_frame += self.period
        self.renderer.update_scene(self.sim.data, camera=self.camera)
        self.writer.write(cv2.cvtColor(self.renderer.render(), cv2.COLOR_RGB2BGR))
        self.frames += 1

    def close(self) -> None:
        self.writer.release()
        self.renderer.close()
