"""The MuJoCo world in a Rerun recording: every visible geom once, in its body's frame, and the poses of the
bodies that move, buffered and sent as columns.

Geometry is static: each body is an entity (``world/bodies/<body>``) holding its geoms as batches of boxes,
ellipsoids, capsules, cylinders and meshes in the body's frame. Bodies welded to the world get one static
pose; the others (the robot's links, free objects, people driven as mocap bodies) get a pose at each
``sample()``. Samples are copied into a buffer (two array copies) and sent with ``rr.send_columns`` every
few seconds of simulation time, so a sample costs microseconds rather than a log call per body.
"""

from __future__ import annotations

import re
from typing import Any

import mujoco
import numpy as np

from bt_humanoid.sim.simulation import Simulation

VISIBLE_GROUPS = 2  # geom groups 0–2 are drawn by MuJoCo's viewer by default; 3 and up are collision-only
PLANE_MARGIN = 1.0  # m an infinite plane (size 0) is drawn beyond the world's bounds
PLANE_THICKNESS = 0.001  # m (half)
FLOOR_GREY = 90


def entity_part(name: str) -> str:
    """A name usable as one part of an entity path."""
    return re.sub(r"[^A-Za-z0-9_\-]", "_", name) or "_"


def xyzw(wxyz: np.ndarray) -> np.ndarray:
    """MuJoCo's (w, x, y, z) quaternions as Rerun's (x, y, z, w), for one or many."""
    return np.roll(np.asarray(wxyz, dtype=np.float32), -1, axis=-1)


def body_paths(model: mujoco.MjModel) -> list[str]:
    """The entity path of each body."""
    return [f"world/bodies/{entity_part(model.body(b).name or f'body{b}')}" for b in range(model.nbody)]


def moving_bodies(model: mujoco.MjModel) -> list[int]:
    """Bodies with a pose of their own: not welded to the world, or moved as mocap bodies."""
    return [b for b in range(1, model.nbody) if model.body_weldid[b] != 0 or model.body_mocapid[b] >= 0]


def log_geometry(rr: Any, rec: Any, sim: Simulation) -> None:
    """Every visible geom, once (static), under its body's entity; static bodies' poses too."""
    model, data = sim.model, sim.data
    paths = body_paths(model)
    moving = set(moving_bodies(model))
    shapes: dict[tuple[int, int], list[int]] = {}
    for geom in range(model.ngeom):
        if model.geom_group[geom] > VISIBLE_GROUPS or _colour(model, geom)[3] == 0:
            continue
        shapes.setdefault((int(model.geom_bodyid[geom]), int(model.geom_type[geom])), []).append(geom)
    for body in {body for body, _ in shapes} - moving:
        pose = rr.Transform3D(translation=data.xpos[body], quaternion=xyzw(data.xquat[body]))
        rec.log(paths[body], pose, static=True)
    plane_half = float(np.max(np.abs(sim.world.bounds))) + PLANE_MARGIN  # the map, and a little beyond
    for (body, kind), geoms in sorted(shapes.items()):
        for suffix, archetype in _archetypes(rr, model, kind, geoms, plane_half):
            rec.log(f"{paths[body]}/{suffix}", archetype, static=True)


def _colour(model: mujoco.MjModel, geom: int) -> np.ndarray:
    material = model.geom_matid[geom]
    return model.mat_rgba[material] if material >= 0 else model.geom_rgba[geom]


