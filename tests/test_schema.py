"""The exported JSON Schema: in sync with the registry and behaviours, and it judges files like the loader."""

import json

import jsonschema
import yaml

from bt_humanoid.cli import SCHEMA_FILE, mission_schema


def test_committed_schema_is_up_to_date(project_root):
    committed = json.loads((project_root / "missions" / SCHEMA_FILE).read_text())
    assert committed == mission_schema(), "regenerate with: bt-validate --schema missions/mission.schema.json"


def test_schema_accepts_every_mission_in_the_repo(project_root):
    schema = mission_schema()
    for path in sorted((project_root / "missions").glob("*.yaml")):
        jsonschema.validate(yaml.safe_load(path.read_text()), schema)


def test_schema_rejects_what_the_loader_rejects():
    schema = mission_schema()
    validator = jsonschema.Draft202012Validator(schema)
    bad = [
        {"mission": "x", "tree": {"move_bse": {"x": 1, "y": 0}}},
        {"mission": "x", "tree": {"wait": {"seconds": "soon"}}},
        {"mission": "x", "tree": {"say": {}}},
        {"mission": "x", "tree": {"sequence": [{"wait": {"seconds": 1}, "say": {"text": "two kinds"}}]}},
        {"mission": "x", "tree": {"retry": {"attempts": 0, "child": {"wait": {"seconds": 1}}}}},
    ]
    for mission in bad:
        assert not validator.is_valid(mission), mission
    good = {"mission": "x", "tree": {"retry": {"attempts": 2, "child": {"approach": {"place": "table"}}}}}
    assert validator.is_valid(good)


def test_readme_reference_matches_the_registry(project_root):
    from bt_humanoid.docs import reference

    assert reference() in (project_root / "README.md").read_text(), "regenerate with: python -m bt_humanoid.docs"
