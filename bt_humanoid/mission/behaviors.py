"""The library of reusable subtrees: behaviors/*.yaml, called by name with arguments.

A behaviour file declares its parameters and a tree; ``${param}`` in the tree
is replaced by the argument when the behaviour is expanded (a whole-value
``${param}`` keeps the argument's type).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, Field, create_model

from bt_humanoid.errors import UserError
from bt_humanoid.paths import behaviors_dir
from bt_humanoid.strict_model import StrictModel
from bt_humanoid.yaml_source import YamlSource, read_model

_TYPES: dict[str, Any] = {"string": str, "number": float, "integer": int, "boolean": bool, "any": Any}
PLACEHOLDER = re.compile(r"\$\{([A-Za-z_][A-Za-z0-9_]*)\}")


class BehaviorParam(StrictModel):
    type: Literal["string", "number", "integer", "boolean", "any"] = "string"
    default: Any = None
    required: bool = False
    description: str = ""


class BehaviorHeader(StrictModel):
    behavior: str = Field(pattern=r"^[a-z][a-z0-9_]*$")
    description: str = ""
    params: dict[str, BehaviorParam] = Field(default_factory=dict)
    example: dict[str, Any] = Field(default_factory=dict)  # arguments of a typical call; used to check the tree
    tree: Any


@dataclass
class Behavior:
    name: str
    description: str
    source: YamlSource
    args_model: type[BaseModel]
    example: dict[str, Any] = field(default_factory=dict)


def _args_model(name: str, header: BehaviorHeader) -> type[BaseModel]:
    fields: dict[str, Any] = {}
    for param, spec in header.params.items():
        kind = _TYPES[spec.type]
        if spec.required:
            fields[param] = (kind, Field(description=spec.description))
        else:
            optional = kind if spec.default is not None or kind is Any else kind | None
            fields[param] = (optional, Field(spec.default, description=spec.description))
    return create_model(f"{name}_args", __base__=StrictModel, __doc__=header.description, **fields)


def load_behavior(file: Path) -> Behavior:
    """Read and check one behaviour file (its header; the tree is checked when expanded)."""
    header, source = read_model(file, BehaviorHeader, "a behaviour file is a mapping with behavior, params and tree")
    return Behavior(header.behavior, header.description, source, _args_model(header.behavior, header), header.example)


class BehaviorLibrary:
    """Behaviours found in behaviors/ (and any extra folders), by name."""

    def __init__(self, folders: list[Path] | None = None) -> None:
        self.folders = folders if folders is not None else [behaviors_dir()]
        self._behaviors: dict[str, Behavior] | None = None

    @property
    def behaviors(self) -> dict[str, Behavior]:
        if self._behaviors is None:
            found: dict[str, Behavior] = {}
            for folder in self.folders:
                for file in sorted(folder.glob("*.yaml")):
                    behavior = load_behavior(file)
                    if behavior.name in found:
                        raise UserError(
                            f"behaviour '{behavior.name}' is defined twice", where=behavior.source.where(("behavior",))
                        )
                    found[behavior.name] = behavior
            self._behaviors = found
        return self._behaviors

    def args_models(self) -> dict[str, type[BaseModel]]:
        return {name: b.args_model for name, b in self.behaviors.items()}


def default_args(behavior: Behavior) -> dict[str, Any]:
    """Arguments for checking a behaviour's tree on its own: its example, and a sample for any other required one."""
    samples = {str: "x", float: 0.0, int: 0, bool: False}
    args = {}
    for name, spec in behavior.args_model.model_fields.items():
        if spec.is_required():
            args[name] = samples.get(spec.annotation, "x")
    return {**args, **behavior.example}


def substitute(value: Any, args: dict[str, Any], source: YamlSource, path: tuple) -> Any:
    """Replace ``${param}`` in a behaviour's tree with the call's arguments."""
    if isinstance(value, dict):
        return {k: substitute(v, args, source, (*path, k)) for k, v in value.items()}
    if isinstance(value, list):
        return [substitute(v, args, source, (*path, i)) for i, v in enumerate(value)]
    if not isinstance(value, str) or "${" not in value:
        return value
    for name in PLACEHOLDER.findall(value):
        if name not in args:
            valid = ", ".join(sorted(args)) or "none"
            raise UserError(
                f"unknown behaviour parameter '${{{name}}}' (parameters: {valid})", where=source.where(path)
            )
    whole = PLACEHOLDER.fullmatch(value)
    if whole:
        return args[whole.group(1)]
    return PLACEHOLDER.sub(lambda m: str(args[m.group(1)]), value)
