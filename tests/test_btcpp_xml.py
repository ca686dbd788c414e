"""BehaviorTree.CPP v4 XML: export, import, round trip and errors (bt_humanoid/interop/, docs/btcpp.md)."""

from __future__ import annotations

import re

import pytest

from bt_humanoid.cli import export_main, validate_main
from bt_humanoid.engine.expand import expand
from bt_humanoid.interop.btcpp import SCHEMA, compile_for_export, export_file, load_mission
from bt_humanoid.mission.loader import MissionLoader
from bt_humanoid.paths import project_root
from bt_humanoid.skills import REGISTRY

ROOT = project_root()
FILES = sorted((ROOT / "missions").glob("*.yaml")) + sorted((ROOT / "behaviors").glob("*.yaml"))
EXAMPLE = ROOT / "docs" / "examples" / "pick_and_place.xml"
IDS = [f"{p.parent.name}/{p.name}" for p in FILES]


@pytest.fixture(scope="module")
def schema():
    etree = pytest.importorskip("lxml.etree")
    return etree.XMLSchema(etree.parse(str(SCHEMA)))


def _valid(schema, text: str) -> str | None:
    from lxml import etree

    return None if schema.validate(etree.fromstring(text.encode())) else str(schema.error_log.last_error)


@pytest.mark.parametrize("file", FILES, ids=IDS)
@pytest.mark.parametrize("wrappers", [False, True], ids=["mission", "compiled"])
def test_every_export_is_valid_against_the_schema(file, wrappers, schema):
    text, _ = export_file(file, wrappers=wrappers)
    assert _valid(schema, text) is None


@pytest.mark.parametrize("file", FILES, ids=IDS)
def test_export_import_export_is_identical(file, tmp_path):
    first, _ = export_file(file, wrappers=False)
    exported = tmp_path / f"{file.stem}.xml"
    exported.write_text(first)
    second, _ = export_file(exported, wrappers=False)
    assert second == first


@pytest.mark.parametrize("name", ["demo.yaml", "recovery.yaml", "pick_and_place.yaml", "visit_kitchen.yaml"])
def test_an_imported_mission_compiles_to_the_tree_its_yaml_does(name, tmp_path):
    file = ROOT / "missions" / name
    exported = tmp_path / "mission.xml"
    exported.write_text(export_file(file, wrappers=False)[0])
    # the same nodes, paths, wrappers and resolved recovery; a number written 2.0 is labelled 2 after the trip
    same = [re.sub(r"\b(\d+)\.0\b", r"\1", expand(load_mission(f))) for f in (exported, file)]
    assert same[0] == same[1]


@pytest.mark.parametrize("name", ["demo.yaml", "recovery.yaml", "language_tour.yaml"])
def test_the_compiled_export_has_one_element_per_node_of_the_running_tree(name):
    from lxml import etree

    file = ROOT / "missions" / name
    compiled = compile_for_export(MissionLoader().load_file(file))
    running = sum(1 for _ in compiled.root.iterate())
    tree = etree.fromstring(export_file(file)[0].encode()).find("BehaviorTree")
    assert sum(1 for _ in tree.iter()) - 1 == running  # the BehaviorTree element itself is no node


def test_the_compiled_export_shows_the_wrappers_with_their_settings():
    text, _ = export_file(ROOT / "missions" / "recovery.yaml")
    assert '<Decorator ID="RecoveryRetry" retries="2" backoff="1">' in text  # recovery.skills.move_base
    assert '<Control ID="OrElse">' in text  # recovery.skills.put.alternative
    assert text.count('<Decorator ID="SafetyGuard">') >= 10
    assert '<Decorator ID="Recovery"' not in text  # the mission's own words are in the mission form only


def test_the_mission_form_writes_behaviours_as_subtrees_with_ports():
    text, _ = export_file(ROOT / "missions" / "pick_and_place.yaml", wrappers=False)
    assert '<SubTree ID="pick" object="red cube"/>' in text
    assert '<BehaviorTree ID="pick">' in text
    assert '<Action ID="stand_near" object="{picking}" side="{side}"/>' in text  # ${side} and $picking
    assert '<Action ID="stand_near" surface="{surface}" at="{x};{y}" side="{side}"/>' in text
    assert '<input_port name="side" type="std::string" default="right">' in text  # the subtree's model


def test_the_model_lists_every_skill_with_its_ports():
    from lxml import etree

    text, _ = export_file(ROOT / "missions" / "demo.yaml", wrappers=False)
    model = etree.fromstring(text.encode()).find("TreeNodesModel")
    listed = {node.get("ID"): node for node in model if node.tag in ("Action", "Condition")}
    assert set(listed) == set(REGISTRY)
    assert listed["check"].tag == "Condition"
    port = listed["move_joints"].find("input_port[@name='speed']")
    assert (port.get("type"), port.get("default"), port.text) == (
        "double",
        "1",
        "fraction of the joints' velocity and acceleration limits",
    )


