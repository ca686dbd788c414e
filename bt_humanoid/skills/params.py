"""Parameter helpers: blackboard references and readable validation errors."""

from __future__ import annotations

import re
from collections.abc import Iterable
from typing import Any

from pydantic import BaseModel

from bt_humanoid.errors import did_you_mean
from bt_humanoid.perception.grounding import describes_an_object
from bt_humanoid.sim.world_config import WorldConfig

OBJECT_PARAMETER = "object"  # what every skill calls the parameter naming the object it acts on (check_object)


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


def check_name(value: str | None, valid: Iterable[str], parameter: str, what: str) -> list[tuple[str, str]]:
    """Compile-time check that ``value`` (if given) names one of ``valid``, as (parameter, message) pairs.

    Leaves with blackboard references are not checked at all (the loader skips them).
    """
    valid = list(valid)
    if value is None or value in valid:
        return []
    return [(parameter, f"unknown {what} '{value}' ({did_you_mean(value, valid)})")]


TRACKED_ID = re.compile(r"[a-z]+-\d+")  # perception's ids: "can-3", "fruit-2" (perception/world_model.py)


def check_object(value: str | None, world: WorldConfig, parameter: str = OBJECT_PARAMETER) -> list[tuple[str, str]]:
    """Compile-time check of an object parameter: a name the world gives (or one of a scene's: "coke 2" is a
    second coke), or a phrase to ground when it runs."""
    names = list(world.objects)
    if value is None or world.object_of(value) is not None or describes_an_object(value, [*names, *world.surfaces]):
        return []
    if TRACKED_ID.fullmatch(value):  # the robot's own id for a thing it saw: a plan names one of two alike by it
        return []
    example = 'or a description such as "the red cube" or "the cup on the counter"'
    return [(parameter, f"unknown object '{value}' ({did_you_mean(value, names)}), {example}")]


def named_objects(params: BaseModel, raw: dict[str, Any]) -> list[tuple[str, str]]:
    """The (parameter, name or phrase) a skill's parameters give for its object, if any, and not by reference."""
    value = getattr(params, OBJECT_PARAMETER, None)
    if not isinstance(value, str) or is_reference(raw.get(OBJECT_PARAMETER)):
        return []
    return [(OBJECT_PARAMETER, value)]


def check_in_map(at: tuple[float, float] | None, world: WorldConfig, parameter: str = "at") -> list[tuple[str, str]]:
    """Compile-time check that a spot ``[x, y]`` (if given) lies inside the world's map."""
    problem = world.outside_map(*at) if at is not None else None
    return [(parameter, problem)] if problem else []
