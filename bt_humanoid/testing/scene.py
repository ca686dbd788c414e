"""Scene set-up for tests and benchmarks: put an object somewhere before a run starts.

Set-up is the one place where positions are written: the object's declared
pose and its simulated pose change together, before the first step, so a
benchmark that tells the robot where things are (``told.py``) tells it the
new pose. Never call this during a run.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from bt_humanoid.engine.stack import RobotStack
from bt_humanoid.perception.map_knowledge import map_world_model
from bt_humanoid.testing.told import told_objects

DROP = 0.001  # m above the surface the object starts, so it settles without a jolt


def place_object(run: RobotStack, name: str, x: float, y: float, yaw: float) -> None:
    """Stand object ``name`` upright at (x, y) on the surface there, turned ``yaw`` rad (a stack, or a MissionRun)."""
    if run.sim.time > 0.0:
        raise RuntimeError("place_object is set-up: call it before the run starts")
    surface = map_world_model(run.context.world, run.sim.model).surface_under(np.array([x, y, 10.0]))
    if surface is None:
        raise ValueError(f"({x:.2f}, {y:.2f}) is on no known surface")
    model, data = run.sim.model, run.sim.data
    body = model.body(run.sim.object_bodies[name])
    obj = next(o for o in told_objects(run.sim) if o.name == name)
    bottom_in_body = obj.position[2] - obj.size[2] / 2 - body.pos[2]  # for an upright body
    position = np.array([x, y, surface.height - bottom_in_body + DROP])
    quat = np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])
    model.body_pos[body.id] = position
    model.body_quat[body.id] = quat
    address = model.jnt_qposadr[model.body_jntadr[body.id]]
    for qpos in (data.qpos, model.qpos0):
        qpos[address : address + 7] = np.concatenate([position, quat])
    mujoco.mj_forward(model, data)