def test_reactive_children_are_written_in_compact_form():
    text, _ = export_file(ROOT / "missions" / "language_tour.yaml", wrappers=False)
    guard = text[text.index("<ReactiveSequence>") : text.index("</ReactiveSequence>")]
    assert '<check key="door_open" op="equals" value="true"/>' in guard
    assert "ID=" not in guard


@pytest.mark.parametrize("file", FILES, ids=IDS)
@pytest.mark.parametrize("wrappers", [False, True], ids=["mission", "compiled"])
def test_behaviortree_cpp_parses_every_export(file, wrappers):
    """BehaviorTree.CPP 4.8's own XML check (behaviortreepy), with our skills registered as actions. Its Python
    bindings register no control nodes: ours (RoundRobin, RecoveryOrElse, OrElse) stand in as Sequence."""
    bt = pytest.importorskip("behaviortreepy")
    text, _ = export_file(file, wrappers=wrappers)
    for control in ("RoundRobin", "RecoveryOrElse", "OrElse"):
        text = text.replace(f'<Control ID="{control}">', "<Sequence>").replace(f"<{control}>", "<Sequence>")
        text = text.replace(f"</{control}>", "</Sequence>")
    text = text.replace("</Control>", "</Sequence>")
    factory = bt.BehaviorTreeFactory()
    for name, info in REGISTRY.items():
        register = factory.register_simple_condition if info.is_condition else factory.register_simple_action
        register(name, lambda node: bt.NodeStatus.SUCCESS)
    for decorator in ("Recovery", "SafetyGuard", "FaultWatch", "RecoveryRetry", "RecoveryReplan", "RecoveryAsk"):
        factory.register_simple_decorator(decorator, lambda status, node: status)
    factory.register_behavior_tree_from_text(text)  # raises on what BehaviorTree.CPP refuses
    assert "MainTree" in factory.registered_behavior_trees() or file.parent.name == "behaviors"


# --- the hand-written tree --------------------------------------------------------------


def test_the_hand_written_pick_and_place_validates(schema, capsys):
    assert validate_main([str(EXAMPLE)]) == 0
    assert "BehaviorTree.CPP XML" in capsys.readouterr().out
    assert _valid(schema, EXAMPLE.read_text()) is None


def test_the_hand_written_tree_calls_library_behaviours_and_its_own_subtree():
    spec = load_mission(EXAMPLE)
    kinds = [node.kind for node in spec.tree.children]
    assert kinds == ["say", "sequence", "pick", "ToTheCounter", "place", "say"]
    assert spec.tree.children[3].name == "to the counter"
    assert [c.category for c in spec.tree.children[2].children[0].children] == ["skill"] * 4  # behaviors/pick.yaml


@pytest.mark.sim
def test_the_hand_written_pick_and_place_runs_to_success(run_mission):
    scenario = run_mission(EXAMPLE)
    assert scenario.result.success, scenario.result.summary()
    assert scenario.result.said == ["I will bring the red cube to the counter.", "The red cube is on the counter."]
    assert scenario.truth.robot_contacts() == []


# --- errors: one line at file:line, exit 2 -------------------------------------------------


def _tree(body: str, extra: str = "") -> str:
    head = '<root BTCPP_format="4" main_tree_to_execute="Main">\n<BehaviorTree ID="Main">\n'
    return f"{head}{body}\n</BehaviorTree>\n{extra}</root>\n"


def _error(tmp_path, capsys, text: str) -> str:
    file = tmp_path / "tree.xml"
    file.write_text(text)
    assert validate_main([str(file)]) == 2
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err
    return " ".join(captured.err.split())


def test_an_unknown_node_names_its_line_and_the_close_match(tmp_path, capsys):
    error = _error(
        tmp_path, capsys, _tree('<Sequence>\n  <say text="hi"/>\n  <Action ID="move_bse" x="1"/>\n</Sequence>')
    )
    assert "tree.xml:5: unknown node 'move_bse'" in error
    assert "did you mean 'move_base'?" in error


def test_a_missing_required_port_names_its_line(tmp_path, capsys):
    error = _error(tmp_path, capsys, _tree("<Sequence>\n  <say/>\n</Sequence>"))
    assert "tree.xml:4: say: missing required parameter 'text'" in error


