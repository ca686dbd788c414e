"""Port values: mission values ↔ BehaviorTree.CPP attribute strings, by the parameter's type.

BehaviorTree.CPP's conventions: ``{key}`` is a blackboard entry (the mission's ``$key``), a vector is
``a;b;c``, a structured value is ``json:…``. Numbers are written in one canonical form (``0`` for 0 and 0.0)
so that export → import → export gives the same bytes.
"""

from __future__ import annotations

import json
import re
import types
import typing
from typing import Any, Literal

#: a whole value naming a blackboard entry or a subtree port
BRACED = re.compile(r"\{([A-Za-z_][A-Za-z0-9_]*)\}")
PLACEHOLDER = re.compile(r"\$\{([A-Za-z_][A-Za-z0-9_]*)\}")


def _base(annotation: Any) -> Any:
    """The annotation without Optional."""
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        options = [a for a in typing.get_args(annotation) if a is not type(None)]
        if len(options) == 1:
            return options[0]
    return annotation


def type_name(annotation: Any) -> str:
    """The type Groot2 shows for a port, in BehaviorTree.CPP's C++ spelling."""
    base = _base(annotation)
    origin = typing.get_origin(base)
    if base is str or origin is Literal:
        return "std::string"
    if base is float:
        return "double"
    if base is int:
        return "int"
    if base is bool:
        return "bool"
    if origin is tuple or origin is list:
        return "std::vector<double>"
    if origin is dict:
        return "json"
    return "BT::Any"


def format_number(value: float | int) -> str:
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    return repr(value)


def encode(value: Any, annotation: Any, params: frozenset[str] = frozenset()) -> str:
    """A mission value as an attribute; ``params`` are the enclosing behaviour's parameters (``${p}`` → ``{p}``)."""
    if isinstance(value, str):
        return _encode_text(value, params, structured=type_name(annotation) in ("BT::Any",))
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float):
        return format_number(value)
    base = _base(annotation)
    if typing.get_origin(base) in (tuple, list) and isinstance(value, list | tuple):
        items = [encode(item, float, params) for item in value]
        if not any(";" in item for item in items):
            return ";".join(items)
    return "json:" + json.dumps(value, separators=(", ", ": "), ensure_ascii=False)


def _encode_text(text: str, params: frozenset[str], structured: bool) -> str:
    if PLACEHOLDER.fullmatch(text) or (text.startswith("$") and not text.startswith("$$") and len(text) > 1):
        name = text[2:-1] if PLACEHOLDER.fullmatch(text) else text[1:]
        return "{" + name + "}"
    if BRACED.search(PLACEHOLDER.sub("", text)):
        raise ValueError(f"the text {text!r} holds {{name}}, which BehaviorTree.CPP reads as a blackboard entry")
    text = PLACEHOLDER.sub(lambda m: "{" + m.group(1) + "}", text)
    if text.startswith("$$"):
        text = text[1:]  # the mission's escape for a literal dollar: in XML a $ means nothing
    if structured and _decode_any(text) != text:
        return "json:" + json.dumps(text, ensure_ascii=False)  # a text that would read back as a number
    return text


def decode(text: str, annotation: Any, params: frozenset[str] = frozenset()) -> Any:
    """An attribute as a mission value. What cannot be converted is left as text, for the loader to refuse
    with the parameter's name and the value."""
    whole = BRACED.fullmatch(text)
    if whole:
        name = whole.group(1)
        return "${" + name + "}" if name in params else "$" + name
    base = _base(annotation)
    origin = typing.get_origin(base)
    if text.startswith("json:"):
        try:
            return json.loads(text[5:])
        except ValueError:
            return text
    if base is str or origin is Literal:
        return _decode_text(text, params)
    if base is bool:
        return {"true": True, "false": False}.get(text.lower(), text)
    if base is int:
        return _number(text, int)
    if base is float:  # written 2: read 2, as YAML would (the live tree's labels show what was written)
        return _number(text, int) if text.lstrip("-").isdigit() else _number(text, float)
    if origin in (tuple, list):
        return [decode(item.strip(), float, params) for item in text.split(";")]
    return _decode_any(_decode_text(text, params))


def _decode_text(text: str, params: frozenset[str]) -> str:
    if text.startswith("$") and len(text) > 1:
        text = "$" + text  # a literal dollar, escaped as the mission language writes it
    return BRACED.sub(lambda m: "${" + m.group(1) + "}" if m.group(1) in params else m.group(0), text)


def _number(text: str, kind: type) -> Any:
    try:
        return kind(text)
    except ValueError:
        return text


def _decode_any(text: str) -> Any:
    """A value of no declared type: true/false, a number, or the text itself."""
    if text in ("true", "false"):
        return text == "true"
    for kind in (int, float):
        try:
            value = kind(text)
        except ValueError:
            continue
        if kind is float and not abs(value) < float("inf"):
            return text
        return value
    return text
