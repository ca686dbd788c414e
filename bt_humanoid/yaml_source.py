"""YAML with positions: every value of a file keeps the line it came from."""

from __future__ import annotations

import copy
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import yaml
from pydantic import BaseModel, ValidationError

from bt_humanoid.errors import UserError, describe_validation_error, did_you_mean

YamlPath = tuple[str | int, ...]
M = TypeVar("M", bound=BaseModel)


def display_path(path: Path) -> str:
    """A path as a user would type it: relative to the working directory when inside it."""
    try:
        return os.path.relpath(path)
    except ValueError:
        return str(path)


def step_name(path: YamlPath) -> str:
    """A path of keys and indices as one would write it: ``tree.sequence[1].pick``."""
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else f"{'.' if text else ''}{part}"
    return text


@dataclass
class YamlSource:
    """Parsed YAML data plus the line of every value (by path of keys and indices)."""

    file: Path
    data: Any
    lines: dict[YamlPath, int] = field(default_factory=dict)

    def where(self, path: YamlPath) -> str:
        """'file:line' of the value at ``path``, or of its nearest ancestor; for data with no file (a planner's
        mission, named like ``<plan>``), the step: ``<plan> at tree.sequence[1].pick.object``."""
        if not self.lines and self.file.name.startswith("<"):
            return f"{self.file.name} at {step_name(path)}" if path else self.file.name
        probe = tuple(path)
        while probe and probe not in self.lines:
            probe = probe[:-1]
        line = self.lines.get(probe, 1)
        return f"{display_path(self.file)}:{line}"

    def invalid(self, error: ValidationError, base: YamlPath = (), prefix: str = "") -> UserError:
        """A pydantic error on the value at ``base``, phrased for people, at the file:line of its first problem."""
        location, message = describe_validation_error(error)
        return UserError(f"{prefix}{message}", where=self.where((*base, *location)))


_PARSED: dict[tuple[str, int, int], YamlSource] = {}  # files read before, by path, modification time and size
_PARSED_MAX = 256


def read_yaml(file: Path, text: str | None = None) -> YamlSource:
    """Parse one YAML document; syntax errors become UserErrors at file:line.

    A file read before and unchanged since is not parsed again (a planned mission reads the world's, the robot's
    and the behaviours' files each time): the caller gets its own copy of the data.
    """
    if text is None:
        try:
            stat = file.stat()
        except OSError:
            stat = None
        key = (str(file.resolve()), stat.st_mtime_ns, stat.st_size) if stat is not None else None
        if key is not None and key in _PARSED:
            parsed = _PARSED[key]
            return YamlSource(file, copy.deepcopy(parsed.data), parsed.lines)
        source = _read_file(file)
        if key is not None:
            if len(_PARSED) >= _PARSED_MAX:
                _PARSED.pop(next(iter(_PARSED)))
            _PARSED[key] = YamlSource(file, copy.deepcopy(source.data), source.lines)
        return source
    return _parse(file, text)


def _read_file(file: Path) -> YamlSource:
    try:
        text = file.read_text()
    except FileNotFoundError:
        raise UserError("file not found", where=display_path(file)) from None
    except OSError as error:
        raise UserError(f"cannot read: {error.strerror}", where=display_path(file)) from None
    except UnicodeDecodeError:
        raise UserError("not a text file (UTF-8 expected)", where=display_path(file)) from None
    return _parse(file, text)


def _parse(file: Path, text: str) -> YamlSource:
    try:
        loader = yaml.SafeLoader(text)  # checks the characters first: control characters are refused here
    except yaml.YAMLError as error:
        raise UserError(f"YAML error: {error}", where=display_path(file)) from None
    try:
        root = loader.get_single_node()
        source = YamlSource(file, None)
        source.data = _convert(loader, root, (), source) if root is not None else None
        return source
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark or error.context_mark
        line = mark.line + 1 if mark else 1
        problem = error.problem or error.context or "invalid YAML"
        raise UserError(f"YAML syntax error: {problem}", where=f"{display_path(file)}:{line}") from None
    except yaml.YAMLError as error:
        raise UserError(f"YAML error: {error}", where=display_path(file)) from None
    except RecursionError:
        raise UserError("nested too deeply to read", where=display_path(file)) from None
    finally:
        loader.dispose()


def read_model(file: Path, model: type[M], shape: str) -> tuple[M, YamlSource]:
    """A YAML mapping read into ``model``, with its source; ``shape`` says what the file should be when it is not
    a mapping. Every error is a UserError at file:line."""
    source = read_yaml(file)
    if not isinstance(source.data, dict):
        raise UserError(shape, where=source.where(()))
    try:
        return model.model_validate(source.data), source
    except ValidationError as error:
        raise source.invalid(error) from None


def read_config(
    kind: str,
    folder: Path,
    name: str,
    filename: str,
    model: type[BaseModel],
    inherit: Callable[[Any], dict] | None = None,
) -> BaseModel:
    """Read ``folder/name/filename`` (a robot.yaml or world.yaml) into ``model``, errors at file:line.

    With ``inherit``, the file may say ``extends: OTHER``: ``inherit(OTHER's config)`` gives the keys it
    starts from, and its own keys override them.
    """
    path = folder / name / filename
    if not path.is_file():
        valid = sorted(p.name for p in folder.iterdir() if (p / filename).is_file()) if folder.is_dir() else []
        raise UserError(f"unknown {kind} '{name}'", hint=did_you_mean(name, valid))
    source = read_yaml(path)
    data = dict(source.data or {}) if isinstance(source.data, dict) else source.data
    if inherit is not None and isinstance(data, dict) and "extends" in data:
        parent = data.pop("extends")
        if not isinstance(parent, str) or parent == name:
            raise UserError(f"extends: the name of another {kind}", where=source.where(("extends",)))
        data = {**inherit(read_config(kind, folder, parent, filename, model, inherit)), **data}
    try:
        return model.model_validate({**(data or {}), "folder": path.parent})
    except ValidationError as error:
        raise source.invalid(error) from None


def _convert(loader: yaml.SafeLoader, node: yaml.Node, path: YamlPath, source: YamlSource) -> Any:
    source.lines[path] = node.start_mark.line + 1
    if isinstance(node, yaml.MappingNode):
        result: dict[Any, Any] = {}
        for key_node, value_node in node.value:
            if not isinstance(key_node, yaml.ScalarNode):
                line = key_node.start_mark.line + 1
                raise UserError("mapping keys must be plain names", where=f"{display_path(source.file)}:{line}")
            # keys are names: keep them as written (YAML 1.1 would read `on:` or `yes:` as booleans)
            key = key_node.value
            if key in result:
                line = key_node.start_mark.line + 1
                raise UserError(f"duplicate key '{key}'", where=f"{display_path(source.file)}:{line}")
            result[key] = _convert(loader, value_node, (*path, key), source)
            # a key's own line wins over its value's (a block value starts on the next line)
            source.lines[(*path, key)] = key_node.start_mark.line + 1
        return result
    if isinstance(node, yaml.SequenceNode):
        return [_convert(loader, item, (*path, i), source) for i, item in enumerate(node.value)]
    return loader.construct_object(node, deep=True)
