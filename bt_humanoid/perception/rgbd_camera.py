"""The head RGB-D camera: rendered colour and depth frames, with intrinsics and pose from the MJCF.

MuJoCo's OpenGL renderer draws the scene off-screen (EGL) from the camera. Shadows,
reflections and the skybox are off: they cost most of the rendering time and
a depth camera's colour stream has no use for them. Each frame carries what
is needed to turn a pixel into a world point.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
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
    own_body: np.ndarray | None = None  # (H, W) bool: pixels of the robot's own body, from its kinematic model

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
# flat colours, one per geom: a pass that reads which geom each pixel shows, and depth more exactly far away
_SEGMENT = (mujoco.mjtRndFlag.mjRND_SEGMENT, mujoco.mjtRndFlag.mjRND_IDCOLOR)


@contextmanager
def _sensor_buffers(model: mujoco.MjModel, width: int, height: int) -> Iterator[None]:
    """While a camera's render context is made: buffers for a sensor, not for a viewer (a recording's renderer
    keeps the model's own). No multisampling: it doubled the rendering time (an edge pixel shows one side's
    colour, not a blend). A frame of the camera's size, and the smallest shadow map: shadows are not drawn (a
    4096² one took most of the time a context took to make)."""
    quality, buffer = model.vis.quality, model.vis.global_
    kept = quality.offsamples, quality.shadowsize, buffer.offwidth, buffer.offheight
    quality.offsamples, quality.shadowsize, buffer.offwidth, buffer.offheight = 0, 1, width, height
    try:
        yield
    finally:
        quality.offsamples, quality.shadowsize, buffer.offwidth, buffer.offheight = kept


class _OwnedGLContext(mujoco.GLContext):
    """An OpenGL context freed only by its camera, after what was drawn with it: collected on its own, it could go
    first, and MuJoCo's render context would then free its textures in whichever context is current."""

    def __del__(self) -> None:
        pass


class RgbdCamera:
    """Renders one MuJoCo camera at a fixed resolution, with the robot's sensor models (noise, missing depth).

    One frame is two passes of one OpenGL context: colour, then depth with each pixel's geom. The geoms give the
    robot its own body's pixels (``RgbdFrame.own_body``: a real robot knows them from its kinematic model) and,
    for training and benchmarks only, ``geoms``: the ground truth of what each pixel shows.
    """

    def __init__(self, sim: Simulation, camera: str, width: int, height: int) -> None:
        self.sim = sim
        self.name = camera
        self.camera = sim.model.camera(camera).id
        self.width, self.height = width, height
        model = sim.model
        self._gl = _OwnedGLContext(width, height)
        self._gl.make_current()
        with _sensor_buffers(model, width, height):
            self._context: mujoco.MjrContext | None = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_50)
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self._context)
        self._context.readDepthMap = mujoco.mjtDepthMap.mjDEPTH_ZEROFAR
        self._scene = mujoco.MjvScene(model, maxgeom=model.ngeom + model.nsite + 100)  # all it can draw, and some
        for flag in _OFF:  # the scene's flags stay as set: updating the scene does not touch them
            self._scene.flags[flag] = 0
        self._option = mujoco.MjvOption()
        self._view = mujoco.MjvCamera()
        self._view.type = mujoco.mjtCamera.mjCAMERA_FIXED
        self._view.fixedcamid = self.camera
        self._rect = mujoco.MjrRect(0, 0, width, height)
        root = model.body(sim.robot_root).id
        self._own_geoms = model.body_rootid[model.geom_bodyid] == root  # per geom: part of the robot
        fovy = math.radians(float(model.cam_fovy[self.camera]))
        self.focal = (height / 2) / math.tan(fovy / 2)
        self.dropped_until = -math.inf  # s of simulation time: the camera delivers no frames before then
        #: the last frame's geom per pixel (-1: none). Ground truth: for training and benchmarks, never for the robot
        self.geoms = np.full((height, width), -1)

    def capture(self) -> RgbdFrame | None:
        """A frame, or None while the camera is dropped out (a covered lens, a driver restart)."""
        if self.sim.time < self.dropped_until:
            return None
        data = self.sim.data
        rgb, depth, self.geoms = self._render()
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
            own_body=(self.geoms >= 0) & self._own_geoms[np.maximum(self.geoms, 0)],
        )

    def _render(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Exact colour (H, W, 3 uint8), depth (H, W, m) and geom per pixel (H, W; -1: none), top row first."""
        model, scene, context = self.sim.model, self._scene, self._context
        if context is None:
            raise RuntimeError(f"camera '{self.name}' was closed")
        self._gl.make_current()
        mujoco.mjv_updateScene(model, self.sim.data, self._option, None, self._view, mujoco.mjtCatBit.mjCAT_ALL, scene)
        rgb = np.empty((self.height, self.width, 3), dtype=np.uint8)
        mujoco.mjr_render(self._rect, scene, context)
        mujoco.mjr_readPixels(rgb, None, self._rect, context)
        for flag in _SEGMENT:
            scene.flags[flag] = 1
        ids = np.empty((self.height, self.width, 3), dtype=np.uint8)
        depth = np.empty((self.height, self.width), dtype=np.float32)
        mujoco.mjr_render(self._rect, scene, context)
        mujoco.mjr_readPixels(ids, depth, self._rect, context)
        for flag in _SEGMENT:
            scene.flags[flag] = 0
        # OpenGL's rows run bottom to top
        return np.flipud(rgb), np.flipud(self._metres(depth)), np.flipud(self._geoms_of(ids))

    def _metres(self, depth: np.ndarray) -> np.ndarray:
        """Depth along the optical axis (m) from the depth buffer's reversed-Z values.

        The clip planes in float32, as OpenGL's projection matrix holds them; the inversion in float64.
        """
        extent = self.sim.model.stat.extent
        far = np.float32(self.sim.model.vis.map.zfar * extent)
        near = np.float32(self.sim.model.vis.map.znear * extent)
        c = np.float32(-0.5) * (-(far + near) / (far - near)) - np.float32(0.5)
        d = np.float32(-0.5) * (-(np.float32(2) * far * near) / (far - near))
        return (d / (depth.astype(np.float64) + c)).astype(np.float32).astype(np.float64)

    def _geoms_of(self, ids: np.ndarray) -> np.ndarray:
        """Geom per pixel from a segmentation pass's colours (each a scene geom's index plus one; 0: nothing)."""
        scene = self._scene
        geom_of_segment = np.full(scene.ngeom + 1, -1)
        for g in scene.geoms[: scene.ngeom]:
            if g.segid >= 0 and g.objtype == mujoco.mjtObj.mjOBJ_GEOM:
                geom_of_segment[g.segid + 1] = g.objid
        wide = ids.astype(np.int64)
        segment = wide[..., 0] + wide[..., 1] * 256 + wide[..., 2] * 65536
        return geom_of_segment[segment]

    def close(self) -> None:
        """Free the OpenGL context; ``capture()`` cannot be called afterwards."""
        if self._context is None:
            return
        with self._gl.as_current():  # its textures and buffers, not another camera's that share their numbers
            self._context.free()
        self._context = None
        self._gl.free()

    def __del__(self) -> None:
        if hasattr(self, "_context"):  # not when __init__ failed before making it
            self.close()
