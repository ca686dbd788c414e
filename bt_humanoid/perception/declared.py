"""Seed the WorldModel from what the world declares: objects where the world file puts them.

This is the robot being told where things are at the start, the stand-in for
perception until the RGB-D pipeline fills the WorldModel. It reads the
compiled model's declared body poses and geom sizes (never the live
simulation state), so moving an object during a run does not update it.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from bt_humanoid.perception.world_model import SupportSurface, TrackedObject, WorldModel
from bt_humanoid.sim.world_config import WorldConfig


def declared_world_model(world: WorldConfig, model: mujoco.MjModel) -> WorldModel:
    belief = WorldModel()
    for name, surface in world.surfaces.items():
        geom = model.geom(surface.geom)
        body = model.body(int(geom.bodyid[0]))
        centre = body.pos + geom.pos  # static furniture bodies are not rotated
        half = geom.size
        belief.surfaces[name] = SupportSurface(
            name, np.array([centre[:2] - half[:2], centre[:2] + half[:2]]), float(centre[2] + half[2])
        )
    for name, person in world.people.items():
        for alias in (name, *person.aliases):
            belief.people[alias] = model.body(person.body).pos.copy()
    for name, declared in world.objects.items():
        body = model.body(declared.body)
        w, _, _, z = body.quat
        low, high = _extents(model, body.id)
        belief.update(
            TrackedObject(
                id=declared.body,
                name=name,
                kind=declared.kind,
                colour=declared.colour,
                position=body.pos + _rotation(body.quat) @ ((low + high) / 2),
                yaw=2.0 * math.atan2(z, w),
                size=high - low,
                keep_upright=declared.upright,
            )
        )
    return belief


def _rotation(quat: np.ndarray) -> np.ndarray:
    matrix = np.zeros(9)
    mujoco.mju_quat2Mat(matrix, quat)
    return matrix.reshape(3, 3)


def _extents(model: mujoco.MjModel, body: int) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned extents of an object body in its frame: across, its main geom (the first one); up, all geoms.

    Handles and caps do not widen the object (grasps close on its body), but a
    cap does make it taller, and the palm must stay above it.
    """
    geom = int(model.body_geomadr[body])
    low, high = _geom_extents(model, geom)
    for other in range(geom + 1, geom + int(model.body_geomnum[body])):
        other_low, other_high = _geom_extents(model, other)
        low[2], high[2] = min(low[2], other_low[2]), max(high[2], other_high[2])
    return low, high


def _geom_extents(model: mujoco.MjModel, geom: int) -> tuple[np.ndarray, np.ndarray]:
    kind, size, pos = model.geom_type[geom], model.geom_size[geom], model.geom_pos[geom]
    if kind == mujoco.mjtGeom.mjGEOM_BOX:
        half = size.copy()
    elif kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
        half = np.array([size[0], size[0], size[1]])
    elif kind == mujoco.mjtGeom.mjGEOM_SPHERE:
        half = np.full(3, size[0])
    else:
        body = model.body(int(model.geom_bodyid[geom])).name
        raise ValueError(f"object body {body!r}: unsupported geom type {kind}")
    return pos - half, pos + half
