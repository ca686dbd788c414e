"""Imports run one way: commanding and the CLI → engine → mission → skills → control, navigation, perception,
language → sim (docs/architecture.md, "Layers"). A module may import its own package and lower layers only."""

import ast
from pathlib import Path

import bt_humanoid

PACKAGE = Path(bt_humanoid.__file__).parent

#: each top-level module or package of bt_humanoid, and its layer: imports go to a lower number only
LAYERS = {
    "errors": 0,
    "paths": 0,
    "strict_model": 0,
    "yaml_source": 1,
    "sim": 2,
    "perception": 3,
    "localisation": 3,
    "control": 4,
    "language": 4,
    "navigation": 5,
    "safety": 5,
    "skills": 6,
    "mission": 7,
    "engine": 8,
    "docs": 8,
    "viz": 9,
    "interop": 9,
    "commanding": 10,
    "testing": 11,
    "training": 11,
    "benchmarks": 12,
    "cli": 12,
    "evaluation": 13,
}


def _imports(file: Path) -> set[str]:
    """The bt_humanoid top-level names a file imports, anywhere in it (late imports inside functions too)."""
    found = set()
    for node in ast.walk(ast.parse(file.read_text())):
        names = []
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module]
        elif isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        found |= {name.split(".")[1] for name in names if name.startswith("bt_humanoid.")}
    return found


def _owner(file: Path) -> str:
    parts = file.relative_to(PACKAGE).parts
    return parts[0] if len(parts) > 1 else file.stem


def test_every_module_has_a_layer():
    owners = {_owner(file) for file in PACKAGE.rglob("*.py")} - {"__init__", "__main__"}
    assert owners <= set(LAYERS), f"give these a layer in this test: {sorted(owners - set(LAYERS))}"


def test_imports_point_down_the_layers_only():
    wrong = []
    for file in sorted(PACKAGE.rglob("*.py")):
        owner = _owner(file)
        if owner not in LAYERS:
            continue
        for target in _imports(file) - {owner}:
            if LAYERS.get(target, -1) >= LAYERS[owner]:
                wrong.append(f"{file.relative_to(PACKAGE.parent)} ({owner}) imports {target}")
    assert not wrong, "imports against the layers:\n" + "\n".join(wrong)


def test_the_mission_language_knows_nothing_of_the_engine():
    mission = PACKAGE / "mission"
    for file in mission.rglob("*.py"):
        assert not _imports(file) & {"engine", "safety", "commanding", "cli"}, file


def test_skills_and_navigation_see_the_base_through_its_motion_interface():
    from bt_humanoid.control.base_driver import BaseDriver
    from bt_humanoid.control.base_motion import BaseMotion

    wanted = [name for name in vars(BaseMotion) if not name.startswith("_")]
    assert {"pose", "move_to", "track", "brake", "capped", "time"} <= set(wanted)
    assert all(hasattr(BaseDriver, name) for name in wanted if name != "speed_cap"), "the wheeled base has them all"
    for package in ("skills", "navigation", "perception", "engine", "language"):
        for file in (PACKAGE / package).rglob("*.py"):
            assert "BaseDriver" not in file.read_text(), f"{file.name} reaches past BaseMotion to the wheeled driver"
