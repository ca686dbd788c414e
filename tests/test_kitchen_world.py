"""The kitchen world: it loads, its labels are what the script draws, and its default scene stands still."""

from __future__ import annotations

import subprocess
import sys

import pytest

from bt_humanoid.sim.ground_truth import GroundTruth
from bt_humanoid.sim.scene_config import load_scene
from bt_humanoid.sim.simulation import Simulation
from bt_humanoid.sim.world_config import load_world_config


def test_the_kitchen_loads_with_its_objects_as_models():
    world = load_world_config("kitchen")
    assert len(world.objects) == 16 and world.placeable == list(world.objects)  # every object is a model
    assert all(o.categories for o in world.objects.values())
    assert {"table", "close_counter", "far_counter"} == set(world.surfaces)
    assert {"trash_can", "recycling_bin", "compost_bin"} == set(world.containers)
    assert world.scene == "default"
    sim = Simulation.load("kitchen", "wheeled_humanoid")
    assert sim.scene is not None and sim.scene.name == "default"
    assert set(sim.object_bodies) == set(world.objects)  # the default scene: one of each
    for surface in world.surfaces.values():
        sim.model.geom(surface.geom)  # a geom of the model
    for container in world.containers.values():
        sim.model.body(container.body)


def test_the_committed_textures_are_what_the_script_draws(project_root):
    done = subprocess.run(
        [sys.executable, str(project_root / "scripts" / "kitchen_textures.py"), "--check"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stdout + done.stderr


@pytest.mark.sim
def test_the_default_scene_settles_upright_on_its_surfaces():
    world = load_world_config("kitchen")
    scene = load_scene(world, "default")
    sim = Simulation.load("kitchen", "wheeled_humanoid")
    truth = GroundTruth(sim)
    sim.step(round(1.0 / sim.timestep))
    for (name, _), placement in zip(scene.instances(), scene.objects, strict=True):
        assert truth.upright(name), name
        assert truth.rests_on(name, placement.on), f"{name} is not at rest on the {placement.on}"
        assert truth.object_speed(name) < 0.01, name
