"""BehaviorTree.CPP v4 XML → the mission language, every error at file:line.

The XML becomes the same data a mission file gives (plus the line of each value), and the behaviours its
``<BehaviorTree>``s define; the mission loader then validates it like YAML and the compiler adds Safety and
Recovery. Nodes: our skills (``<Action ID="move_base" x="1"/>`` or ``<move_base x="1"/>``), behaviours called
with ``<SubTree ID=… param="…"/>``, BehaviorTree.CPP's standard controls and decorators (btcpp_nodes.py), and
our RoundRobin, Recovery and RecoveryOrElse. Anything else is refused, naming what would be valid.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from bt_humanoid.errors import UserError, did_you_mean
from bt_humanoid.interop.btcpp_document import BehaviorDef, Document, complete
from bt_humanoid.interop.btcpp_export import (
    BEHAVIOR_MARK,
    MISSION_MARK,
    PARAM_ANNOTATIONS,
    PARAM_TYPES,
    RECOVERY_FIELDS,
)
from bt_humanoid.interop.btcpp_nodes import (
    MISSION_NODE_IDS,
    SCRIPTED_ATTRIBUTES,
    TAG_COMPOSITES,
    TAG_DECORATORS,
    UNSUPPORTED_BUILTINS,
    WRAPPER_IDS,
)
from bt_humanoid.interop.btcpp_values import decode
from bt_humanoid.interop.btcpp_xml import XmlDocument, XmlElement, parse_xml
from bt_humanoid.mission.behaviors import Behavior, BehaviorHeader, BehaviorLibrary, _args_model
from bt_humanoid.mission.schema import structural_kinds
from bt_humanoid.skills import REGISTRY
from bt_humanoid.yaml_source import YamlPath, YamlSource, read_yaml

TYPES_BY_PORT = {port: kind for kind, port in PARAM_TYPES.items()}
STANDARD = [*TAG_COMPOSITES, "Parallel", *TAG_DECORATORS, "SubTree", "Action", "Condition", "Control", "Decorator"]


@dataclass
class ImportedXml:
    """A BehaviorTree.CPP file read: the document, and its mission (or behaviour) as loader input."""

    document: Document
    source: YamlSource | None  # the mission, with lines; None for a behaviour
    behaviors: dict[str, Behavior] = field(default_factory=dict)  # the behaviours it defines, as the loader takes them

    def library(self, base: BehaviorLibrary) -> BehaviorLibrary:
        """``base`` with this file's behaviours over its own (a subtree edited in Groot2 wins)."""
        merged = copy.copy(base)
        merged._behaviors = {**base.behaviors, **self.behaviors}
        return merged


def read_btcpp(file: Path, text: str | None = None, library: BehaviorLibrary | None = None) -> ImportedXml:
    """Read a BehaviorTree.CPP v4 XML file; every problem is a UserError at file:line."""
    xml = parse_xml(Path(file), text)
    return _Reader(xml, library or BehaviorLibrary()).read()


