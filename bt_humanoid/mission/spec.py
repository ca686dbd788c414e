"""The loaded, validated form of a mission: a header and a tree of NodeSpecs."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel

from bt_humanoid.mission.schema import MissionHeader, RecoverySettings
from bt_humanoid.sim.scene_config import SceneConfig
from bt_humanoid.skills.context import CheckContext

Category = Literal["composite", "decorator", "skill", "behavior"]


@dataclass
class NodeSpec:
    """One validated tree node.

    ``path`` names the node the way it is written (``tree.sequence[2].move_base``)
    and is how the event log and error messages refer to it; ``where`` is its
    file:line.
    """

    kind: str
    category: Category
    path: str
    where: str
    settings: BaseModel | None = None  # decorator/parallel settings, or skill params (refs left out)
    raw: dict[str, Any] = field(default_factory=dict)  # skill parameters as written ("$key" refs kept)
    children: list[NodeSpec] = field(default_factory=list)
    name: str | None = None
    recovery: RecoverySettings | None = None
    alternative: NodeSpec | None = None  # run instead when this node still fails (its recovery's alternative)

    def walk(self):
        yield self
        for child in self.children:
            yield from child.walk()
        if self.alternative is not None:
            yield from self.alternative.walk()


@dataclass
class MissionSpec:
    header: MissionHeader
    tree: NodeSpec
    #: the robot and world configs the mission was checked against
    known: CheckContext
    file: Path | None = None
    #: per-skill alternatives from the mission's recovery section, compiled afresh wherever the skill is used
    skill_alternatives: dict[str, NodeSpec] = field(default_factory=dict)
    #: the scene a fresh robot for it starts from (the command line's, the mission's, or the world's own; None:
    #: the world has none); missions run one after another on a robot start from wherever the last one left it
    scene: SceneConfig | None = None
