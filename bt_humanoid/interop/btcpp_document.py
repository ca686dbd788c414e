"""What one BehaviorTree.CPP XML file holds, in mission-language terms: a header, a main tree and the
behaviours it calls (each its parameters and its tree with ``${param}`` placeholders)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from bt_humanoid.errors import UserError
from bt_humanoid.mission.behaviors import BehaviorLibrary, load_behavior
from bt_humanoid.mission.schema import COMPOSITES, LOADER_BODIES, NODE_EXTRAS
from bt_humanoid.yaml_source import YamlSource, read_yaml


@dataclass
class BehaviorDef:
    """A behaviour as written: its header fields (params, description, example) and its tree."""

    name: str
    params: dict[str, dict[str, Any]]  # name → {type, default, required, description}, as behaviour files write them
    description: str
    tree: Any
    example: dict[str, Any] = field(default_factory=dict)


@dataclass
class Document:
    """A mission (header + tree) or a behaviour (``behavior`` names the main tree), and the behaviours called."""

    header: dict[str, Any]  # a mission's sections but its tree; for a behaviour: behavior (and example)
    tree: Any  # the main tree; None for a behaviour (its tree is behaviors[its name])
    behaviors: dict[str, BehaviorDef]  # in the order first called
    file: Path | None = None
    #: ``subtree: {file: …}`` as written → the behaviour that file defines
    subtree_files: dict[str, str] = field(default_factory=dict)

    @property
    def behavior(self) -> str | None:
        return self.header.get("behavior")

    @property
    def main_id(self) -> str:
        return self.behavior or "mission"


def behavior_def(source: YamlSource) -> BehaviorDef:
    data = source.data
    params = {name: dict(spec or {}) for name, spec in (data.get("params") or {}).items()}
    return BehaviorDef(data["behavior"], params, data.get("description", ""), data["tree"], data.get("example") or {})


def document_from_yaml(file: Path, library: BehaviorLibrary | None = None) -> Document:
    """A mission or behaviour file (already valid) as a Document, with every behaviour it calls, transitively."""
    library = library or BehaviorLibrary()
    source = read_yaml(Path(file))
    data = source.data
    if isinstance(data, dict) and "behavior" in data:
        load_behavior(Path(file))  # its header checked
        main = behavior_def(source)
        header = {"behavior": main.name}
        document = Document(header, None, {main.name: main}, Path(file))
        _collect(main.tree, document, library, Path(file))
        return document
    return document_from_data(data, library, Path(file))


def document_from_data(
    data: dict[str, Any], library: BehaviorLibrary | None = None, file: Path | None = None
) -> Document:
    """A mission given as data (already valid: a file's, or a planner's plan) as a Document, with every behaviour
    it calls, transitively; ``subtree: {file}`` calls are found beside ``file`` (none: the working folder)."""
    library = library or BehaviorLibrary()
    base = file if file is not None else Path("<plan>")
    header = {key: value for key, value in data.items() if key != "tree"}
    document = Document(header, data["tree"], {}, file)
    _collect(data["tree"], document, library, base)
    for skill in (header.get("recovery") or {}).get("skills", {}).values():
        if isinstance(skill, dict) and skill.get("alternative") is not None:
            _collect(skill["alternative"], document, library, base)
    return document


def complete(document: Document, library: BehaviorLibrary) -> None:
    """Add the library's behaviours that the document calls but does not define (an XML file may call
    behaviors/ by name), transitively."""
    for behavior in list(document.behaviors.values()):
        _collect(behavior.tree, document, library, document.file or Path("."))
    _collect(document.tree, document, library, document.file or Path("."))


def _collect(node: Any, document: Document, library: BehaviorLibrary, file: Path) -> None:
    """Add the behaviours ``node`` calls (by name, or as ``subtree: {file}``) to the document, depth first."""
    if not isinstance(node, dict):
        return
    kind = next((key for key in node if key not in NODE_EXTRAS), None)
    recovery = node.get("recovery")
    if isinstance(recovery, dict) and recovery.get("alternative") is not None:
        _collect(recovery["alternative"], document, library, file)
    body = node.get(kind)
    if kind in COMPOSITES:
        for child in body or []:
            _collect(child, document, library, file)
    elif kind == "subtree":
        behavior = load_behavior((file.parent / body["file"]).resolve())
        document.subtree_files[body["file"]] = behavior.name
        _add(behavior_def(behavior.source), document, library, behavior.source.file)
    elif kind in LOADER_BODIES:
        for child in (body or {}).get("children", []):
            _collect(child, document, library, file)
        for key in ("condition", "child"):
            _collect((body or {}).get(key), document, library, file)
    elif kind in document.behaviors:
        return  # defined in the document, or collected already (its calls with it)
    elif kind in library.behaviors:
        behavior = library.behaviors[kind]
        _add(behavior_def(behavior.source), document, library, behavior.source.file)


def _add(behavior: BehaviorDef, document: Document, library: BehaviorLibrary, file: Path) -> None:
    known = document.behaviors.get(behavior.name)
    if known is not None:
        if known.tree != behavior.tree or known.params != behavior.params:
            raise UserError(f"two different behaviours are called '{behavior.name}'", where=str(file))
        return
    document.behaviors[behavior.name] = behavior
    _collect(behavior.tree, document, library, file)