class _Reader:
    def __init__(self, xml: XmlDocument, library: BehaviorLibrary) -> None:
        self.xml = xml
        self.library = library

    def fail(self, element: XmlElement | int, message: str, hint: str | None = None) -> UserError:
        return UserError(message, where=self.xml.where(element), hint=hint)

    # --- the file ----------------------------------------------------------------------------------

    def read(self) -> ImportedXml:
        root = self.xml.root
        if root.tag != "root":
            raise self.fail(root, f'a BehaviorTree.CPP file starts with <root BTCPP_format="4">, not <{root.tag}>')
        version = root.attrs.get("BTCPP_format", "4")
        if version != "4":
            raise self.fail(root, f'BTCPP_format="{version}": this reads BehaviorTree.CPP v4 XML (BTCPP_format="4")')
        trees: dict[str, XmlElement] = {}
        models: dict[str, XmlElement] = {}
        for child in root.children:
            if child.tag == "BehaviorTree":
                tree_id = child.attrs.get("ID")
                if not tree_id:
                    raise self.fail(child, "<BehaviorTree> needs an ID")
                if tree_id in trees:
                    raise self.fail(child, f"two <BehaviorTree>s are called '{tree_id}'")
                if len(child.children) != 1:
                    raise self.fail(
                        child, f'<BehaviorTree ID="{tree_id}"> holds exactly one node, found {len(child.children)}'
                    )
                trees[tree_id] = child
            elif child.tag == "TreeNodesModel":
                models |= {m.attrs.get("ID", ""): m for m in child.children if m.tag == "SubTree"}
            elif child.tag == "include":
                raise self.fail(child, "<include> is not read here", hint="put the subtrees in this one file")
            else:
                raise self.fail(
                    child, f"unexpected <{child.tag}> in <root>", hint="valid: BehaviorTree, TreeNodesModel"
                )
        if not trees:
            raise self.fail(root, "no <BehaviorTree> in the file")
        main = root.attrs.get("main_tree_to_execute")
        if main is None:
            if len(trees) != 1:
                raise self.fail(root, "main_tree_to_execute is needed with more than one <BehaviorTree>")
            main = next(iter(trees))
        if main not in trees:
            raise self.fail(
                root, f'main_tree_to_execute="{main}": no such <BehaviorTree>', hint=did_you_mean(main, trees)
            )
        mark, header, header_lines = self._header()
        is_behavior = mark == BEHAVIOR_MARK
        if is_behavior and header.get("behavior") != main:
            raise self.fail(root, f"the behaviour header names '{header.get('behavior')}', the main tree is '{main}'")
        self.subtrees = {tree_id for tree_id in trees if is_behavior or tree_id != main}
        for tree_id in self.subtrees:
            if tree_id in REGISTRY or tree_id in structural_kinds():
                raise self.fail(
                    trees[tree_id], f"a subtree may not be called '{tree_id}': that is a skill or node kind"
                )
        self.params = {tree_id: self._params(tree_id, models.get(tree_id), trees) for tree_id in self.subtrees}
        definitions: dict[str, BehaviorDef] = {}
        behaviors: dict[str, Behavior] = {}
        example = (header.pop("example", None) or {}) if is_behavior else {}
        for tree_id in sorted(self.subtrees, key=lambda t: list(trees).index(t)):
            lines: dict[YamlPath, int] = {}
            tree = self.node(trees[tree_id].children[0], ("tree",), frozenset(self.params[tree_id]), lines)
            model = models.get(tree_id)
            description = _description(model) if model is not None else ""
            definition = BehaviorDef(
                tree_id, self.params[tree_id], description, tree, example if tree_id == main else {}
            )
            definitions[tree_id] = definition
            behaviors[tree_id] = self._behavior(definition, lines, trees[tree_id])
        if is_behavior:
            document = Document(header, None, definitions, self.xml.file)
            complete(document, self.library)
            return ImportedXml(document, None, behaviors)
        lines = {key: value for key, value in header_lines.items()}
        lines[("tree",)] = trees[main].line
        tree = self.node(trees[main].children[0], ("tree",), frozenset(), lines)
        document = Document(header, tree, definitions, self.xml.file)
        complete(document, self.library)
        source = YamlSource(self.xml.file, {**header, "tree": tree}, lines)
        return ImportedXml(document, source, behaviors)

    def _header(self) -> tuple[str | None, dict[str, Any], dict[YamlPath, int]]:
        """The mission (or behaviour) header from the comment bt-export writes before <root>; none: defaults."""
        for comment in self.xml.comments:
            text = comment.text.lstrip()
            mark = next((m for m in (MISSION_MARK, BEHAVIOR_MARK) if text.startswith(m)), None)
            if mark is None:
                continue
            # blank lines in front, so that the YAML's lines (and its syntax errors) are the file's
            body = "\n" * (comment.line - 1) + text[len(mark) :]
            source = read_yaml(self.xml.file, body)
            if not isinstance(source.data, dict):
                raise self.fail(comment.line, f"the {mark} header is a YAML mapping")
            return mark, dict(source.data), dict(source.lines)
        main = self.xml.root.attrs.get("main_tree_to_execute") or "behaviour tree"
        return None, {"mission": main}, {}

    def _params(
        self, tree_id: str, model: XmlElement | None, trees: dict[str, XmlElement]
    ) -> dict[str, dict[str, Any]]:
        """A subtree's parameters: its TreeNodesModel ports; without one, the ports its callers pass (any type)."""
        params: dict[str, dict[str, Any]] = {}
        if model is None:
            for call in _calls(trees.values(), tree_id):
                for name in call.attrs:
                    if name not in ("ID", "name") and not name.startswith("_"):
                        params.setdefault(name, {"type": "any", "description": ""})
            return params
        for port in model.children:
            if port.tag not in ("input_port", "inout_port"):
                continue
            name = port.attrs.get("name")
            if not name:
                raise self.fail(port, f"a port of subtree '{tree_id}' needs a name")
            kind = TYPES_BY_PORT.get(port.attrs.get("type", "BT::Any"), "any")
            spec: dict[str, Any] = {"type": kind}
            if "default" in port.attrs:
                default = port.attrs["default"]
                spec["default"] = None if default == "" else decode(default, PARAM_ANNOTATIONS[kind])
            else:
                spec["required"] = True
            spec["description"] = port.text.strip()
            params[name] = spec
        return params

    def _behavior(self, definition: BehaviorDef, lines: dict[YamlPath, int], element: XmlElement) -> Behavior:
        try:
            header = BehaviorHeader.model_validate(
                {"behavior": "x", "params": definition.params, "description": definition.description, "tree": {}}
            )
        except ValidationError as error:
            raise self.fail(element, f"subtree '{definition.name}': its ports: {error.errors()[0]['msg']}") from None
        source = YamlSource(self.xml.file, {"tree": definition.tree}, lines)
        args = _args_model(definition.name, header)
        return Behavior(definition.name, definition.description, source, args, definition.example)

    # --- nodes -----------------------------------------------------------------------------------------

    def node(self, element: XmlElement, ypath: YamlPath, params: frozenset[str], lines: dict[YamlPath, int]) -> dict:
        """One element as a mission node (a mapping with one kind key), its lines recorded in ``lines``."""
        tag = element.tag
        attrs = dict(element.attrs)
        if tag in ("Action", "Condition", "Control", "Decorator"):
            node_id = attrs.pop("ID", None)
            if not node_id:
                raise self.fail(element, f"<{tag}> needs an ID")
        elif tag == "SubTree":
            node_id = tag
        else:
            node_id = tag
            if "ID" in attrs:
                raise self.fail(element, f"<{tag}> takes no ID", hint=f'write <Action ID="{tag}" …/> or <{tag} …/>')
        name = attrs.pop("name", None)
        for attribute in list(attrs):
            if attribute in SCRIPTED_ATTRIBUTES:
                raise self.fail(
                    element,
                    f"{attribute}: BehaviorTree.CPP's scripted conditions are not read here",
                    hint="use a check skill in a guard or fallback",
                )
        if node_id in MISSION_NODE_IDS and node_id != "RoundRobin":
            return self._recovery(element, node_id, attrs, ypath, params, lines, name)
        lines[ypath] = element.line
        data = self._kind(element, node_id, attrs, ypath, params, lines)
        if name is not None:
            data["name"] = name
            lines[(*ypath, "name")] = element.line
        return data

    def _kind(self, element, node_id, attrs, ypath, params, lines) -> dict:
        children = element.children

        def at(kind: str) -> YamlPath:
            lines[(*ypath, kind)] = element.line
            return (*ypath, kind)

        def no_ports(kind: str) -> None:
            if attrs:
                raise self.fail(element, f"{node_id} takes no ports here, got: {', '.join(attrs)}")

        def count(low: int, high: int | None = None) -> None:
            n = len(children)
            if n < low or (high is not None and n > high):
                wanted = f"exactly {low}" if high == low else f"at least {low}"
                raise self.fail(element, f"{node_id} holds {wanted} child node{'s' if low != 1 else ''}, found {n}")

        if node_id in TAG_COMPOSITES:
            kind = TAG_COMPOSITES[node_id]
            no_ports(kind)
            count(1)
            base = at(kind)
            return {kind: [self.node(c, (*base, i), params, lines) for i, c in enumerate(children)]}
        if node_id == "RoundRobin":
            no_ports("round_robin")
            count(1)
            base = at("round_robin")
            return {"round_robin": [self.node(c, (*base, i), params, lines) for i, c in enumerate(children)]}
        if node_id == "Parallel":
            count(1)
            base = at("parallel")
            policy = self._policy(element, attrs, len(children))
            kids = [self.node(c, (*base, "children", i), params, lines) for i, c in enumerate(children)]
            return {"parallel": {"policy": policy, "children": kids}}
        if node_id in TAG_DECORATORS:
            kind, port, setting = TAG_DECORATORS[node_id]
            count(1, 1)
            base = at(kind)
            body: dict[str, Any] = {}
            if port is not None:
                if port not in attrs:
                    raise self.fail(element, f"{node_id} needs its port {port}")
                body[setting] = self._decorator_value(element, node_id, port, attrs.pop(port), params)
                lines[(*base, setting)] = element.line
            no_ports(kind)
            body["child"] = self.node(children[0], (*base, "child"), params, lines)
            return {kind: body}
        if node_id == "SubTree":
            return self._call(element, attrs, ypath, params, lines, at)
        if node_id in REGISTRY:
            if children:
                raise self.fail(element, f"skill {node_id} is a leaf: it holds no child nodes")
            base = at(node_id)
            fields = REGISTRY[node_id].params.model_fields
            body = {}
            for port, value in attrs.items():
                if port not in fields:
                    raise self.fail(element, f"{node_id}: unknown port '{port}'", hint=did_you_mean(port, fields))
                annotation = fields[port].annotation
                body[port] = decode(value, annotation, params)
                lines[(*base, port)] = element.line
            return {node_id: body}
        if node_id in WRAPPER_IDS:
            raise self.fail(
                element,
                f"{node_id} is a wrapper the compiler adds: a compiled export is for viewing",
                hint="bt-export --no-wrappers writes the tree to read back; the compiler adds the wrappers again",
            )
        if node_id in UNSUPPORTED_BUILTINS:
            raise self.fail(
                element,
                f"BehaviorTree.CPP's {node_id} has no counterpart here",
                hint=f"valid: {', '.join(STANDARD)}, RoundRobin, Recovery, RecoveryOrElse and the skills",
            )
        if node_id in self.subtrees or node_id in self.library.behaviors:
            raise self.fail(element, f"'{node_id}' is a behaviour: call it as <SubTree ID=\"{node_id}\" …/>")
        options = [*STANDARD, *MISSION_NODE_IDS, *REGISTRY]
        raise self.fail(element, f"unknown node '{node_id}'", hint=did_you_mean(node_id, options))

    def _policy(self, element: XmlElement, attrs: dict[str, str], children: int) -> str:
        success = attrs.pop("success_count", "-1")
        failure = attrs.pop("failure_count", "1")
        if attrs:
            raise self.fail(element, f"Parallel takes success_count and failure_count, got: {', '.join(attrs)}")
        if failure != "1":
            raise self.fail(
                element, f'Parallel failure_count="{failure}": here any failing child fails it', hint="valid: 1"
            )
        if success in ("-1", str(children)):
            return "all"
        if success == "1":
            return "one"
        raise self.fail(
            element,
            f'Parallel success_count="{success}"',
            hint=f"valid: -1 or {children} (all children) or 1 (the first to succeed)",
        )

    def _decorator_value(self, element: XmlElement, node_id: str, port: str, value: str, params: frozenset[str]) -> Any:
        decoded = decode(value, int, params)
        if isinstance(decoded, str) and decoded.startswith("${") and node_id != "Timeout":
            return decoded  # a behaviour parameter, filled in where the behaviour is called
        if not isinstance(decoded, int):
            raise self.fail(
                element,
                f'{node_id} {port}="{value}": a whole number is needed',
                hint="blackboard entries {key} are not read by this decorator here",
            )
        return decoded / 1000 if node_id == "Timeout" else decoded

    def _call(self, element, attrs, ypath, params, lines, at) -> dict:
        tree_id = attrs.pop("ID", None)
        if not tree_id:
            raise self.fail(element, "<SubTree> needs an ID")
        if element.children:
            raise self.fail(element, f'<SubTree ID="{tree_id}"> holds no child nodes')
        attrs.pop("_autoremap", None)  # behaviours share the one blackboard here: remapping is always on
        if tree_id in self.subtrees:
            declared = self.params[tree_id]
        elif tree_id in self.library.behaviors:
            declared = {
                name: {"type": _param_type(f.annotation)}
                for name, f in self.library.behaviors[tree_id].args_model.model_fields.items()
            }
        else:
            valid = sorted({*self.subtrees, *self.library.behaviors})
            raise self.fail(element, f"unknown subtree '{tree_id}'", hint=did_you_mean(tree_id, valid))
        base = at(tree_id)
        body = {}
        for port, value in attrs.items():
            kind = declared.get(port, {}).get("type", "any")
            body[port] = decode(value, PARAM_ANNOTATIONS[kind], params)
            lines[(*base, port)] = element.line
        return {tree_id: body}

    def _recovery(self, element, node_id, attrs, ypath, params, lines, name) -> dict:
        """Recovery (one child) or RecoveryOrElse (the node, then its alternative): the node's own ``recovery:``."""
        wanted = 1 if node_id == "Recovery" else 2
        if len(element.children) != wanted:
            raise self.fail(
                element,
                f"{node_id} holds exactly {wanted} child node{'s' if wanted > 1 else ''}, "
                f"found {len(element.children)}",
            )
        if name is not None:
            raise self.fail(element, f"{node_id}: give the name to the node inside it")
        recovery: dict[str, Any] = {}
        for port, value in attrs.items():
            if port not in RECOVERY_FIELDS:
                raise self.fail(element, f"{node_id}: unknown port '{port}'", hint=did_you_mean(port, RECOVERY_FIELDS))
            recovery[port] = decode(value, RECOVERY_FIELDS[port], params)
            lines[(*ypath, "recovery", port)] = element.line
        data = self.node(element.children[0], ypath, params, lines)
        if "recovery" in data:
            raise self.fail(element, f"{node_id} around a node that has one already")
        if wanted == 2:
            recovery["alternative"] = self.node(element.children[1], (*ypath, "recovery", "alternative"), params, lines)
        lines[(*ypath, "recovery")] = element.line
        data["recovery"] = recovery
        return data


def _description(model: XmlElement) -> str:
    found = next((c for c in model.children if c.tag == "description"), None)
    return found.text.strip() if found is not None else ""


def _calls(trees, tree_id: str):
    def walk(element: XmlElement):
        if element.tag == "SubTree" and element.attrs.get("ID") == tree_id:
            yield element
        for child in element.children:
            yield from walk(child)

    for tree in trees:
        yield from walk(tree)


def _param_type(annotation: Any) -> str:
    base = annotation
    for kind, python in PARAM_ANNOTATIONS.items():
        if base is python or base == python | None:
            return kind
    return "any"
