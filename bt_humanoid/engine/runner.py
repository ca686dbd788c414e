"""One mission on a robot stack: safety monitors, the compiled tree, its executor, and the verdict."""

from __future__ import annotations

import gc
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from py_trees.common import Status

from bt_humanoid.control.robot import RobotController
from bt_humanoid.engine.compiler import CompiledMission, Compiler
from bt_humanoid.engine.events import EventLog
from bt_humanoid.engine.executor import Executor
from bt_humanoid.engine.settings import resolve_safety
from bt_humanoid.engine.stack import RobotStack
from bt_humanoid.engine.verdict import ConditionResult, check_condition
from bt_humanoid.errors import UserError, did_you_mean
from bt_humanoid.mission.spec import MissionSpec
from bt_humanoid.navigation.navigator import Navigator
from bt_humanoid.perception.perceiver import Perceiver
from bt_humanoid.safety.monitors import (
    BumperMonitor,
    DroppedMonitor,
    FallMonitor,
    JointLimitMonitor,
    LostMonitor,
    SafetySupervisor,
    StopRequestMonitor,
    StrainMonitor,
    StuckMonitor,
    TimeBudgetMonitor,
    WorkspaceMonitor,
    trunk_bodies,
)
from bt_humanoid.sim.ground_truth import GroundTruth
from bt_humanoid.sim.simulation import Simulation
from bt_humanoid.skills.base import Skill
from bt_humanoid.skills.context import Blackboard, SkillContext

GC_THRESHOLD = 20_000  # allocations between the collector's young-generation passes while a mission runs


@dataclass
class RunResult:
    mission: str
    tree_status: str
    conditions: list[ConditionResult]
    sim_time: float
    wall_time: float
    events: EventLog
    said: list[str] = field(default_factory=list)
    safety: str | None = None
    cause: str | None = None  # the last skill that failed and why, when the tree failed
    speed_at_end: float = 0.0  # the robot's fastest joint or base axis when the tree finished, before braking

    @property
    def halted_by(self) -> list[str]:
        """``monitor: message`` for every branch fault reported: it halted the running leaf it concerned (whose
        recovery took over), unless that leaf handles such faults itself (grasp checks its own hold)."""
        return [f"{e['monitor']}: {e['message']}" for e in self.events.events if e["event"] == "monitor"]

    @property
    def success(self) -> bool:
        return self.tree_status == "SUCCESS" and all(c.holds for c in self.conditions)

    @property
    def real_time_factor(self) -> float:
        return self.sim_time / self.wall_time if self.wall_time > 0 else float("inf")

    def summary(self) -> dict[str, Any]:
        return {
            "mission": self.mission,
            "outcome": "success" if self.success else "failure",
            "tree_status": self.tree_status,
            "conditions": [{"condition": c.condition, "holds": c.holds, "detail": c.detail} for c in self.conditions],
            "safety": self.safety,
            "halted_by": self.halted_by,
            "cause": self.cause,
            "sim_time": round(self.sim_time, 3),
            "wall_time": round(self.wall_time, 3),
            "real_time_factor": round(self.real_time_factor, 2),
        }


