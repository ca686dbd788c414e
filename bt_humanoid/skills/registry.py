"""The one registry of leaf skills: name → parameter model, behaviour class, description.

The mission schema, the docs, the reference and the LLM prompt's catalogue are
generated from it. What a person can say or type is ``language/vocabulary.py``
(one table of verbs for the planner's phrasings and the speech grammar); each
kind of step there plans registered skills or behaviours, which a test checks.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

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
    #: this skill's own recovery defaults (retries, backoff, replan, ask); the mission's settings win
    recovery: Mapping[str, Any] = field(default_factory=dict)


REGISTRY: dict[str, SkillInfo] = {}


def skill(
    name: str, description: str, *, condition: bool = False, recovery: Mapping[str, Any] | None = None
) -> Callable[[type[Skill]], type[Skill]]:
    """Class decorator: register a Skill subclass (its ``Params`` model is the parameter schema).

    A condition's failure is an answer, not a fault: it is never retried unless a mission says so.
    """
    if condition:
        recovery = {"retries": 0, "replan": 0, "ask": False, **(recovery or {})}

    def register(cls: type[Skill]) -> type[Skill]:
        if name in REGISTRY:
            raise ValueError(f"skill '{name}' registered twice")
        REGISTRY[name] = SkillInfo(name, cls.Params, cls, description, condition, dict(recovery or {}))
        cls.skill_name = name
        return cls

    return register
