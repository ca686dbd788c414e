"""bt-validate: every kind of bad input gets one line naming file:line and what would be valid, exit 2."""

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from bt_humanoid.cli import validate_main
from bt_humanoid.errors import UserError


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(text).lstrip())
    return path


def validate(capsys, *files: Path) -> tuple[int, str]:
    code = validate_main([str(f) for f in files])
    captured = capsys.readouterr()
    return code, captured.err.strip()


def test_yaml_syntax_error(tmp_path, capsys):
    path = write(
        tmp_path,
        "m.yaml",
        """
        mission: broken
        tree:
          sequence:
            - wait: {seconds: 1
            - say: {text: hi}
        """,
    )
    code, err = validate(capsys, path)
    assert code == 2
    assert "m.yaml:5" in err or "m.yaml:4" in err
    assert "YAML syntax error" in err


def test_unknown_skill_suggests_the_closest(tmp_path, capsys):
    path = write(
        tmp_path,
        "m.yaml",
        """
        mission: typo
        tree:
          sequence:
            - wait: {seconds: 1}
            - move_bse: {x: 1, y: 0}
        """,
    )
    code, err = validate(capsys, path)
    assert code == 2
    assert "m.yaml:5" in err
    assert "unknown skill or node kind 'move_bse'" in err
    assert "did you mean 'move_base'" in err


def test_wrong_parameter_type(tmp_path, capsys):
    path = write(
        tmp_path,
        "m.yaml",
        """
        mission: types
        tree:
          sequence:
            - wait: {seconds: soon}
        """,
    )
    code, err = validate(capsys, path)
    assert code == 2
    assert "m.yaml:4" in err and "seconds" in err and "'soon'" in err


def test_missing_required_parameter(tmp_path, capsys):
    path = write(
        tmp_path,
        "m.yaml",
        """
        mission: missing
        tree:
          sequence:
            - say: {}
        """,
    )
    code, err = validate(capsys, path)
    assert code == 2
    assert "m.yaml:4" in err and "missing required parameter 'text'" in err


def test_unknown_parameter_is_named(tmp_path, capsys):
    path = write(
        tmp_path,
        "m.yaml",
        """
        mission: extra
        tree:
          wait:
            seconds: 1
            minutes: 2
        """,
    )
    code, err = validate(capsys, path)
    assert code == 2
    assert "m.yaml:5" in err and "unknown parameter 'minutes'" in err


def test_missing_subtree_file(tmp_path, capsys):
    path = write(
        tmp_path,
        "m.yaml",
        """
        mission: subtree
        tree:
          sequence:
            - subtree: {file: nowhere/pick.yaml}
        """,
    )
    code, err = validate(capsys, path)
    assert code == 2
    assert "m.yaml:4" in err and "subtree file not found" in err and "pick.yaml" in err


def test_a_mission_file_calls_subtree_files_of_its_own_and_a_plan_may_not(tmp_path):
    from bt_humanoid.mission.loader import MissionLoader

    mission = write(tmp_path, "m.yaml", "mission: mine\ntree: {subtree: {file: ../wave.yaml, args: {times: 1}}}\n")
    wave = (Path(__file__).parent.parent / "behaviors" / "wave.yaml").read_text()
    (tmp_path.parent / "wave.yaml").write_text(wave)  # the person's own behaviour, beside their folder
    assert MissionLoader().load_file(mission).tree.children[0].kind == "sequence"
    with pytest.raises(UserError) as refused:
        MissionLoader.for_plans().load_file(mission)
    assert "m.yaml:2: subtree file '../wave.yaml' is outside" in str(refused.value)


@pytest.mark.parametrize(
    ("node", "problem"),
    [
        ("navigate_to: {pose: [40, 3, 0]}", "navigate_to: (40.0, 3.0) is outside the map"),
        ("navigate: {pose: [40, 3, 0]}", "(40.0, 3.0) is outside the map"),
        ("find: {object: golden key}", "find: unknown object 'golden key'"),
    ],
)
def test_a_goal_off_the_map_or_an_object_nobody_could_ground_is_refused_in_a_file(tmp_path, capsys, node, problem):
    # Before, only a planner's missions were checked for these (commanding._world_problems); a file ran them
    path = write(tmp_path, "m.yaml", f"mission: far away\ntree:\n  {node}\n")
    code, err = validate(capsys, path)
    assert code == 2 and "m.yaml:3" in err and problem in err, err


def test_recursive_subtree(tmp_path, capsys):
    write(
        tmp_path,
        "a.yaml",
        """
        behavior: a
        tree:
          sequence:
            - wait: {seconds: 1}
            - subtree: {file: b.yaml}
        """,
    )
    write(
        tmp_path,
        "b.yaml",
        """
        behavior: b
        tree:
          subtree: {file: a.yaml}
        """,
    )
    path = write(
        tmp_path,
        "m.yaml",
        """
        mission: loops
        tree:
          subtree: {file: a.yaml}
        """,
    )
    code, err = validate(capsys, path)
    assert code == 2
    assert "recursive subtree: a → b → a" in err
    assert "b.yaml:3" in err  # where b calls a again


@pytest.mark.parametrize(
    ("field", "value", "valid"),
    [("world", "flat", "apartment"), ("robot", "wheeled_humanoidd", "did you mean 'wheeled_humanoid'")],
)
def test_unknown_world_or_robot(tmp_path, capsys, field, value, valid):
    path = write(
        tmp_path,
        "m.yaml",
        f"""
        mission: where
        {field}: {value}
        tree:
          wait: {{seconds: 1}}
        """,
    )
    code, err = validate(capsys, path)
    assert code == 2
    assert "m.yaml:2" in err and f"unknown {field} '{value}'" in err and valid in err


