"""One mission run, assembled: simulation, robot, skills, safety, compiled tree, executor, verdict."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from py_trees.common import Status

from bt_humanoid.control.robot import RobotController
from bt_humanoid.engine.compiler import CompiledMission, Compiler
from bt_humanoid.engine.decorators import RecoveryPolicy
from bt_humanoid.engine.events import EventLog
from bt_humanoid.engine.executor import Executor
from bt_humanoid.engine.verdict import ConditionResult, check_condition
from bt_humanoid.errors import UserError
from bt_humanoid.mission.spec import MissionSpec
from bt_humanoid.navigation.navigator import Navigator
from bt_humanoid.perception.map_knowledge import map_world_model
from bt_humanoid.perception.perceiver import Perceiver
from bt_humanoid.perception.safety_scanner import SafetyScanner
from bt_humanoid.safety.monitors import (
    BumperMonitor,
    DroppedMonitor,
    JointLimitMonitor,
    SafetySupervisor,
    StopRequestMonitor,
    StrainMonitor,
    StuckMonitor,
    TimeBudgetMonitor,
    WorkspaceMonitor,
    trunk_bodies,
)
from bt_humanoid.safety.separation import SpeedAndSeparation
from bt_humanoid.sim.ground_truth import GroundTruth
from bt_humanoid.sim.simulation import Simulation
from bt_humanoid.skills.base import Skill
from bt_humanoid.skills.context import Blackboard, SkillContext


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


@dataclass
class MissionRun:
    """Everything one run is made of; build it, optionally attach viewers, then ``execute()``."""

    spec: MissionSpec
    seed: int | None = None
    tick_hz: float = 20.0
    control_hz: float = 100.0
    speak: Callable[[str], None] | None = None

    def __post_init__(self) -> None:
        header = self.spec.header
        known = self.spec.known
        robot_config, world = known.robot_config, known.world
        self.sim = Simulation(world, robot_config)
        self.sim.reset(self.seed if self.seed is not None else header.seed)
        self.robot = RobotController(self.sim)
        self.navigator = Navigator(self.sim, self.robot, np.array(world.bounds))
        self.robot.planners.append(self.navigator)
        self.truth = GroundTruth(self.sim)
        self.said: list[str] = []

        def say(text: str) -> None:
            self.said.append(text)
            self.events.add(self.sim.time, "say", text=text)
            if self.speak is not None:
                self.speak(text)

        self.events = EventLog()
        self.context = SkillContext(
            robot_config=robot_config,
            world=world,
            joint_ranges=known.joint_ranges,
            robot=self.robot,
            clock=lambda: self.sim.time,
            max_base_speed=0.0,  # per mission: set by _prepare
            blackboard=Blackboard({}),  # per mission: set by _prepare
            speak=say,
            world_model=map_world_model(world, self.sim.model),  # its map, and no objects until the camera sees them
            navigator=self.navigator,
        )
        self.perceiver: Perceiver | None = None
        if robot_config.cameras:  # objects are known only once the head camera has seen them
            camera = next(iter(robot_config.cameras))
            self.perceiver = Perceiver(self.sim, lambda: self.context.world_model, camera, "base")
            self.robot.planners.append(self.perceiver)
            self.context.perceiver = self.perceiver
        self.separation = self._separation()
        self._prepare(self.spec)

    def _prepare(self, spec: MissionSpec) -> None:
        """Safety monitors, the compiled tree and its executor for ``spec``, on this run's simulation and robot."""
        self.spec = spec
        header, defaults = spec.header, spec.known.robot_config.safety
        safety = header.safety
        self.context.blackboard = Blackboard(header.blackboard)
        self.context.max_base_speed = min(safety.max_base_speed or defaults.max_base_speed, defaults.max_base_speed)
        self.stop_monitor = StopRequestMonitor()
        self.time_budget = safety.time_budget or defaults.time_budget
        margin = safety.joint_limit_margin if safety.joint_limit_margin is not None else defaults.joint_limit_margin
        io = self.robot.body_io
        limbs = [io.actuator(j) for j in io.joints if j not in spec.known.robot_config.finger_joints]
        monitors = [
            self.stop_monitor,
            BumperMonitor(self.sim.model, self.sim.data, self._trunk(), self.sim.robot_bodies),  # a cause first
            JointLimitMonitor(self.robot, margin, defaults.joint_speed_factor),
            TimeBudgetMonitor(self.time_budget, self.sim.time),
            WorkspaceMonitor(self.robot, np.array(spec.known.world.bounds), defaults.min_hand_height),
        ]
        branch_monitors = [
            DroppedMonitor(self.robot.grippers, lambda: self.context.world_model),
            StrainMonitor(self.sim.model, self.sim.data, limbs, defaults.strain_time),  # not wheels, not fingers
            StuckMonitor(self.robot, lambda: self.executor.running, defaults.stuck_after),
        ]
        self.supervisor = SafetySupervisor(monitors, lambda: self.sim.time, branch_monitors)

        def log_recovery(policy: RecoveryPolicy, action: str) -> None:
            # "retry", "replan", "ask" or "answer", with the node that failed and what the policy does about it
            self.events.add(self.sim.time, action, node=policy.decorated.bt_path, message=policy.feedback_message)

        self.compiled: CompiledMission = Compiler(self.context, self.supervisor, log_recovery).compile(spec)
        observers = self.executor.observers if hasattr(self, "executor") else []
        self.executor = Executor(self.compiled, self.sim, self.robot, self.events, self.tick_hz, self.control_hz)
        self.executor.observers.extend(observers)

    def _separation(self) -> SpeedAndSeparation | None:
        """Speed and separation monitoring from the base scanner, when the robot has one."""
        config = self.context.robot_config
        if config.scanner is None:
            return None
        model = self.sim.model
        base_body = int(model.jnt_bodyid[model.joint(config.base.joints["yaw"]).id])
        whole_body = self.robot.whole_body

        def hands() -> list[np.ndarray]:
            return [whole_body.frame_pose(whole_body.hand_frame(side)).translation for side in config.grippers]

        def zone(name: str, distance: float) -> None:
            self.events.add(self.sim.time, "separation", zone=name, distance=round(distance, 3))

        separation = SpeedAndSeparation(
            SafetyScanner(model, self.sim.data, base_body, config.scanner),
            config.safety,
            config.base.footprint_radius,
            config.base.limits.max_speed,
            furniture=self.navigator.is_furniture,
            people=lambda: list(self.context.world_model.people.values()),
            hands=hands,
            on_zone=zone,
        )
        self.robot.monitor_separation(separation)
        return separation

    def _trunk(self) -> set[int]:
        """The robot's bodies that are not on an arm: what the bumper monitor watches."""
        model = self.sim.model
        hands = [int(model.jnt_bodyid[model.joint(j).id]) for j in self.sim.robot.finger_joints]
        return trunk_bodies(model, self.sim.robot_bodies, hands) if hands else set()

    def follow_with(self, spec: MissionSpec) -> None:
        """Make ``spec`` the next mission, from where the last one left the robot and the world (and the belief)."""
        same = (spec.header.world, spec.header.robot) == (self.spec.header.world, self.spec.header.robot)
        if not same:
            raise UserError(
                f"mission '{spec.header.mission}' is for {spec.header.world}/{spec.header.robot}; "
                f"this run is {self.spec.header.world}/{self.spec.header.robot}"
            )
        self._prepare(spec)

    def request_stop(self, reason: str = "stop requested") -> None:
        """Stop now: every motion starts braking at once; the tree is halted at its next tick."""
        first = self.stop_monitor.reason is None
        self.stop_monitor.request(reason)
        if first:
            self.robot.brake()

    def execute(self, keep_open: bool = False) -> RunResult:
        """Run the mission to its end and the robot to rest; ``keep_open`` for another mission after it."""
        started = time.perf_counter()
        try:
            status = self.executor.run(max_time=self.sim.time + self.time_budget + 1.0)
        finally:
            if self.perceiver is not None and not keep_open:
                self.perceiver.close()  # its off-screen GL contexts: one per run adds up over a benchmark
        if self.stop_monitor.reason is not None:
            self.context.speak("I have stopped.")  # at rest now: executor.run brakes to rest before it returns
        wall = time.perf_counter() - started
        conditions = [check_condition(c, self.truth) for c in self.spec.header.success]
        violation = self.supervisor.violation
        tree_status = status.name if status is not Status.INVALID else "FAILURE"
        return RunResult(
            mission=self.spec.header.mission,
            tree_status=tree_status,
            conditions=conditions,
            sim_time=self.sim.time,
            wall_time=wall,
            events=self.events,
            said=self.said,
            safety=f"{violation.monitor}: {violation.message}" if violation else None,
            cause=self._failure_cause() if tree_status == "FAILURE" else None,
        )

    def _failure_cause(self) -> str | None:
        """``path: reason`` of the last skill that failed (a decorator's own message says less)."""
        skills = {path for node, path in self.compiled.nodes if isinstance(node, Skill)}
        for event in reversed(self.events.events):
            if event["event"] == "status" and event["new"] == "FAILURE" and event["node"] in skills:
                return f"{event['node']}: {event.get('feedback') or 'failed'}"
        return None


def run_mission_file(path: Path, seed: int | None = None) -> RunResult:
    """Load, compile and run a mission headless; the convenience entry for scripts and tests."""
    from bt_humanoid.mission.loader import MissionLoader

    return MissionRun(MissionLoader().load_file(path), seed=seed).execute()
