"""Tell the robot where objects are, for tests and benchmarks of control alone.

A mission's robot finds objects with its camera. To measure a controller
without perception in the loop, a benchmark may instead tell the WorldModel
where the world file (or a test's set-up) put each object. This reads the
compiled model's declared body poses and geom sizes, never the live state,
so an object moved during a run is not followed.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from bt_humanoid.language.plan import PlanningContext
from bt_humanoid.perception.world_model import TrackedObject, WorldModel
from bt_humanoid.sim.geometry import object_extents, rotation_of
from bt_humanoid.sim.robot_config import RobotConfig
from bt_humanoid.sim.scene_config import SceneConfig
from bt_humanoid.sim.simulation import Simulation
from bt_humanoid.sim.world_config import WorldConfig

if TYPE_CHECKING:
    from bt_humanoid.engine.stack import RobotStack


def told_objects(sim: Simulation) -> list[TrackedObject]:
    """Every object of the run (the world's and its scene's) where the model puts it."""
    told = []
    model = sim.model
    for name, body_name in sim.object_bodies.items():
        declared = sim.world.objects[sim.object_kinds[name]]
        body = model.body(body_name)
        w, _, _, z = body.quat
        low, high = object_extents(model, body.id)
        told.append(
            TrackedObject(
                id=body_name,
                name=name,
                kind=declared.kind,
                colour=declared.colour,
                position=body.pos + rotation_of(body.quat) @ ((low + high) / 2),
                yaw=2.0 * math.atan2(z, w),
                size=high - low,
                keep_upright=declared.upright,
                identity=sim.object_kinds[name],
            )
        )
    return told


def tell_object_poses(belief: WorldModel, sim: Simulation) -> None:
    """Put every object of the run into ``belief`` where the model puts it."""
    for tracked in told_objects(sim):
        belief.update(tracked)


def told_planning_context(world: str = "apartment", scene: SceneConfig | None = None) -> PlanningContext:
    """A planner's view of ``world`` (and ``scene``: its objects, start and what is in hand) with every object
    told, from where the robot starts: language, not sight. What the robot holds it knows as it would."""
    from bt_humanoid.engine.stack import RobotStack

    stack = RobotStack.load(world, "wheeled_humanoid", scene=scene)
    stack.close()  # no looking: told, not seen
    held = stack.sim.held
    belief = stack.context.world_model
    for tracked in told_objects(stack.sim):
        in_hand = held is not None and tracked.name == held.name
        if not in_hand:  # the one in hand the robot already believes, where its hand holds it
            belief.update(tracked)
    return PlanningContext(stack.world, belief, np.asarray(stack.robot.base.pose(), dtype=float))


def told_stack(world: WorldConfig, robot: RobotConfig, seed: int = 0, scene: SceneConfig | None = None) -> RobotStack:
    """A stack whose robot is told where every object is, its head camera off: control alone.

    Nothing a detector sees or misses moves the told objects, skills that look first (find, grasp) recall
    instead, and the navigator plans on the map's furniture alone: for scenes with nothing else on the floor.
    ``scene``: the objects and start the run has (none: the world's own scene).
    """
    from bt_humanoid.engine.stack import RobotStack

    stack = RobotStack(world, robot.model_copy(update={"cameras": {}}), seed, scene=scene)
    tell_object_poses(stack.context.world_model, stack.sim)
    return stack
