"""Tell the robot where objects are, for tests and benchmarks of control alone.

A mission's robot finds objects with its camera. To measure a controller
without perception in the loop, a benchmark may instead tell the WorldModel
where the world file (or a test's set-up) put each object. This reads the
compiled model's declared body poses and geom sizes, never the live state,
so an object moved during a run is not followed.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from bt_humanoid.language.plan import PlanningContext
from bt_humanoid.perception.world_model import TrackedObject, WorldModel
from bt_humanoid.sim.geometry import object_extents, rotation_of
from bt_humanoid.sim.world_config import WorldConfig


def told_objects(world: WorldConfig, model: mujoco.MjModel) -> list[TrackedObject]:
    """Every declared object where the model puts it."""
    told = []
    for name, declared in world.objects.items():
        body = model.body(declared.body)
        w, _, _, z = body.quat
        low, high = object_extents(model, body.id)
        told.append(
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
    return told


def tell_object_poses(belief: WorldModel, world: WorldConfig, model: mujoco.MjModel) -> None:
    """Put every declared object into ``belief`` where the model puts it."""
    for tracked in told_objects(world, model):
        belief.update(tracked)


def told_planning_context(world: str = "apartment") -> PlanningContext:
    """A planner's view of ``world`` with every declared object told, from its start pose: language, not sight."""
    from bt_humanoid.engine.stack import RobotStack

    stack = RobotStack.load(world, "wheeled_humanoid")
    stack.close()  # no looking: told, not seen
    tell_object_poses(stack.context.world_model, stack.world, stack.sim.model)
    return PlanningContext(stack.world, stack.context.world_model, np.zeros(3))
