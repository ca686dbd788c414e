"""Each robot folder is something a MuJoCo user can open: a scene.xml that loads as it is, and a README."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from bt_humanoid.sim.robot_config import load_robot_config
from bt_humanoid.sim.robot_scene import SCENE_FILE, scene_xml

ROBOTS = Path(__file__).resolve().parents[1] / "robots"
FOLDERS = sorted(p for p in ROBOTS.iterdir() if p.is_dir())


def test_there_are_robots():
    assert FOLDERS


@pytest.mark.parametrize("folder", FOLDERS, ids=lambda p: p.name)
def test_each_robot_folder_has_a_scene_and_a_readme(folder):
    assert (folder / SCENE_FILE).is_file(), f"regenerate with: python -m bt_humanoid.sim.robot_scene {folder.name}"
    assert (folder / "README.md").is_file()


@pytest.mark.sim
@pytest.mark.parametrize("scene", sorted(ROBOTS.glob(f"*/{SCENE_FILE}")), ids=lambda p: p.parent.name)
def test_scene_loads_as_it_is_with_the_robot_on_a_floor(scene):
    model = mujoco.MjModel.from_xml_path(str(scene))  # what python -m mujoco.viewer --mjcf does
    floors = [
        i for i in range(model.ngeom) if model.geom_bodyid[i] == 0 and model.geom_type[i] == mujoco.mjtGeom.mjGEOM_PLANE
    ]
    assert floors, "no floor: a plane in the worldbody"
    assert model.nlight + int(model.vis.headlight.active) > 0
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    if load_robot_config(scene.parent.name).legs is not None:
        # torque-controlled legs hold nothing without a controller (tests/test_biped_model.py drops the robot):
        # the keyframe stands it on the floor, the soles on it and everything else above it
        mujoco.mj_forward(model, data)
        fromto = np.zeros(6)
        floor = floors[0]
        gaps = {
            model.geom(g).name: mujoco.mj_geomDistance(model, data, floor, g, 0.1, fromto)
            for g in range(model.ngeom)
            if g != floor and model.geom_contype[g] | model.geom_conaffinity[g]
        }
        assert all(abs(gap) < 1e-6 if "_sole_" in name else gap > 1e-3 for name, gap in gaps.items()), gaps
        return
    home = data.qpos.copy()
    mujoco.mj_step(model, data, 500)  # one second: the actuators hold the posture, nothing falls or drifts
    assert abs(data.qpos - home).max() < 1e-3


@pytest.mark.parametrize("folder", FOLDERS, ids=lambda p: p.name)
def test_scene_is_the_robot_as_the_project_composes_it(folder):
    config = load_robot_config(folder.name)
    written = (folder / SCENE_FILE).read_text()
    assert written == scene_xml(config), f"regenerate with: python -m bt_humanoid.sim.robot_scene {folder.name}"
