"""Run a mission headless for a test and keep everything needed to judge it."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from bt_humanoid.engine.runner import MissionRun, RunResult
from bt_humanoid.engine.stack import RobotStack
from bt_humanoid.interop.btcpp import load_mission as load_file
from bt_humanoid.mission.loader import MissionLoader
from bt_humanoid.mission.spec import MissionSpec
from bt_humanoid.sim.ground_truth import GroundTruth


@dataclass
class Scenario:
    """A finished run: its result, the run itself and the simulator's ground truth."""

    run: MissionRun
    result: RunResult

    @property
    def truth(self) -> GroundTruth:
        return self.run.truth

    @property
    def events(self) -> list[dict[str, Any]]:
        return self.result.events.events

    def statuses(self, node: str) -> list[str]:
        """The statuses one node went through, in order."""
        return [e["new"] for e in self.events if e["event"] == "status" and e["node"] == node]

    def feedback(self, node: str) -> list[str]:
        """The feedback messages one node reported with its status changes, in order."""
        return [e.get("feedback", "") for e in self.events if e["event"] == "status" and e["node"] == node]

    def final_speed(self) -> float:
        """The robot's fastest axis when the tree finished, before the executor braked it and waited for rest."""
        return self.result.speed_at_end


def load_mission(mission: str | Path | dict) -> MissionSpec:
    """A validated mission from a file path, YAML text or a mission mapping."""
    loader = MissionLoader()
    if isinstance(mission, dict):
        return loader.load_data(mission)
    if isinstance(mission, Path) or (
        isinstance(mission, str) and mission.endswith((".yaml", ".xml")) and "\n" not in mission
    ):
        return load_file(Path(mission), loader)  # a mission file: YAML, or BehaviorTree.CPP XML
    return loader.load_text(mission)


def build_run(
    mission: str | Path | dict, seed: int | None = None, robot_start: tuple[float, float, float] | None = None
) -> MissionRun:
    """A MissionRun on a fresh RobotStack from a file path, YAML text or a mission mapping (not yet executed).

    ``robot_start`` [x, y, yaw_deg] replaces the world's start pose (test and benchmark set-up).
    """
    spec = load_mission(mission)
    header = spec.header
    seed = header.seed if seed is None else seed
    stack = RobotStack.load(header.world, header.robot, seed, robot_start, scene=spec.scene)
    return MissionRun(stack, spec)


def run_scenario(mission: str | Path | dict, seed: int | None = None) -> Scenario:
    run = build_run(mission, seed)
    try:
        return Scenario(run, run.execute())
    finally:
        run.stack.close()
