"""What a skill may use: the robot's controllers, its knowledge of the world, the clock, the blackboard."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from bt_humanoid.control.robot import RobotController
from bt_humanoid.language.questions import Questions
from bt_humanoid.navigation.navigator import Navigator
from bt_humanoid.perception.perceiver import Perceiver
from bt_humanoid.perception.world_model import WorldModel
from bt_humanoid.sim.robot_config import RobotConfig
from bt_humanoid.sim.world_config import WorldConfig


class Blackboard:
    """Mission variables shared by leaves: a plain dict, one per run (py_trees' is process-global)."""

    def __init__(self, initial: dict[str, Any] | None = None) -> None:
        self.values: dict[str, Any] = dict(initial or {})

    def get(self, key: str) -> Any:
        return self.values[key]

    def set(self, key: str, value: Any) -> None:
        self.values[key] = value

    def __contains__(self, key: str) -> bool:
        return key in self.values


@dataclass
class CheckContext:
    """What compile-time checks of skill parameters may consult.

    ``world`` is the robot's map knowledge (named places, surfaces): what a
    deployed robot would be told about its home, not the simulator's state.
    """

    robot_config: RobotConfig
    world: WorldConfig
    joint_ranges: dict[str, tuple[float, float]]


@dataclass
class SkillContext(CheckContext):
    """Handed to every skill at construction."""

    robot: RobotController = None  # type: ignore[assignment]
    clock: Callable[[], float] = lambda: 0.0
    blackboard: Blackboard = field(default_factory=Blackboard)
    speak: Callable[[str], None] = print
    world_model: WorldModel = field(default_factory=WorldModel)  # what the robot believes; skills read only this
    navigator: Navigator | None = None  # plans and follows routes for the base
    perceiver: Perceiver | None = None  # fills the world model from the head camera (robots that have one)
    questions: Questions | None = None  # someone to ask (interactive runs); None when no one can answer
