"""Mission → BehaviorTree.CPP v4 XML.

Two forms. The mission form (``wrappers=False``) writes the mission's own structure: behaviours as
``<SubTree>`` calls with one ``<BehaviorTree>`` each, a node's own ``recovery:`` as a ``Recovery`` decorator; it
is what ``bt-run`` and ``bt-validate`` read back, byte for byte the same on the next export. The compiled form
(the default of ``bt-export``) writes the tree as it runs: every Safety guard and recovery step the compiler
added, one element per py_trees node; it is for viewing (Groot2), not for reading back.
The mission header (world, robot, safety, success, …) travels as YAML in a comment before ``<root>``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import yaml
from py_trees.behaviour import Behaviour

from bt_humanoid.engine.compiler import CompiledMission
from bt_humanoid.engine.decorators import Ask, FaultWatch, OrElse, Replan, Retry, SafetyGuard
from bt_humanoid.errors import UserError
from bt_humanoid.interop.btcpp_document import BehaviorDef, Document
from bt_humanoid.interop.btcpp_nodes import (
    COMPOSITE_TAGS,
    DECORATOR_TAGS,
    MISSION_NODES,
    RECOVERY,
    RECOVERY_OR_ELSE,
    ROUND_ROBIN,
    SEMANTICS,
    WRAPPERS,
    CustomNode,
)
from bt_humanoid.interop.btcpp_values import encode, format_number, type_name
from bt_humanoid.mission.schema import NODE_EXTRAS
from bt_humanoid.skills import REGISTRY
from bt_humanoid.yaml_source import display_path

MAIN_TREE = "MainTree"
MISSION_MARK = "bt-humanoid mission"
BEHAVIOR_MARK = "bt-humanoid behaviour"
#: behaviour parameter types ↔ the port types Groot2 shows
PARAM_TYPES = {"string": "std::string", "number": "double", "integer": "int", "boolean": "bool", "any": "BT::Any"}
PARAM_ANNOTATIONS: dict[str, Any] = {"string": str, "number": float, "integer": int, "boolean": bool, "any": Any}
RECOVERY_FIELDS = {"retries": int, "backoff": float, "replan": int, "ask": bool}
REACTIVE = ("ReactiveSequence", "ReactiveFallback")


@dataclass
class El:
    """An element to write: a built-in node (``category`` None) or one with an ID (Action, Control, …)."""

    id: str
    category: str | None = None
    attrs: list[tuple[str, str]] = field(default_factory=list)
    children: list[El] = field(default_factory=list)
    text: str | None = None


def export_btcpp(document: Document, compiled: CompiledMission | None = None) -> str:
    """The document as BehaviorTree.CPP v4 XML; with ``compiled``, the tree as it runs (wrappers included)."""
    try:
        return _Exporter(document, compiled).write()
    except ValueError as error:
        where = display_path(document.file) if document.file else None
        raise UserError(f"cannot write as BehaviorTree.CPP XML: {error}", where=where) from None


def compiled_elements(document: Document, compiled: CompiledMission) -> tuple[dict[str, El], list[El]]:
    """The compiled form's trees (BehaviorTree ID → its root element; ``MAIN_TREE`` first) and its
    TreeNodesModel, for writers of other forms of the same tree (Groot2's live tree, interop/groot2_tree.py).

    A behaviour compiled the same way at each call is one tree here; its elements match each call's nodes.
    """
    exporter = _Exporter(document, compiled)
    try:
        exporter.write()
        return exporter.trees, exporter._models()
    except ValueError as error:
        where = display_path(document.file) if document.file else None
        raise UserError(f"cannot write as BehaviorTree.CPP XML: {error}", where=where) from None


def kind_of(node: dict[str, Any]) -> str:
    return next(key for key in node if key not in NODE_EXTRAS)


class _Exporter:
    def __init__(self, document: Document, compiled: CompiledMission | None) -> None:
        self.document = document
        self.compiled = compiled
        self.trees: dict[str, El] = {}  # BehaviorTree ID → its root, in the order written
        self.variants: dict[str, list[tuple[str, str]]] = {}  # behaviour → (tree ID, its text) per compiled form
        self.used: set[str] = set()  # element names and IDs written, for the notes on semantics

    # --- the document -------------------------------------------------------------------

    def write(self) -> str:
        document = self.document
        if document.behavior is not None:
            main_id = document.behavior
            self._behavior_tree(document.behaviors[main_id], None)
        else:
            main_id = MAIN_TREE
            root = self.compiled.root if self.compiled is not None else None
            self.trees[MAIN_TREE] = El("placeholder")  # the main tree first
            self.trees[MAIN_TREE] = self.node(document.tree, frozenset(), root)
        for behavior in document.behaviors.values():  # called only from the header (a per-skill alternative)
            if behavior.name not in self.variants:
                self._behavior_tree(behavior, None)
        lines = ['<?xml version="1.0" encoding="UTF-8"?>', self._header()]
        lines.append(f'<root BTCPP_format="4" main_tree_to_execute={_quote(main_id)}>')
        notes = [text for key, text in SEMANTICS.items() if key in self.used]
        if notes:
            lines.append("  <!-- Where BehaviorTree.CPP would run this differently (docs/btcpp.md):")
            lines += [f"       - {text}" for text in notes]
            lines.append("  -->")
        for tree_id, root in self.trees.items():
            lines.append(f"  <BehaviorTree ID={_quote(tree_id)}>")
            _write(root, 2, lines)
            lines.append("  </BehaviorTree>")
        lines.append("  <TreeNodesModel>")
        for model in self._models():
            _write(model, 2, lines)
        lines.append("  </TreeNodesModel>")
        lines.append("</root>")
        return "\n".join(lines) + "\n"

    def _header(self) -> str:
        document = self.document
        mark = BEHAVIOR_MARK if document.behavior is not None else MISSION_MARK
        header = dict(document.header)
        if document.behavior is not None and document.behaviors[document.behavior].example:
            header["example"] = document.behaviors[document.behavior].example
        text = yaml.safe_dump(header, sort_keys=False, allow_unicode=True, width=110)
        if "--" in text or text.rstrip().endswith("-"):
            raise ValueError("its header holds '--', which an XML comment cannot: reword it")
        return f"<!-- {mark}\n{text}-->"

    def _models(self) -> list[El]:
        """The TreeNodesModel: every skill of the registry, our own nodes, and the document's behaviours."""
        models = []
        for name, info in sorted(REGISTRY.items()):
            ports = []
            for field_name, spec in info.params.model_fields.items():
                attrs = [("name", field_name), ("type", type_name(spec.annotation))]
                if not spec.is_required() and spec.default is not None:
                    attrs.append(("default", encode(spec.default, spec.annotation)))
                ports.append(El("input_port", attrs=attrs, text=spec.description or ""))
            category = "Condition" if info.is_condition else "Action"
            models.append(
                El(category, attrs=[("ID", name)], children=[*ports, El("description", text=info.description)])
            )
        # a compiled tree holds the compiler's wrappers; a mission tree, a node's own recovery
        customs: tuple[CustomNode, ...] = (ROUND_ROBIN, *WRAPPERS) if self.compiled is not None else MISSION_NODES
        for node in customs:
            ports = [
                El("input_port", attrs=[("name", n), ("type", t)] + ([("default", d)] if d is not None else []), text=s)
                for n, t, d, s in node.ports
            ]
            models.append(
                El(node.category, attrs=[("ID", node.id)], children=[*ports, El("description", text=node.description)])
            )
        for tree_id in self.trees:
            behavior = self.document.behaviors.get(tree_id.rsplit("@", 1)[0])
            if behavior is not None:
                models.append(self._subtree_model(tree_id, behavior))
        return models

    def _subtree_model(self, tree_id: str, behavior: BehaviorDef) -> El:
        ports = []
        for name, spec in behavior.params.items():
            kind = spec.get("type", "string")
            attrs = [("name", name), ("type", PARAM_TYPES[kind])]
            if not spec.get("required", False):
                default = spec.get("default")
                # no default and not required: left out (None); BehaviorTree.CPP has no such port, "" stands for it
                attrs.append(("default", "" if default is None else encode(default, PARAM_ANNOTATIONS[kind])))
            ports.append(El("input_port", attrs=attrs, text=spec.get("description", "")))
        return El("SubTree", attrs=[("ID", tree_id)], children=[*ports, El("description", text=behavior.description)])

    # --- nodes -----------------------------------------------------------------------------

    def node(self, data: dict[str, Any], params: frozenset[str], guard: Behaviour | None) -> El:
        """One mission node; ``guard`` is its compiled form (its SafetyGuard) in a compiled export."""
        chain, inner = _unwrap(guard) if guard is not None else ([], None)
        kind = kind_of(data)
        element = self._inner(kind, data[kind], params, inner)
        if data.get("name") is not None:
            first = 1 if element.attrs and element.attrs[0][0] == "ID" else 0  # a SubTree's ID leads
            element.attrs.insert(first, ("name", data["name"]))
        if guard is not None:
            return self._wrapped(element, chain, data, kind, params)
        recovery = data.get("recovery")
        if not recovery:
            return element
        attrs = [(name, encode(recovery[name], typed)) for name, typed in RECOVERY_FIELDS.items() if name in recovery]
        self.used.add("Recovery")
        if recovery.get("alternative") is None:
            return El(RECOVERY.id, "Decorator", attrs, [element])
        alternative = self.node(recovery["alternative"], params, None)
        return El(RECOVERY_OR_ELSE.id, "Control", attrs, [element, alternative])

    def _inner(self, kind: str, body: Any, params: frozenset[str], inner: Behaviour | None) -> El:
        children_of = inner.children if inner is not None else None

        def child(data: Any, index: int) -> El:
            return self.node(data, params, children_of[index] if children_of is not None else None)

        if kind in COMPOSITE_TAGS:
            tag = COMPOSITE_TAGS[kind]
            self.used.add(tag)
            return self._control(El(tag, children=[child(c, i) for i, c in enumerate(body)]))
        if kind == "round_robin":
            self.used.add(ROUND_ROBIN.id)
            return El(ROUND_ROBIN.id, "Control", children=[child(c, i) for i, c in enumerate(body)])
        if kind == "parallel":
            self.used.add("Parallel")
            success = "-1" if body.get("policy", "all") == "all" else "1"
            attrs = [("success_count", success), ("failure_count", "1")]
            return El("Parallel", attrs=attrs, children=[child(c, i) for i, c in enumerate(body["children"])])
        if kind == "guard":
            self.used.add("ReactiveSequence")
            return self._control(
                El("ReactiveSequence", children=[child(body["condition"], 0), child(body["child"], 1)])
            )
        if kind in DECORATOR_TAGS:
            tag, port, setting = DECORATOR_TAGS[kind]
            self.used.add(tag)
            attrs = [(port, self._decorator_value(kind, body[setting], params))] if port else []
            return El(tag, attrs=attrs, children=[child(body["child"], 0)])
        if kind in REGISTRY:
            info = REGISTRY[kind]
            fields = info.params.model_fields
            attrs = [
                (name, encode(value, fields[name].annotation if name in fields else Any, params))
                for name, value in (body or {}).items()
            ]
            return El(kind, "Condition" if info.is_condition else "Action", attrs)
        if kind == "subtree":
            behavior = self.document.behaviors[self.document.subtree_files[body["file"]]]
            return self._call(behavior, body.get("args") or {}, params, inner)
        return self._call(self.document.behaviors[kind], body or {}, params, inner)

    def _control(self, element: El) -> El:
        if element.id in REACTIVE:
            self.used.add("ReactiveSequence")
        return element

    def _decorator_value(self, kind: str, value: Any, params: frozenset[str]) -> str:
        if kind == "timeout":
            if isinstance(value, str):
                raise ValueError("a timeout's seconds given by a behaviour parameter (BehaviorTree.CPP takes msec)")
            msec = value * 1000
            if abs(msec - round(msec)) > 1e-6:
                raise ValueError(f"timeout {value} s is not a whole number of milliseconds")
            return str(round(msec))
        return encode(value, int, params)

    def _call(self, behavior: BehaviorDef, args: dict[str, Any], params: frozenset[str], inner: Behaviour | None) -> El:
        self.used.add("SubTree")
        attrs = []
        for name, value in args.items():
            kind = behavior.params.get(name, {}).get("type", "any")
            attrs.append((name, encode(value, PARAM_ANNOTATIONS[kind], params)))
        tree_id = self._behavior_tree(behavior, inner.children[0] if inner is not None else None)
        return El("SubTree", attrs=[("ID", tree_id), *attrs])

    def _behavior_tree(self, behavior: BehaviorDef, guard: Behaviour | None) -> str:
        """The ID of the BehaviorTree holding ``behavior`` (compiled: as compiled here, one ID per distinct form)."""
        variants = self.variants.setdefault(behavior.name, [])
        if guard is None and variants:
            return variants[0][0]
        root = self.node(behavior.tree, frozenset(behavior.params), guard)
        text: list[str] = []
        _write(root, 0, text)
        for tree_id, known in variants:
            if known == "\n".join(text):
                return tree_id
        # a behaviour compiled differently where it is called again (a recovery that depends on the caller)
        tree_id = behavior.name if not variants else f"{behavior.name}@{len(variants) + 1}"
        variants.append((tree_id, "\n".join(text)))
        self.trees[tree_id] = root
        return tree_id

    # --- the compiler's wrappers ------------------------------------------------------------

    def _wrapped(
        self, element: El, chain: list[Behaviour], data: dict[str, Any], kind: str, params: frozenset[str]
    ) -> El:
        self.used.add("SafetyGuard")
        for wrapper in reversed(chain):
            if isinstance(wrapper, OrElse):
                alternative = (data.get("recovery") or {}).get("alternative")
                if alternative is None:  # the mission's per-skill alternative, compiled at each use
                    alternative = self.document.header["recovery"]["skills"][kind]["alternative"]
                    params = frozenset()
                element = El("OrElse", "Control", [], [element, self.node(alternative, params, wrapper.children[1])])
                continue
            attrs: list[tuple[str, str]] = []
            if isinstance(wrapper, Retry):
                attrs = [("retries", str(wrapper.retries)), ("backoff", format_number(wrapper.backoff))]
            elif isinstance(wrapper, Replan):
                watched = ", ".join(f"{b.node.rsplit('>', 1)[-1]} ×{b.limit}" for b in wrapper.budgets.values())
                attrs = [("backoff", format_number(wrapper.backoff)), ("watches", watched)]
            element = El(_WRAPPER_IDS[type(wrapper)], "Decorator", attrs, [element])
        return element


_WRAPPER_IDS = {
    SafetyGuard: "SafetyGuard",
    FaultWatch: "FaultWatch",
    Retry: "RecoveryRetry",
    Replan: "RecoveryReplan",
    Ask: "RecoveryAsk",
    OrElse: "OrElse",
}


def _unwrap(guard: Behaviour) -> tuple[list[Behaviour], Behaviour]:
    """The wrappers from a node's SafetyGuard down (outermost first), and the node itself."""
    chain = []
    node = guard
    while type(node) in _WRAPPER_IDS:
        chain.append(node)
        node = node.children[0]
    return chain, node


def _quote(text: str) -> str:
    escaped = (
        text.replace("&", "&amp;")
        .replace("<", "&lt;")
        .replace(">", "&gt;")
        .replace('"', "&quot;")
        .replace("\n", "&#10;")
        .replace("\t", "&#9;")
    )
    return f'"{escaped}"'


def _text(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def _write(element: El, depth: int, out: list[str], compact: bool = False) -> None:
    """``element`` as indented XML lines; ``compact``: a node with an ID written as ``<ID …/>``."""
    pad = "  " * depth
    if element.category is not None and not compact:
        tag, attrs = element.category, [("ID", element.id), *element.attrs]
    else:
        tag, attrs = element.id, element.attrs
    opening = tag + "".join(f" {name}={_quote(value)}" for name, value in attrs)
    if element.text is not None:
        out.append(f"{pad}<{opening}>{_text(element.text)}</{tag}>" if element.text else f"{pad}<{opening}/>")
        return
    if not element.children:
        out.append(f"{pad}<{opening}/>")
        return
    out.append(f"{pad}<{opening}>")
    for child in element.children:
        # BehaviorTree.CPP 4.8 looks a reactive node's children up by element name: write them <ID …/>
        _write(child, depth + 1, out, compact=element.id in REACTIVE)
    out.append(f"{pad}</{tag}>")
