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
from bt_humanoid.sim.geometry import object_extents, rotation_of
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
    belief.vocabulary = {name: (declared.kind, declared.colour) for name, declared in world.objects.items()}
    for name, declared in world.objects.items():
        body = model.body(declared.body)
        w, _, _, z = body.quat
        low, high = object_extents(model, body.id)
        belief.update(
            TrackedObject(
                id=declared.body,
                name=name,
                kind=declared.kind,
                colour=declared.colour,
                position=body.pos + rotation_of(body.quat) @ ((low + high) / 2),
                yaw=2.0 * math.atan2(z, w),
                size=high - low,
                keep_upright=declared.upright,
            )
        )
    return belief