class MissionRun:
    """One mission on a robot stack: safety monitors, the compiled tree and its executor; then ``execute()``.

    Missions follow one another on a stack (``MissionRun(stack, next_spec)``): the robot keeps its place, what it
    holds and what it believes. The mission's settings are resolved once, here (``self.limits``).
    """

    def __init__(self, stack: RobotStack, spec: MissionSpec, tick_hz: float = 20.0, control_hz: float = 100.0) -> None:
        header = spec.header
        if (header.world, header.robot) != (stack.world.name, stack.robot_config.name):
            raise UserError(
                f"mission '{header.mission}' is for {header.world}/{header.robot}; "
                f"this robot is {stack.robot_config.name} in {stack.world.name}"
            )
        absent = [name for name in _objects_judged(spec) if name not in stack.sim.object_bodies]
        if absent:  # judged in ground truth at the end: a name the run lacks cannot be judged
            scene = stack.sim.scene
            raise UserError(
                f"success: no '{absent[0]}' in this run"
                + (f" (scene '{scene.name}')" if scene is not None else f" (world '{stack.world.name}')"),
                where=spec.file.name if spec.file is not None else None,
                hint=did_you_mean(absent[0], stack.sim.object_bodies),
            )
        self.stack, self.spec = stack, spec
        robot_config = stack.robot_config
        self.limits = resolve_safety(header.safety, robot_config.safety)
        self.time_budget = self.limits.time_budget.value
        defaults = robot_config.safety
        self.stop_monitor = StopRequestMonitor()
        sim, robot = stack.sim, stack.robot
        io = robot.body_io
        limbs = [io.actuator(j) for j in io.joints if j not in robot_config.finger_joints]
        monitors = [
            self.stop_monitor,
            BumperMonitor(sim.model, sim.data, _trunk(sim), sim.robot_bodies),  # a cause first
            JointLimitMonitor(robot, self.limits.joint_limit_margin.value, defaults.joint_speed_factor),
            TimeBudgetMonitor(self.time_budget, sim.time),
            WorkspaceMonitor(robot, np.array(stack.world.bounds), defaults.min_hand_height),
        ]
        if robot.localisation is not None:  # a robot that lost its place on the map stops
            monitors.append(LostMonitor(robot.localisation))
        if robot.walking is not None and robot_config.legs is not None:  # a biped can fall
            legs = robot_config.legs
            feet = {sim.model.body(leg.foot).id for leg in (legs.left, legs.right)}
            walker = robot.walking.walker
            monitors.insert(1, FallMonitor(lambda: walker.fallen, sim.model, sim.data, sim.robot_bodies, feet))
        branch_monitors = [
            DroppedMonitor(robot.grippers, lambda: stack.context.world_model),
            StrainMonitor(sim.model, sim.data, limbs, defaults.strain_time),  # not wheels, not fingers
            StuckMonitor(robot, lambda: self.executor.running, defaults.stuck_after),
        ]
        self.supervisor = SafetySupervisor(monitors, lambda: sim.time, branch_monitors)

        def log_recovery(path: str, action: str, message: str) -> None:
            # "retry", "replan", "ask" or "answer", with the node concerned and what the recovery does about it
            stack.events.add(sim.time, action, node=path, message=message)

        self.compiled: CompiledMission = Compiler(stack.context, self.supervisor, log_recovery).compile(spec)
        self.executor = Executor(self.compiled, sim, robot, stack.events, tick_hz, control_hz, stack.observers)

    # the stack's parts, for callers that hold a run
    @property
    def sim(self) -> Simulation:
        return self.stack.sim

    @property
    def robot(self) -> RobotController:
        return self.stack.robot

    @property
    def navigator(self) -> Navigator:
        return self.stack.navigator

    @property
    def perceiver(self) -> Perceiver | None:
        return self.stack.perceiver

    @property
    def context(self) -> SkillContext:
        return self.stack.context

    @property
    def truth(self) -> GroundTruth:
        return self.stack.truth

    @property
    def events(self) -> EventLog:
        return self.stack.events

    @property
    def said(self) -> list[str]:
        return self.stack.said

    def request_stop(self, reason: str = "stop requested") -> None:
        """Stop now: every motion starts braking at once; the tree is halted at its next tick."""
        first = self.stop_monitor.reason is None
        self.stop_monitor.request(reason)
        if first:
            self.robot.brake()

    def execute(self) -> RunResult:
        """Run the mission to its end and the robot to rest; the stack stays open for the next mission.

        The result holds this mission's events and words only, not those of missions run before on the stack.
        """
        started = time.perf_counter()
        stack = self.stack
        stack.context.blackboard = Blackboard(self.spec.header.blackboard)  # this mission's, from its start
        stack.robot.base.speed_cap = self.limits.max_base_speed.value
        first_event, first_said = len(stack.events.events), len(stack.said)
        # what the stack built lives as long as the run: the cyclic collector need not walk it, and the control
        # loop's short-lived arrays hold no cycles worth a pass every 700 of them (2 % of an episode's time)
        thresholds = gc.get_threshold()
        gc.freeze()
        gc.set_threshold(GC_THRESHOLD, *thresholds[1:])
        try:
            status = self.executor.run(max_time=self.sim.time + self.time_budget + 1.0)
        finally:
            gc.set_threshold(*thresholds)
            gc.unfreeze()
        if self.stop_monitor.reason is not None:
            stack.say("I have stopped.")  # at rest now: executor.run brakes to rest before it returns
        wall = time.perf_counter() - started
        events = EventLog()
        events.events = stack.events.events[first_event:]
        conditions = [check_condition(c, self.truth) for c in self.spec.header.success]
        violation = self.supervisor.violation
        tree_status = status.name if status is not Status.INVALID else "FAILURE"
        return RunResult(
            mission=self.spec.header.mission,
            tree_status=tree_status,
            conditions=conditions,
            sim_time=self.sim.time,
            wall_time=wall,
            events=events,
            said=stack.said[first_said:],
            safety=f"{violation.monitor}: {violation.message}" if violation else None,
            cause=self._failure_cause(events) if tree_status == "FAILURE" else None,
            speed_at_end=self.executor.speed_at_end,
        )

    def _failure_cause(self, events: EventLog) -> str | None:
        """``path: reason`` of the last skill that failed (a decorator's own message says less)."""
        skills = {path for node, path in self.compiled.nodes if isinstance(node, Skill)}
        for event in reversed(events.events):
            if event["event"] == "status" and event["new"] == "FAILURE" and event["node"] in skills:
                return f"{event['node']}: {event.get('feedback') or 'failed'}"
        return None


def _objects_judged(spec: MissionSpec) -> list[str]:
    """The objects the mission's success conditions name (the first of a pair: an object on a surface)."""
    names = []
    for condition in spec.header.success:
        for kind, value in condition.model_dump().items():
            if kind in ("on", "inside"):
                names.append(value[0])
            elif kind in ("in_hand", "upright", "delivered"):
                names.append(value)
            elif kind == "near":
                names.append(value["object"])
    return names


def _trunk(sim: Simulation) -> set[int]:
    """The robot's bodies that are not on an arm: what the bumper monitor watches."""
    model = sim.model
    hands = [int(model.jnt_bodyid[model.joint(j).id]) for j in sim.robot.finger_joints]
    return trunk_bodies(model, sim.robot_bodies, hands) if hands else set()


def stack_for(spec: MissionSpec, seed: int | None = None, speak: Callable[[str], None] | None = None) -> RobotStack:
    """A fresh stack of the robot and world ``spec`` was checked against, in its scene (the command line's, the
    mission's or the world's), seeded by ``seed`` or the mission's."""
    known = spec.known
    return RobotStack(known.world, known.robot_config, spec.header.seed if seed is None else seed, speak, spec.scene)


def run_mission_file(path: Path, seed: int | None = None, scene: str | None = None) -> RunResult:
    """Load, compile and run a mission headless on a fresh stack (in ``scene``, by name or path, over the
    mission's); the convenience entry for scripts and tests."""
    from bt_humanoid.mission.loader import MissionLoader

    spec = MissionLoader(scene=scene).load_file(path)
    stack = stack_for(spec, seed)
    try:
        return MissionRun(stack, spec).execute()
    finally:
        stack.close()
