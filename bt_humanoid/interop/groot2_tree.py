"""The running tree as Groot2 asks for it: BehaviorTree.CPP's ``WriteTreeToXML(tree, add_metadata=true,
add_builtin_models=true)`` form, with a ``_uid`` on every node, and the py_trees node behind each uid.

BehaviorTree.CPP gives its nodes uids 1, 2, … in the order it creates them: depth first, a subtree's nodes
created where its ``<SubTree>`` is (``XMLParser::recursivelyCreateSubtree``). Each call of a subtree is an
instance with its own ``<BehaviorTree ID=… _fullpath=…>`` element and its own uids. The nodes are the
compiled tree's, one element per py_trees node (bt-export's compiled form, interop/btcpp_export.py), so a
uid's status is the status of exactly one py_trees node.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

from py_trees.behaviour import Behaviour

from bt_humanoid.engine.compiler import CompiledMission
from bt_humanoid.interop.btcpp_document import Document
from bt_humanoid.interop.btcpp_export import MAIN_TREE, El, compiled_elements

#: BehaviorTree.CPP's own nodes a compiled tree may hold: category and ports (name, type), as its factory
#: registers them (the models Groot2 is sent with add_builtin_models=true)
BUILTIN_MODELS: dict[str, tuple[str, tuple[tuple[str, str], ...]]] = {
    "Sequence": ("Control", ()),
    "Fallback": ("Control", ()),
    "ReactiveSequence": ("Control", ()),
    "ReactiveFallback": ("Control", ()),
    "Parallel": ("Control", (("success_count", "int"), ("failure_count", "int"))),
    "RetryUntilSuccessful": ("Decorator", (("num_attempts", "int"),)),
    "Timeout": ("Decorator", (("msec", "unsigned int"),)),
    "Repeat": ("Decorator", (("num_cycles", "int"),)),
    "Inverter": ("Decorator", ()),
    "ForceSuccess": ("Decorator", ()),
    "ForceFailure": ("Decorator", ()),
}


@dataclass(frozen=True)
class Groot2Tree:
    """The FULLTREE reply's XML, and the py_trees node of each uid (``nodes[uid - 1]``)."""

    xml: str
    nodes: list[Behaviour]


def groot2_tree(document: Document, compiled: CompiledMission) -> Groot2Tree:
    """``compiled`` (the mission ``document`` compiled) written as BehaviorTree.CPP's publisher writes a tree."""
    trees, models = compiled_elements(document, compiled)
    return _Writer(trees).write(compiled.root, models)


class _Writer:
    def __init__(self, trees: dict[str, El]) -> None:
        self.trees = trees
        self.root = ET.Element("root", {"BTCPP_format": "4"})
        self.nodes: list[Behaviour] = []
        self.used: set[str] = set()

    def write(self, root: Behaviour, models: list[El]) -> Groot2Tree:
        self._instance(MAIN_TREE, "", self.trees[MAIN_TREE], root)
        model_root = ET.SubElement(self.root, "TreeNodesModel")
        builtins = [_builtin_model(tag) for tag in BUILTIN_MODELS if tag in self.used]
        for model in sorted([*models, *builtins], key=_model_id):
            model_root.append(_model_element(model))
        ET.indent(self.root, "  ")
        return Groot2Tree(ET.tostring(self.root, encoding="unicode") + "\n", self.nodes)

    def _instance(self, tree_id: str, path: str, element: El, node: Behaviour) -> None:
        """One instance of a tree: its ``<BehaviorTree>`` element, then its nodes (and the subtrees they call)."""
        tree = ET.SubElement(self.root, "BehaviorTree", {"ID": tree_id, "_fullpath": path})
        self._node(element, node, tree, path)

    def _node(self, element: El, node: Behaviour, parent: ET.Element, path: str) -> None:
        self.nodes.append(node)
        uid = str(len(self.nodes))
        attrs = dict(element.attrs)
        if element.id == "SubTree":
            # a call: its instance's path is the caller's, then the call's name (BehaviorTree.CPP: ID::uid)
            tree_id = attrs.pop("ID")
            instance = f"{path}/" if path else ""
            instance += attrs.pop("name", None) or f"{tree_id}::{uid}"
            ET.SubElement(parent, "SubTree", {"ID": tree_id, "_fullpath": instance, "_uid": uid, **attrs})
            (child,) = node.children  # the call compiles to a sequence around the behaviour's tree
            self._instance(tree_id, instance, self.trees[tree_id], child)
            return
        if element.category is None:
            self.used.add(element.id)
        name = attrs.pop("name", None) or node.name
        written = ET.SubElement(parent, element.id, {"name": name, "_uid": uid, **attrs})
        if len(element.children) != len(node.children):
            raise AssertionError(f"{element.id} '{node.name}': the export and the running tree differ")
        for child_element, child in zip(element.children, node.children, strict=True):
            self._node(child_element, child, written, path)


def _model_id(model: El) -> str:
    return dict(model.attrs)["ID"]


def _builtin_model(tag: str) -> El:
    category, ports = BUILTIN_MODELS[tag]
    return El(
        category, attrs=[("ID", tag)], children=[El("input_port", attrs=[("name", n), ("type", t)]) for n, t in ports]
    )


def _model_element(model: El) -> ET.Element:
    """A TreeNodesModel entry: ``<Action ID="pick"><input_port …>…</input_port><description>…</…></Action>``."""
    element = ET.Element(model.id, dict(model.attrs))
    for child in model.children:
        sub = ET.SubElement(element, child.id, dict(child.attrs))
        sub.text = child.text or None
    return element
