"""Scenes through the command line: every mistake in choosing or writing one is one line naming the place, exit 2.

bt-run (a mission's scene:, --scene), bt-plan and bt-eval (--scene, a suite's scene: and random scenes), and
bt-validate on kitchen missions (a mission names the world's objects, "coke", or a scene's, "coke 2").
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from bt_humanoid.cli import EXIT_INVALID, EXIT_OK, plan_main, run_main, validate_main
from bt_humanoid.evaluation.command import eval_main
from bt_humanoid.evaluation.suite import load_suite
from bt_humanoid.sim.scene_config import scene_names
from bt_humanoid.sim.world_config import load_world_config

SCENES = ", ".join(scene_names(load_world_config("kitchen")))  # every scene of the kitchen's scenes/ folder


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(textwrap.dedent(text).lstrip())
    return path


def one_error(capsys) -> str:
    """The one line a user error prints (and nothing like a traceback)."""
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("error:") and "Traceback" not in err, err
    return err


def kitchen_mission(folder: Path, scene: str | None = None, success: str = "") -> Path:
    line = f"scene: {scene}\n" if scene else ""
    text = f"mission: look\nworld: kitchen\n{line}tree:\n  wait: {{seconds: 1}}\n{success}"
    return write(folder, "m.yaml", text)


def test_a_mission_naming_an_unknown_scene_is_refused_at_its_line(tmp_path, capsys):
    assert run_main([str(kitchen_mission(tmp_path, "breakfast")), "--no-live"]) == EXIT_INVALID
    err = one_error(capsys)
    assert "m.yaml:3" in err and "unknown scene 'breakfast' of world 'kitchen'" in err and f"valid: {SCENES}" in err
    assert {"default", "holding_coke", "three_cokes"} <= set(SCENES.split(", "))


def test_an_unknown_scene_on_the_command_line_is_named_as_the_option(tmp_path, capsys):
    assert run_main([str(kitchen_mission(tmp_path)), "--no-live", "--scene", "tree_cokes"]) == EXIT_INVALID
    err = one_error(capsys)
    assert "--scene: unknown scene 'tree_cokes'" in err and "did you mean 'three_cokes'?" in err
    assert plan_main(["bring me a coke", "--world", "kitchen", "--scene", "lunch"]) == EXIT_INVALID
    assert "--scene: unknown scene 'lunch' of world 'kitchen'" in one_error(capsys)
    assert run_main([str(kitchen_mission(tmp_path)), "--scene", str(tmp_path / "absent.yaml")]) == EXIT_INVALID
    assert "scene file not found" in one_error(capsys)


def test_a_scene_for_a_world_without_models_says_so(tmp_path, capsys):
    mission = write(tmp_path, "a.yaml", "mission: look\ntree:\n  wait: {seconds: 1}\n")  # the apartment
    assert run_main([str(mission), "--scene", "default"]) == EXIT_INVALID
    err = one_error(capsys)
    assert "unknown scene 'default' of world 'apartment'" in err and "its objects are fixed bodies" in err
    scene = write(tmp_path, "s.yaml", "robot_start: start\nobjects:\n  - {object: coke, on: table}\n")
    assert run_main([str(mission), "--scene", str(scene)]) == EXIT_INVALID
    err = one_error(capsys)
    assert "s.yaml:3" in err and "world 'apartment' has no objects a scene can place" in err


@pytest.mark.parametrize(
    ("scene", "line", "message"),
    [
        ("objects:\n  - {object: coke, on: table}\n  - {object: cokee, on: table}\n", 3, "did you mean 'coke'?"),
        ("objects:\n  - {object: coke, on: tabel}\n", 2, "unknown surface 'tabel' (did you mean 'table'?"),
        ("robot_start: tabel\n", 1, "unknown place 'tabel' (did you mean 'table'?"),
        ("robot_start: [20, 0, 0]\n", 1, "(20.0, 0.0) is outside the map"),
        ("holding: {object: red cube}\n", 1, "'red cube' is not an object scenes can place in world 'kitchen'"),
        ("holding: {object: coke, hand: middle}\n", 1, "hand: Input should be 'left' or 'right'"),
        ("objects:\n  - {object: coke, on: table, at: [0.7, 0]}\n", 2, "is off the table for this object"),
        (
            "objects:\n  - {object: coke, on: table, at: [0, 0]}\n  - {object: pepsi, on: table, at: [0.03, 0]}\n",
            3,
            "overlaps objects[0]",
        ),
        ("objects:\n" + "  - {object: coke, on: table}\n" * 80, None, "no free spot left on the table"),
        ("seed: -1\n", 1, "seed: Input should be greater than or equal to 0"),
    ],
)
def test_mistakes_in_a_scene_file_are_named_at_their_line(tmp_path, capsys, scene, line, message):
    file = write(tmp_path, "scene.yaml", scene)
    assert run_main([str(kitchen_mission(tmp_path)), "--no-live", "--scene", str(file)]) == EXIT_INVALID
    err = one_error(capsys)
    assert message in err
    assert f"scene.yaml:{line}" in err if line is not None else "scene.yaml:" in err


def test_too_many_objects_for_a_surface_name_the_first_that_does_not_fit(tmp_path, capsys):
    file = write(tmp_path, "scene.yaml", "objects:\n" + "  - {object: coke, on: table}\n" * 80)
    assert run_main([str(kitchen_mission(tmp_path)), "--scene", str(file)]) == EXIT_INVALID
    err = one_error(capsys)
    line = int(err.split("scene.yaml:")[1].split(":")[0])
    assert 10 < line <= 81 and f"objects[{line - 2}]: no free spot left on the table for the coke" in err


def test_a_mission_s_scene_file_is_found_beside_it(tmp_path, capsys):
    write(tmp_path, "two.yaml", "objects:\n  - {object: coke, on: table}\n  - {object: coke, on: table}\n")
    mission = kitchen_mission(tmp_path, "two.yaml", success="success:\n  - upright: coke 2\n")
    assert validate_main([str(mission)]) == EXIT_OK
    capsys.readouterr()
    mission = kitchen_mission(tmp_path, "two.yaml", success="success:\n  - upright: coke 3\n")
    assert validate_main([str(mission)]) == EXIT_INVALID
    err = one_error(capsys)
    assert "m.yaml:7" in err and "no 'coke 3' in scene 'two'" in err and "valid: coke, coke 2" in err


def test_success_conditions_name_objects_of_the_command_line_s_scene(tmp_path, capsys):
    mission = kitchen_mission(tmp_path, success="success:\n  - on: [coke 3, table]\n")
    assert run_main([str(mission), "--no-live"]) == EXIT_INVALID  # the default scene has one coke
    err = one_error(capsys)
    assert "m.yaml:6" in err and "no 'coke 3' in scene 'default'" in err


def test_bt_validate_knows_the_kitchen_s_objects(tmp_path, capsys):
    ok = write(
        tmp_path,
        "ok.yaml",
        """
        mission: fetch
        world: kitchen
        tree:
          sequence:
            - find: {object: coke}
            - find: {object: coke 2}
            - grasp: {object: jalapeno chips}
            - find: {object: the red can on the table}
        """,
    )
    assert validate_main([str(ok)]) == EXIT_OK
    capsys.readouterr()
    bad = write(tmp_path, "bad.yaml", "mission: fetch\nworld: kitchen\ntree:\n  find: {object: cokes 2}\n")
    assert validate_main([str(bad)]) == EXIT_INVALID
    err = one_error(capsys)
    assert "bad.yaml:4" in err and "unknown object 'cokes 2'" in err and "coke" in err


SUITE = """
suite: s
world: kitchen
objects: [coke]
tasks:
  - command: bring me the {object}
    expect: [{delivered: '{object}'}]
