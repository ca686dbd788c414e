"""Shapes of bodies in a compiled model: an object's extents, a quaternion as a rotation matrix."""

from __future__ import annotations

import mujoco
import numpy as np


def rotation_of(quat: np.ndarray) -> np.ndarray:
    matrix = np.zeros(9)
    mujoco.mju_quat2Mat(matrix, quat)
    return matrix.reshape(3, 3)


def object_extents(model: mujoco.MjModel, body: int) -> tuple[np.ndarray, np.ndarray]:
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


RESTING_GAP = 1e-3  # m: a sleeping body's geom this close to another's (or into it) rests on it


def geoms_touching(model: mujoco.MjModel, data: mujoco.MjData, body: int) -> set[int]:
    """The geoms in contact with ``body`` now.

    A body at rest may sleep (the worlds enable MuJoCo's sleeping), and a sleeping body has no contacts in
    ``data.contact``: it touches what its geoms are within ``RESTING_GAP`` of, as when it fell asleep.
    """
    if data.body_awake[body] == mujoco.mjtSleepState.mjS_ASLEEP:
        return _geoms_resting_against(model, data, body)
    geom1, geom2 = data.contact.geom1[: data.ncon], data.contact.geom2[: data.ncon]
    bodies1, bodies2 = model.geom_bodyid[geom1], model.geom_bodyid[geom2]
    return set(geom2[bodies1 == body].tolist()) | set(geom1[bodies2 == body].tolist())


def _geoms_resting_against(model: mujoco.MjModel, data: mujoco.MjData, body: int) -> set[int]:
    """The geoms within ``RESTING_GAP`` of one of ``body``'s that MuJoCo would collide it with (the answer key's
    question, asked rarely: each pair is a distance query)."""
    own = range(int(model.body_geomadr[body]), int(model.body_geomadr[body] + model.body_geomnum[body]))
    touching: set[int] = set()
    for geom in own:
        for other in range(model.ngeom):
            if model.geom_bodyid[other] == body or not _may_collide(model, geom, other):
                continue
            if mujoco.mj_geomDistance(model, data, geom, other, RESTING_GAP, None) < RESTING_GAP:
                touching.add(other)
    return touching


def _may_collide(model: mujoco.MjModel, geom: int, other: int) -> bool:
    """MuJoCo's contype/conaffinity test: one geom's type meets the other's affinity."""
    return bool(
        model.geom_contype[geom] & model.geom_conaffinity[other]
        or model.geom_contype[other] & model.geom_conaffinity[geom]
    )
