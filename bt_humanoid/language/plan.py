"""What a planner answers to a command: a mission to run, a question to ask, a refusal, or stop.

Every planner (the embedded one, an LLM backend) returns a ``Plan``. A
mission is plain data in the mission language (the same schema as a YAML
file), so it is validated, compiled with safety and recovery, shown and run
like any other. A question carries what its answer decides, so the answer
continues the same command.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from bt_humanoid.perception.world_model import WorldModel
from bt_humanoid.sim.world_config import WorldConfig

PlanKind = Literal["mission", "question", "refusal", "stop"]


@dataclass
class Choice:
    """An open question: which of ``options`` (names to put in the command) the phrase meant."""

    command: str  # the command as given
    phrase: str  # the words that fit more than one thing
    options: list[str]  # what each option is called in a mission ("coffee mug")


@dataclass
class Plan:
    kind: PlanKind
    say: str  # what the robot says: what it will do, the question, or why not
    mission: dict[str, Any] | None = None
    choice: Choice | None = None  # for a question
    planning_time: float = 0.0  # s of wall time from text to this plan
    understood: bool = True  # False for a refusal of words the planner could not read as any request
    survey: bool = False  # it counts things or takes every one of a kind: worth a look at every surface first

    def involves_things(self) -> bool:
        """Whether the answer depends on what the robot sees: a mission that handles objects, a question, or a
        refusal of a request it understood ("I don't see a banana")."""
        if self.kind == "mission" and self.mission is not None:
            return bool(OBJECT_STEPS & _kinds(self.mission["tree"]))
        return self.kind == "question" or (self.kind == "refusal" and self.understood)


OBJECT_STEPS = {"take", "fetch", "throw_away", "find", "give", "hand_over", "place", "drop", "pick", "turn"}


def _kinds(node: Any) -> set[str]:
    """Every node kind in a mission tree."""
    if isinstance(node, list):
        return {k for child in node for k in _kinds(child)}
    if not isinstance(node, dict):
        return set()
    return set(node) | {k for value in node.values() for k in _kinds(value)}


def plan_outcome(plan: Plan) -> dict[str, Any]:
    """What a plan amounts to, as tests/data/commands.yaml writes it: plan steps, asks, refuses or stop."""
    if plan.kind == "mission" and plan.mission is not None:
        return {"plan": mission_signature(plan.mission["tree"])}
    if plan.kind == "question" and plan.choice is not None:
        return {"asks": plan.choice.options}
    if plan.kind == "refusal":
        return {"refuses": True}
    return {"stop": True}


@dataclass
class PlanningContext:
    """What a planner may read: the world's names and map, the robot's belief and where it stands."""

    world: WorldConfig
    belief: WorldModel
    robot_pose: np.ndarray  # x, y, yaw (rad)
    robot: str = "wheeled_humanoid"


def mission_signature(tree: dict[str, Any]) -> list[str]:
    """The steps of a mission as "skill target" lines, in order: what a planner test compares.

    take/fetch/find name their object (fetch also the surface), navigate its place (``person`` for a person,
    ``object`` for an object found earlier), move its signed distance, turn its signed angle, wave its count.
    """
    kind, params = next(iter(tree.items()))
    if kind in ("sequence", "fallback", "parallel"):
        children = params if isinstance(params, list) else params["children"]
        return [line for child in children for line in mission_signature(child)]
    params = params or {}
    if kind == "take":
        return [f"take {params['object']}"]
    if kind == "fetch":
        return [f"fetch {params['object']} {params['to']}"]
    if kind == "find":
        return [f"find {params['object']}"]
    if kind == "navigate":
        if params.get("person"):
            return ["navigate person"]
        return [f"navigate {params['place']}" if params.get("place") else "navigate object"]
    if kind == "place":
        return [f"place {params['surface']}"]
    if kind in ("give", "hand_over"):  # a hand-over is a give with somewhere to put it if not taken
        return [f"give {params.get('to', 'person') if params.get('to') in (None, 'person') else params['to']}"]
    if kind == "move_base" and params.get("relative"):
        if params.get("x") is not None:
            return [f"move {params['x']:g}"]
        return [f"turn {params['yaw']:g}"]
    if kind == "turn":
        return [f"face {params.get('place') or params.get('object')}"]
    if kind == "wave":
        return [f"wave {params.get('times', 2)}"]
    return [kind]
