"""bt-export's work: a mission or behaviour file → checked → BehaviorTree.CPP v4 XML."""

from __future__ import annotations

from pathlib import Path

from bt_humanoid.engine.compiler import CompiledMission, Compiler
from bt_humanoid.interop.btcpp_document import Document, document_from_yaml
from bt_humanoid.interop.btcpp_export import export_btcpp
from bt_humanoid.interop.btcpp_import import read_btcpp
from bt_humanoid.mission.behaviors import BehaviorLibrary
from bt_humanoid.mission.loader import MissionLoader
from bt_humanoid.mission.spec import MissionSpec
from bt_humanoid.safety.monitors import SafetySupervisor
from bt_humanoid.skills.context import SkillContext

SCHEMA = Path(__file__).with_name("btcpp_schema.xsd")


def load_document(file: Path) -> tuple[Document, MissionSpec | None]:
    """The file as a Document, checked as bt-validate checks it; with the mission's spec (None: a behaviour)."""
    from bt_humanoid.cli import validate_file

    file = Path(file)
    validate_file(file)  # every error at file:line, before anything is written
    library = BehaviorLibrary()
    if file.suffix.lower() == ".xml":
        document = read_btcpp(file, library=library).document
    else:
        document = document_from_yaml(file, library)
    spec = MissionLoader().load_file(file) if document.behavior is None else None
    return document, spec


def compile_for_export(spec: MissionSpec) -> CompiledMission:
    """The tree the mission runs as (a supervisor with no monitors: nothing runs)."""
    known = spec.known
    context = SkillContext(known.robot_config, known.world, known.joint_ranges)
    return Compiler(context, SafetySupervisor([], lambda: 0.0)).compile(spec)


def export_file(file: Path, wrappers: bool = True) -> tuple[str, str | None]:
    """The XML for ``file``, and a note for the user (or None)."""
    document, spec = load_document(file)
    if spec is None:
        note = (
            None
            if not wrappers
            else "a behaviour is written without wrappers: the compiler adds them where a mission calls it"
        )
        return export_btcpp(document), note
    return export_btcpp(document, compile_for_export(spec) if wrappers else None), None