def test_unknown_place_in_a_skill_and_in_success(tmp_path, capsys):
    path = write(
        tmp_path,
        "m.yaml",
        """
        mission: places
        tree:
          move_base: {place: kitchn}
        """,
    )
    code, err = validate(capsys, path)
    assert code == 2 and "m.yaml:3" in err and "did you mean 'kitchen'" in err
    path = write(
        tmp_path,
        "n.yaml",
        """
        mission: success names
        tree:
          wait: {seconds: 1}
        success:
          - on: [red cube, tabel]
        """,
    )
    code, err = validate(capsys, path)
    assert code == 2 and "n.yaml:5" in err and "did you mean 'table'" in err


def test_unknown_behaviour_parameter_in_a_call(tmp_path, capsys):
    path = write(
        tmp_path,
        "m.yaml",
        """
        mission: args
        tree:
          approach: {place: table, sped: 0.2}
        """,
    )
    code, err = validate(capsys, path)
    assert code == 2 and "m.yaml:3" in err and "unknown parameter 'sped'" in err


def test_unknown_success_condition(tmp_path, capsys):
    path = write(
        tmp_path,
        "m.yaml",
        """
        mission: conditions
        tree:
          wait: {seconds: 1}
        success:
          - at: table
          - under: [red cube, table]
        """,
    )
    code, err = validate(capsys, path)
    assert code == 2 and "m.yaml:6" in err and "unknown condition 'under'" in err and "valid: on, inside, at" in err


def test_missing_file(tmp_path, capsys):
    code, err = validate(capsys, tmp_path / "absent.yaml")
    assert code == 2 and "absent.yaml" in err and "file not found" in err


def test_no_traceback_from_the_command_line(tmp_path):
    path = write(tmp_path, "m.yaml", "mission: x\ntree:\n  sequence:\n    - jump: {}\n")
    for command in ("bt_humanoid.cli:validate_main", "bt_humanoid.cli:run_main"):
        module, function = command.split(":")
        code = f"import sys, {module} as m; sys.exit(m.{function}([{str(path)!r}]))"
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
        assert done.returncode == 2
        assert "Traceback" not in done.stderr
        assert len(done.stderr.strip().splitlines()) == 1
        assert "m.yaml:4" in done.stderr and "jump" in done.stderr


def test_valid_files_pass(capsys, project_root):
    files = sorted((project_root / "missions").glob("*.yaml")) + sorted((project_root / "behaviors").glob("*.yaml"))
    code = validate_main([str(f) for f in files])
    assert code == 0, capsys.readouterr().err


def test_malformed_world_file_is_reported_at_its_line(tmp_path):
    from bt_humanoid.errors import UserError
    from bt_humanoid.sim.world_config import WorldConfig
    from bt_humanoid.yaml_source import read_config

    folder = tmp_path / "worlds" / "flat"
    folder.mkdir(parents=True)
    (folder / "world.yaml").write_text(
        "name: flat\nmodel: world.xml\nbounds: [[0, 0], [1, 1]]\nplaces: {a: {pose: [0, 0]}}\n"
    )
    with pytest.raises(UserError) as raised:
        read_config("world", tmp_path / "worlds", "flat", "world.yaml", WorldConfig)
    assert "world.yaml:4" in str(raised.value) and "places.a.pose" in str(raised.value)


def test_a_move_to_a_spot_off_the_map_is_refused(tmp_path, capsys):
    path = write(
        tmp_path,
        "far.yaml",
        """
        mission: far away
        tree:
          move_base: {x: 50, y: 0}
        """,
    )
    code, err = validate(capsys, path)
    assert code == 2 and "far.yaml:3" in err and "(50.0, 0.0) is outside the map: x -2 to 9" in err


def test_an_unknown_parameter_is_refused_even_when_its_value_is_a_reference(tmp_path, capsys):
    # found by the fuzzer: "$cube" is checked when the leaf starts, but only for a parameter the skill has
    path = write(tmp_path, "m.yaml", "mission: x\ntree:\n  stand_near: {objekt: $cube}\n")
    code, err = validate(capsys, path)
    assert code == 2 and err.startswith("error: ") and err.endswith("m.yaml:3: stand_near: unknown parameter 'objekt'")


def test_a_manipulation_mission_for_the_walking_robot_validates(tmp_path, capsys):
    path = write(
        tmp_path,
        "m.yaml",
        """
        mission: fetch on legs
        world: apartment
        robot: biped_humanoid
        tree:
          sequence:
            - navigate: {place: table}
            - pick: {object: red cube}
        """,
    )
    code, err = validate(capsys, path)
    assert code == 0, err


def test_robot_option_runs_a_mission_file_on_another_robot(tmp_path):
    from bt_humanoid.mission.loader import MissionLoader

    path = write(
        tmp_path,
        "m.yaml",
        """
        mission: walk
        world: apartment
        robot: wheeled_humanoid
        tree:
          move_base: {x: 0.5, y: 0.0, yaw: 0}
        """,
    )
    spec = MissionLoader(robot="biped_humanoid").load_file(path)
    assert spec.header.robot == "biped_humanoid" and spec.known.robot_config.base.floating
    with pytest.raises(UserError, match=r"unknown robot|no robot|not a robot"):
        MissionLoader(robot="tripod").load_file(path)
