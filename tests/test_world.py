"""The apartment: what later issues rely on is there and behaves."""

import math

import mujoco
import numpy as np
import pytest

from bt_humanoid.sim.ground_truth import GroundTruth
from bt_humanoid.sim.simulation import Simulation


@pytest.fixture(scope="module")
def sim():
    return Simulation.load("apartment", "wheeled_humanoid")


def test_world_declares_places_surfaces_objects_and_a_person(sim):
    world = sim.world
    assert {"kitchen", "living_room"} <= set(world.places)
    assert {"table", "counter", "shelf"} <= set(world.surfaces)
    assert len(world.obstacles) >= 3
    assert "me" in world.people["person"].aliases
    required = {"red cube", "blue cube", "water bottle", "coffee mug", "yellow ball"}
    assert required <= set(world.objects)
    assert len({o.kind for o in world.objects.values()}) >= 3
    assert len({o.colour for o in world.objects.values()}) >= 3
    for name in [*world.obstacles, *(p.body for p in world.people.values()), *(o.body for o in world.objects.values())]:
        sim.model.body(name)
    for surface in world.surfaces.values():
        sim.model.geom(surface.geom)


def test_straight_line_from_start_to_table_is_blocked(sim):
    x0, y0, _ = sim.world.robot_start
    x1, y1, _ = sim.world.places["table"].pose
    start = np.array([x0, y0, 0.3])
    direction = np.array([x1 - x0, y1 - y0, 0.0])
    length = float(np.linalg.norm(direction))
    geom = np.zeros(1, dtype=np.int32)
    robot_root = sim.model.body("base").id
    # exclude the robot's own geoms by starting the ray outside its footprint
    start = start + direction / length * 0.35
    distance = mujoco.mj_ray(sim.model, sim.data, start, direction / length, None, 1, -1, geom)
    assert 0 < distance < length - 0.35
    hit_body = sim.model.geom_bodyid[geom[0]]
    assert sim.model.body(hit_body).name in sim.world.obstacles
    assert hit_body != robot_root


@pytest.mark.sim
def test_objects_rest_where_declared(sim):
    sim.reset()
    truth = GroundTruth(sim)
    before = {name: truth.object_position(name) for name in sim.world.objects}
    sim.step(500)  # one second
    for name, position in before.items():
        assert np.linalg.norm(truth.object_position(name) - position) < 0.005, name
    assert truth.rests_on("red cube", "table")
    assert truth.rests_on("coffee mug", "counter")
    assert truth.rests_on("yellow ball", "shelf")
    assert truth.upright("water bottle") and truth.upright("coffee mug")


def test_grasp_friendly_contact_settings(sim):
    option = sim.model.opt
    assert option.cone == mujoco.mjtCone.mjCONE_ELLIPTIC
    assert option.impratio >= 5 and option.noslip_iterations >= 5
    pad = sim.model.geom("r_pad_a")
    # the pads' own friction wins (priority); 0.8, a finger pad's on glass (docs/dependencies.md)
    assert sim.model.geom_priority[pad.id] >= 1 and sim.model.geom_friction[pad.id][0] == pytest.approx(0.8)


def test_robot_starts_at_the_start_pose(sim):
    sim.reset()
    x, y, yaw = GroundTruth(sim).robot_pose()
    sx, sy, syaw = sim.world.robot_start
    assert (x, y) == pytest.approx((sx, sy)) and yaw == pytest.approx(math.radians(syaw))


@pytest.mark.sim
def test_a_thing_knocked_to_the_floor_is_on_the_floor_and_one_on_the_table_is_not(sim):
    sim.reset()
    truth = GroundTruth(sim)
    sim.step(100)
    assert not truth.on_floor("red cube")
    cube = sim.model.body(sim.object_bodies["red cube"]).id
    joint = sim.model.body_jntadr[cube]
    address = sim.model.jnt_qposadr[joint]
    sim.data.qpos[address : address + 3] = [3.0, -1.2, 0.2]  # beside the table, just above the floor: it falls
    sim.step(500)
    assert truth.on_floor("red cube")
    assert truth.object_position("red cube")[2] < 0.1
