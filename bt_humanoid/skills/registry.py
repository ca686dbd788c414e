"""The one registry of leaf skills: name → parameter model, behaviour class, description.

The mission schema, the docs, the README reference (and later the ASR grammar
and the LLM prompt) are all generated from it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from pydantic import BaseModel

if TYPE_CHECKING:
    from bt_humanoid.skills.base import Skill


@dataclass(frozen=True)
class SkillInfo:
    name: str
    params: type[BaseModel]
    behaviour: type[Skill]
    description: str
    is_condition: bool = False


REGISTRY: dict[str, SkillInfo] = {}


def skill(name: str, description: str, *, condition: bool = False) -> Callable[[type[Skill]], type[Skill]]:
    """Class decorator: register a Skill subclass (its ``Params`` model is the parameter schema)."""

    def register(cls: type[Skill]) -> type[Skill]:
        if name in REGISTRY:
            raise ValueError(f"skill '{name}' registered twice")
        REGISTRY[name] = SkillInfo(name, cls.Params, cls, description, condition)
        cls.skill_name = name
        return cls

    return register