def _archetypes(
    rr: Any, model: mujoco.MjModel, kind: int, geoms: list[int], plane_half: float
) -> list[tuple[str, Any]]:
    """(entity suffix, archetype) for geoms of one type on one body, in the body's frame; an infinite plane is
    drawn ``plane_half`` metres each way."""
    centres = model.geom_pos[geoms]
    quats = xyzw(model.geom_quat[geoms])
    size = model.geom_size[geoms]
    colours = (np.array([_colour(model, g) for g in geoms]) * 255).astype(np.uint8)
    solid = rr.components.FillMode.Solid
    geom_type = mujoco.mjtGeom
    if kind == geom_type.mjGEOM_BOX:
        box = rr.Boxes3D(centers=centres, half_sizes=size, quaternions=quats, colors=colours, fill_mode=solid)
        return [("boxes", box)]
    if kind == geom_type.mjGEOM_PLANE:
        colours[:, :3] = FLOOR_GREY  # a plane's colour is mostly its texture's (a checker), which is not drawn
        half = np.where(size[:, :2] > 0, size[:, :2], plane_half)
        halves = np.column_stack([half, np.full(len(geoms), PLANE_THICKNESS)])
        box = rr.Boxes3D(centers=centres, half_sizes=halves, quaternions=quats, colors=colours, fill_mode=solid)
        return [("planes", box)]
    if kind in (geom_type.mjGEOM_SPHERE, geom_type.mjGEOM_ELLIPSOID):
        halves = size if kind == geom_type.mjGEOM_ELLIPSOID else np.repeat(size[:, :1], 3, axis=1)
        shape = rr.Ellipsoids3D(centers=centres, half_sizes=halves, quaternions=quats, colors=colours, fill_mode=solid)
        return [("ellipsoids", shape)]
    if kind == geom_type.mjGEOM_CAPSULE:
        # Rerun's capsule runs from its origin along +z; MuJoCo's is centred: start half its length back
        axes = np.array([_rotate(q, [0.0, 0.0, 1.0]) for q in model.geom_quat[geoms]])
        starts = centres - axes * size[:, 1:2]
        capsule = rr.Capsules3D(
            lengths=2 * size[:, 1], radii=size[:, 0], translations=starts, quaternions=quats, colors=colours
        )
        return [("capsules", capsule)]
    if kind == geom_type.mjGEOM_CYLINDER:
        cylinder = rr.Cylinders3D(
            lengths=2 * size[:, 1],
            radii=size[:, 0],
            centers=centres,
            quaternions=quats,
            colors=colours,
            fill_mode=solid,
        )
        return [("cylinders", cylinder)]
    if kind == geom_type.mjGEOM_MESH:
        return [(f"mesh_{g}", _mesh(rr, model, g)) for g in geoms]
    return []  # height fields and SDFs are not drawn


def _rotate(wxyz: np.ndarray, vector: list[float]) -> np.ndarray:
    out = np.zeros(3)
    mujoco.mju_rotVecQuat(out, np.asarray(vector, dtype=float), wxyz)
    return out


def _mesh(rr: Any, model: mujoco.MjModel, geom: int) -> Any:
    mesh = int(model.geom_dataid[geom])
    first, count = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
    face, faces = int(model.mesh_faceadr[mesh]), int(model.mesh_facenum[mesh])
    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, model.geom_quat[geom])
    vertices = model.mesh_vert[first : first + count] @ rotation.reshape(3, 3).T + model.geom_pos[geom]
    colour = (_colour(model, geom) * 255).astype(np.uint8)
    return rr.Mesh3D(
        vertex_positions=vertices, triangle_indices=model.mesh_face[face : face + faces], albedo_factor=colour
    )


class BodyPoses:
    """The moving bodies' poses: sampled into a buffer, sent to the recording as columns by ``flush()``."""

    def __init__(self, sim: Simulation) -> None:
        self.sim = sim
        self.bodies = np.array(moving_bodies(sim.model), dtype=int)
        paths = body_paths(sim.model)
        self.paths = [paths[b] for b in self.bodies]
        self.times: list[float] = []
        self.positions: list[np.ndarray] = []
        self.rotations: list[np.ndarray] = []

    def sample(self) -> None:
        data = self.sim.data
        self.times.append(self.sim.time)
        self.positions.append(data.xpos[self.bodies])  # fancy indexing copies
        self.rotations.append(data.xquat[self.bodies])

    def flush(self, rr: Any, rec: Any, timeline: str) -> None:
        if not self.times:
            return
        times = rr.TimeColumn(timeline, duration=np.array(self.times))
        positions = np.stack(self.positions).astype(np.float32)  # (samples, bodies, 3)
        rotations = xyzw(np.stack(self.rotations))
        for index, path in enumerate(self.paths):
            columns = rr.Transform3D.columns(translation=positions[:, index], quaternion=rotations[:, index])
            rec.send_columns(path, indexes=[times], columns=columns)
        self.times, self.positions, self.rotations = [], [], []