def test_a_bad_port_value_names_the_port_and_the_value(tmp_path, capsys):
    error = _error(tmp_path, capsys, _tree('<move_base x="far" y="0"/>'))
    assert "tree.xml:3: move_base: x:" in error
    assert "'far'" in error


def test_an_unknown_port_is_refused(tmp_path, capsys):
    error = _error(tmp_path, capsys, _tree('<wait secs="1"/>'))
    assert "tree.xml:3: wait: unknown port 'secs'" in error and "did you mean 'seconds'?" in error


def test_malformed_xml_names_its_line(tmp_path, capsys):
    error = _error(tmp_path, capsys, _tree("<Sequence>\n  <say text='hi'>\n</Sequence>"))
    assert "tree.xml:5: malformed XML: mismatched tag" in error


def test_a_compiled_export_is_refused_with_the_way_out(tmp_path, capsys):
    compiled, _ = export_file(ROOT / "missions" / "demo.yaml")
    error = _error(tmp_path, capsys, compiled)
    assert "SafetyGuard is a wrapper the compiler adds" in error and "--no-wrappers" in error


def test_a_builtin_with_no_counterpart_is_named(tmp_path, capsys):
    error = _error(tmp_path, capsys, _tree('<Sequence>\n<Script code="x:=1"/>\n</Sequence>'))
    assert "tree.xml:4: BehaviorTree.CPP's Script has no counterpart here" in error


def test_a_parallel_threshold_without_counterpart_is_refused(tmp_path, capsys):
    waits = '<wait seconds="1"/>' * 3
    body = f'<Parallel success_count="2" failure_count="1">\n{waits}\n</Parallel>'
    error = _error(tmp_path, capsys, _tree(body))
    assert 'tree.xml:3: Parallel success_count="2"' in error and "valid: -1 or 3" in error


def test_a_decorator_needs_one_child(tmp_path, capsys):
    error = _error(tmp_path, capsys, _tree('<Inverter>\n<wait seconds="1"/>\n<wait seconds="1"/>\n</Inverter>'))
    assert "tree.xml:3: Inverter holds exactly 1 child node, found 2" in error


def test_an_unknown_subtree_is_named(tmp_path, capsys):
    error = _error(tmp_path, capsys, _tree('<SubTree ID="pik" object="red cube"/>'))
    assert "tree.xml:3: unknown subtree 'pik'" in error and "did you mean 'pick'?" in error


def test_an_error_in_the_header_comment_names_the_file_line(tmp_path, capsys):
    text = "<!-- bt-humanoid mission\nmission: m\nworld: nowhere\n-->\n" + _tree('<wait seconds="1"/>')
    error = _error(tmp_path, capsys, text)
    assert "tree.xml:3: unknown world 'nowhere'" in error


def test_a_yaml_error_in_the_header_comment_names_the_file_line(tmp_path, capsys):
    text = "<!-- bt-humanoid mission\nmission: m\nsafety: {max_base_speed: [\n-->\n" + _tree('<wait seconds="1"/>')
    error = _error(tmp_path, capsys, text)
    assert "tree.xml:4: YAML syntax error" in error


def test_bt_run_refuses_an_invalid_tree_before_any_physics(tmp_path, capsys):
    from bt_humanoid.cli import run_main

    file = tmp_path / "tree.xml"
    file.write_text(_tree('<Sequence>\n<move_base place="atlantis"/>\n</Sequence>'))
    assert run_main([str(file), "--no-live"]) == 2
    error = " ".join(capsys.readouterr().err.split())
    assert "tree.xml:4: move_base: unknown place 'atlantis'" in error


# --- values ---------------------------------------------------------------------------------


def test_values_keep_their_types_and_escapes(tmp_path):
    from bt_humanoid.interop.btcpp_values import decode, encode

    assert encode("$$5", str) == "$5" and decode("$5", str) == "$$5"  # a literal dollar
    assert encode("$cube", str) == "{cube}" and decode("{cube}", str) == "$cube"
    assert encode(0, float) == encode(0.0, float) == "0"
    assert decode("2.7;-0.02", tuple[float, float]) == [2.7, -0.02]
    assert encode("2", object) == 'json:"2"' and decode('json:"2"', object) == "2"  # text, not a number
    assert decode("true", object) is True and decode("All done.", object) == "All done."
    with pytest.raises(ValueError, match="blackboard entry"):
        encode("a {literal} brace", str)


def test_bt_export_writes_a_file(tmp_path, capsys):
    out = tmp_path / "demo.xml"
    assert export_main([str(ROOT / "missions" / "demo.yaml"), "-o", str(out)]) == 0
    assert out.read_text().startswith('<?xml version="1.0" encoding="UTF-8"?>')
    assert export_main([str(ROOT / "missions" / "nope.yaml")]) == 2