"""


@pytest.mark.parametrize(
    ("extra", "line", "message"),
    [
        ("scene: brunch\n", 7, "unknown scene 'brunch' of world 'kitchen'"),
        ("scene: three_cokes\nrandomize: {scene: {objects: [3, 2], surfaces: [table]}}\n", 8, "is no range"),
        ("randomize: {scene: {objects: [2, 4], surfaces: [tabel]}}\n", 7, "unknown name 'tabel'"),
        ("randomize: {scene: {objects: [2, 4], surfaces: [table], among: [pepsy]}}\n", 7, "did you mean 'pepsi'?"),
    ],
)
def test_a_suite_s_scene_mistakes_are_named_at_their_line(tmp_path, capsys, extra, line, message):
    suite = write(tmp_path, "suite.yaml", SUITE + extra)
    assert eval_main([str(suite)]) == EXIT_INVALID
    err = one_error(capsys)
    assert f"suite.yaml:{line}" in err and message in err


def test_a_suite_s_object_must_be_in_its_scene(tmp_path, capsys):
    suite = write(tmp_path, "suite.yaml", SUITE.replace("[coke]", "[apple]") + "scene: three_cokes\n")
    assert eval_main([str(suite)]) == EXIT_INVALID
    err = one_error(capsys)
    assert "suite.yaml:3" in err and "no 'apple' in scene 'three_cokes'" in err
    loaded, _ = load_suite(suite, scene="default")  # the command line's scene has one
    assert loaded.scene == "default"


def test_random_scenes_need_a_world_of_models(tmp_path, capsys):
    suite = write(
        tmp_path,
        "suite.yaml",
        SUITE.replace("world: kitchen", "world: apartment").replace("[coke]", "[red cube]")
        + "randomize: {scene: {objects: [2, 4], surfaces: [table]}}\n",
    )
    assert eval_main([str(suite)]) == EXIT_INVALID
    err = one_error(capsys)
    assert "suite.yaml:7" in err and "world 'apartment' has no objects a scene can place" in err
    suite.write_text(SUITE)
    assert eval_main([str(suite), "--scene", "nowhere"]) == EXIT_INVALID
    assert "--scene: unknown scene 'nowhere'" in one_error(capsys)
