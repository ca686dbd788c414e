"""What the robot knows from its map before it looks: surfaces, rooms, people and the names of things.

Surfaces (table, counter, shelf) are fixed furniture, the map's business;
people are where the world puts them; the vocabulary says what people call
the world's objects ("water bottle" is a blue bottle), so phrases can be
grounded. Where objects are is not map knowledge: the head camera finds them
(``perceiver.py``).
"""

from __future__ import annotations

import mujoco
import numpy as np

from bt_humanoid.perception.world_model import SupportSurface, WorldModel
from bt_humanoid.sim.world_config import WorldConfig


def map_world_model(world: WorldConfig, model: mujoco.MjModel) -> WorldModel:
    """A WorldModel with the map's surfaces, rooms, people and vocabulary, and no objects yet."""
    belief = WorldModel()
    for name, surface in world.surfaces.items():
        geom = model.geom(surface.geom)
        body = model.body(int(geom.bodyid[0]))
        centre = body.pos + geom.pos  # static furniture bodies are not rotated
        half = geom.size
        belief.surfaces[name] = SupportSurface(
            name, np.array([centre[:2] - half[:2], centre[:2] + half[:2]]), float(centre[2] + half[2])
        )
    for name, place in world.places.items():
        if place.kind == "room" and place.region is not None:
            belief.rooms[name] = np.array(place.region, dtype=float)
    for name, person in world.people.items():
        for alias in (name, *person.aliases):
            belief.people[alias] = model.body(person.body).pos.copy()
    belief.vocabulary = {name: (declared.kind, declared.colour) for name, declared in world.objects.items()}
    return belief
