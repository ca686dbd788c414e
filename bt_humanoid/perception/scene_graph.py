"""Relations between what the robot believes is there: on, in (a room), near, left of, right of.

A scene graph is a list of (subject, relation, object) facts computed from
the WorldModel on demand. "Left" and "right" are as seen from a viewer (the
robot, by default): people say "the cup left of the bottle" meaning as they
look at them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bt_humanoid.perception.world_model import TrackedObject, WorldModel

NEAR = 0.3  # m between centres for "near" / "next to"
SIDE = 0.02  # m sideways (across the line of sight) before one thing is left or right of another


@dataclass(frozen=True)
class Relation:
    subject: str  # object id
    relation: str  # on, in, near, left_of, right_of
    object: str  # object id, surface name or room name


def scene_graph(belief: WorldModel, viewer: np.ndarray | None = None) -> list[Relation]:
    """Every relation that holds now between the believed objects (and the surfaces they stand on)."""
    present = [o for o in belief.present() if o.held_by is None]
    facts = []
    for a in present:
        surface = belief.surface_under(a.position)
        if surface is not None:
            facts.append(Relation(a.id, "on", surface.name))
        room = belief.room_of(a.position)
        if room is not None:
            facts.append(Relation(a.id, "in", room))
        for b in present:
            if a is not b:
                facts += [Relation(a.id, r, b.id) for r in pairwise(a, b, viewer)]
    return facts


def pairwise(a: TrackedObject, b: TrackedObject, viewer: np.ndarray | None) -> list[str]:
    """The relations that hold from ``a`` to ``b``."""
    relations = []
    offset = a.position[:2] - b.position[:2]
    if float(np.hypot(*offset)) < NEAR:
        relations.append("near")
    if viewer is not None:
        sight = b.position[:2] - np.asarray(viewer[:2], dtype=float)
        sight /= max(float(np.hypot(*sight)), 1e-9)
        left = np.array([-sight[1], sight[0]])  # the viewer's left, looking at b
        across = float(offset @ left)
        if across > SIDE:
            relations.append("left_of")
        elif across < -SIDE:
            relations.append("right_of")
    return relations
