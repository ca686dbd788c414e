"""The head RGB-D camera: rendered colour and depth frames, with intrinsics and pose from the MJCF.

``mujoco.Renderer`` draws the scene off-screen (EGL) from the camera. Shadows,
reflections and the skybox are off: they cost most of the rendering time and
a depth camera's colour stream has no use for them. Each frame carries what
is needed to turn a pixel into a world point.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from bt_humanoid.sim.sensor_models import DepthModel, axial_sigma, colour_image, depth_image
from bt_humanoid.sim.simulation import Simulation

HIDDEN_DEPTH = 100.0  # m given to pixels the robot's own body covers: far beyond anything the detector considers


@dataclass
class RgbdFrame:
    """One capture: colour (H, W, 3 uint8), depth along the optical axis (H, W, m; 0 where nothing returned, as a
    depth camera's driver reports it), intrinsics, pose."""

    rgb: np.ndarray
    depth: np.ndarray
    focal: float  # pixels (square pixels)
    centre: tuple[float, float]  # principal point (pixels)
    position: np.ndarray  # camera origin, world (3,)
    rotation: np.ndarray  # camera axes in the world (3, 3): x right, y up, looking along -z
    time: float
    hidden: np.ndarray | None = None  # (H, W) bool: pixels where the robot's own body blocks the view
    noise: DepthModel | None = None  # the depth's noise, as the camera's data sheet gives it (None: exact)

    def depth_sigma(self, distance: float) -> float:
        """σ (m) of a depth reading at ``distance`` m, square on (0 for an exact camera)."""
        return float(axial_sigma(self.noise, np.array(distance))) if self.noise is not None else 0.0

    def depth_sigmas(self) -> np.ndarray | None:
        """Per pixel, σ (m) of its depth reading (None for an exact camera)."""
        return axial_sigma(self.noise, self.depth) if self.noise is not None else None

    def hide(self, mask: np.ndarray) -> None:
        """Mark ``mask``'s pixels as covered by the robot's own body: nothing there for the detector."""
        self.hidden = mask if self.hidden is None else self.hidden | mask
        self.depth[self.hidden] = HIDDEN_DEPTH

    def is_hidden(self, row: int, col: int) -> bool:
        """Whether the robot's own body covers this pixel (what lies behind it is unknown, not absent)."""
        return self.hidden is not None and bool(self.hidden[row, col])

    def in_image(self, point: np.ndarray) -> bool:
        """Whether a world point in front of the camera projects into the image."""
        local = self.rotation.T @ (np.asarray(point) - self.position)
        if local[2] >= 0:
            return False
        u = self.centre[0] + self.focal * local[0] / -local[2]
        v = self.centre[1] - self.focal * local[1] / -local[2]
        height, width = self.depth.shape
        return bool(0 <= u < width and 0 <= v < height)

    def points(self, rows: np.ndarray | None = None, cols: np.ndarray | None = None) -> np.ndarray:
        """World points of pixels (all of them, as (H, W, 3), or the given ones, as (N, 3))."""
        if rows is None or cols is None:
            rows, cols = np.indices(self.depth.shape)
        z = self.depth[rows, cols]
        x = (cols + 0.5 - self.centre[0]) * z / self.focal
        y = -(rows + 0.5 - self.centre[1]) * z / self.focal  # image rows grow downwards, camera y upwards
        camera = np.stack([x, y, -z], axis=-1)
        return self.position + camera @ self.rotation.T


# shadows, reflections and the sky cost most of a frame's rendering time and tell the detector nothing
_OFF = (mujoco.mjtRndFlag.mjRND_SHADOW, mujoco.mjtRndFlag.mjRND_REFLECTION, mujoco.mjtRndFlag.mjRND_SKYBOX)


class RgbdCamera:
    """Renders one MuJoCo camera at a fixed resolution, with the robot's sensor models (noise, missing depth)."""

    def __init__(self, sim: Simulation, camera: str, width: int, height: int) -> None:
        self.sim = sim
        self.name = camera
        self.camera = sim.model.camera(camera).id
        self.width, self.height = width, height
        self._colour = mujoco.Renderer(sim.model, height, width)
        self._depth = mujoco.Renderer(sim.model, height, width)
        self._depth.enable_depth_rendering()
        fovy = math.radians(float(sim.model.cam_fovy[self.camera]))
        self.focal = (height / 2) / math.tan(fovy / 2)
        self.dropped_until = -math.inf  # s of simulation time: the camera delivers no frames before then

    def capture(self) -> RgbdFrame | None:
        """A frame, or None while the camera is dropped out (a covered lens, a driver restart)."""
        if self.sim.time < self.dropped_until:
            return None
        data = self.sim.data
        rgb = self._render(self._colour)
        depth = self._render(self._depth).astype(np.float64)
        models = self.sim.sensors
        # depth is lost on dark surfaces: how dark they are, not how the colour stream's noise shows them
        depth = depth_image(models.depth, depth, rgb, self.focal, self.sim.random_stream(f"{self.name}.depth"))
        rgb = colour_image(models.colour, rgb, self.sim.random_stream(f"{self.name}.colour"))
        position, rotation = self.sim.on_map(
            data.cam_xpos[self.camera].copy(), data.cam_xmat[self.camera].reshape(3, 3)
        )
        return RgbdFrame(
            rgb=rgb,
            depth=depth,
            focal=self.focal,
            centre=(self.width / 2, self.height / 2),
            position=position,
            rotation=rotation.copy(),
            time=self.sim.time,
            noise=models.depth if models.depth.enabled else None,
        )

    def _render(self, renderer: mujoco.Renderer) -> np.ndarray:
        renderer.update_scene(self.sim.data, camera=self.camera)
        for flag in _OFF:
            renderer.scene.flags[flag] = 0
        return renderer.render()

    def close(self) -> None:
        self._colour.close()
        self._depth.close()
