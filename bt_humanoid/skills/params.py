"""Parameter helpers: blackboard references and readable validation errors."""

from __future__ import annotations

from typing import Any


def is_reference(value: Any) -> bool:
    """``"$key"`` reads the blackboard when the leaf starts (``"$$"`` escapes a literal dollar)."""
    return isinstance(value, str) and value.startswith("$") and not value.startswith("$$") and len(value) > 1


def resolve_references(value: Any, blackboard: Any) -> Any:
    if is_reference(value):
        return blackboard.get(value[1:])
    if isinstance(value, str) and value.startswith("$$"):
        return value[1:]
    if isinstance(value, dict):
        return {k: resolve_references(v, blackboard) for k, v in value.items()}
    if isinstance(value, list):
        return [resolve_references(v, blackboard) for v in value]
    return value
