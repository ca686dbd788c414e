"""BehaviorTree.CPP files for the command line: load one as a mission, check one, export a file as one."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

from bt_humanoid.engine.compiler import CompiledMission, Compiler
from bt_humanoid.errors import UserError
from bt_humanoid.interop.btcpp_document import Document, document_from_data, document_from_yaml
from bt_humanoid.interop.btcpp_export import export_btcpp
from bt_humanoid.interop.btcpp_import import ImportedXml, read_btcpp
from bt_humanoid.mission.behaviors import BehaviorLibrary, default_args, load_behavior
from bt_humanoid.mission.loader import MissionLoader
from bt_humanoid.mission.spec import MissionSpec
from bt_humanoid.safety.monitors import SafetySupervisor
from bt_humanoid.skills.context import SkillContext
from bt_humanoid.yaml_source import display_path, read_yaml

SCHEMA = Path(__file__).with_name("btcpp_schema.xsd")


def is_xml(file: Path) -> bool:
    return Path(file).suffix.lower() == ".xml"


def load_mission(file: Path, loader: MissionLoader | None = None) -> MissionSpec:
    """A mission file, YAML or BehaviorTree.CPP XML (Groot2's, or bt-export's), validated by ``loader``."""
    loader = loader or MissionLoader()
    if not is_xml(file):
        return loader.load_file(Path(file))
    imported = read_btcpp(Path(file), library=loader.library)
    return _loader_for(imported, loader).load_source(_mission_source(imported, file))


def check_xml(file: Path) -> str:
    """bt-validate for a BehaviorTree.CPP file: a one-line description, or a UserError at file:line."""
    library = BehaviorLibrary()
    imported = read_btcpp(Path(file), library=library)
    if imported.source is None:
        name = imported.document.behavior
        _check_behavior(name, imported.library(library), file)
        return f"behaviour '{name}' (BehaviorTree.CPP XML)"
    spec = _loader_for(imported, MissionLoader(library=library)).load_source(imported.source)
    count = sum(1 for _ in spec.tree.walk())
    return f"mission '{spec.header.mission}' ({count} nodes, BehaviorTree.CPP XML)"


def load_document(file: Path) -> tuple[Document, MissionSpec | None]:
    """The file as a Document, checked as bt-validate checks it; with the mission's spec (None: a behaviour)."""
    file = Path(file)
    library = BehaviorLibrary()
    if is_xml(file):
        check_xml(file)
        document = read_btcpp(file, library=library).document
    else:
        source = read_yaml(file)
        if isinstance(source.data, dict) and "behavior" in source.data:
            _check_behavior(load_behavior(file).name, library, file)
        else:
            MissionLoader(library=library).load_source(source)
        document = document_from_yaml(file, library)
    spec = load_mission(file, MissionLoader(library=library)) if document.behavior is None else None
    return document, spec


def mission_document(mission: Path | dict[str, Any], library: BehaviorLibrary | None = None) -> Document:
    """The Document of a mission already loaded: from its file (YAML or BehaviorTree.CPP XML), or from a plan's
    data (a command's)."""
    library = library or BehaviorLibrary()
    if isinstance(mission, dict):
        return document_from_data(mission, library)
    if is_xml(mission):
        return read_btcpp(Path(mission), library=library).document
    return document_from_yaml(Path(mission), library)


def compile_for_export(spec: MissionSpec) -> CompiledMission:
    """The tree the mission runs as (a supervisor with no monitors: nothing runs)."""
    known = spec.known
    context = SkillContext(known.robot_config, known.world, known.joint_ranges)
    return Compiler(context, SafetySupervisor([], lambda: 0.0)).compile(spec)


def export_file(file: Path, wrappers: bool = True) -> tuple[str, str | None]:
    """The XML for ``file``, and a note for the user (or None)."""
    document, spec = load_document(file)
    if spec is None:
        note = "a behaviour is written without wrappers: the compiler adds them where a mission calls it"
        return export_btcpp(document), note if wrappers else None
    return export_btcpp(document, compile_for_export(spec) if wrappers else None), None


def _loader_for(imported: ImportedXml, loader: MissionLoader) -> MissionLoader:
    """``loader``, with the file's subtrees over the library's behaviours of the same name."""
    mine = copy.copy(loader)
    mine.library = imported.library(loader.library)
    return mine


def _mission_source(imported: ImportedXml, file: Path):
    if imported.source is None:
        raise UserError(
            f"behaviour '{imported.document.behavior}', not a mission",
            where=display_path(Path(file)),
            hint="call it from a mission with <SubTree ID=…/>",
        )
    return imported.source


def _check_behavior(name: str, library: BehaviorLibrary, file: Path) -> None:
    """A behaviour's tree, checked as bt-validate checks one: expanded in a throw-away mission with its
    defaults, robot and world unchecked."""
    loader = MissionLoader(library=library, check_world=False)
    behavior = library.behaviors[name]
    loader.load_data({"mission": f"check {name}", "tree": {name: default_args(behavior)}}, str(file))
