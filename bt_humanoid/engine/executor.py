"""Ticks a compiled tree on simulation time, stepping controllers and physics in between.

One cycle: the safety supervisor looks at the robot, the tree ticks once,
status changes go to the event log, then controllers and physics advance one
tick period. When the tree finishes (or is halted) every running leaf is
stopped, the robot brakes, and physics runs on until it is at rest.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from py_trees.behaviour import Behaviour
from py_trees.common import Status

from bt_humanoid.control.motion import REST_SPEED
from bt_humanoid.control.robot import RobotController
from bt_humanoid.engine.compiler import CompiledMission
from bt_humanoid.engine.events import EventLog
from bt_humanoid.sim.simulation import Simulation

BRAKE_TIMEOUT = 5.0  # s of simulation time allowed to come to rest after the tree ends


class Executor:
    def __init__(
        self,
        compiled: CompiledMission,
        sim: Simulation,
        robot: RobotController,
        events: EventLog,
        tick_hz: float = 20.0,
        control_hz: float = 100.0,
        observers: list[Callable[[], None]] | None = None,
    ) -> None:
        self.compiled = compiled
        self.root = compiled.root
        self.sim = sim
        self.robot = robot
        self.events = events
        self.tick_period = 1.0 / tick_hz
        steps_per_control = max(1, round(1.0 / (control_hz * sim.timestep)))
        self.steps_per_control = steps_per_control
        robot.set_control_period(steps_per_control * sim.timestep)
        self.controls_per_tick = max(1, round(self.tick_period / (steps_per_control * sim.timestep)))
        self.tick_count = 0
        #: called after every control period (recorder, pacing): the stack's list, shared by its missions
        self.observers: list[Callable[[], None]] = observers if observers is not None else []
        self.tick_listeners: list[Callable[[Executor], None]] = []  # called after every tick (live view)
        self._last_status: dict[int, Status] = {}
        self._running: list[Behaviour] = []
        self._violation_logged = False
        self.speed_at_end = 0.0  # the robot's fastest axis when the tree finished, before it was braked to rest

    @property
    def running(self) -> list[Behaviour]:
        """The mission's nodes running after the last tick."""
        return self._running

    # --- one cycle -------------------------------------------------------------

    def tick(self) -> Status:
        """Evaluate safety, tick the tree once and log what changed."""
        violation = self.compiled.supervisor.update()
        if violation is not None and not self._violation_logged:
            self._violation_logged = True
            self.events.add(violation.time, "safety", monitor=violation.monitor, message=violation.message)
        for fault in self.compiled.supervisor.faults:
            node = getattr(fault.leaf, "bt_path", None)
            self.events.add(fault.time, "monitor", monitor=fault.monitor, message=fault.message, node=node)
        visited = list(self.root.tick())
        self._record(visited)
        self.tick_count += 1
        for listener in self.tick_listeners:
            listener(self)
        return self.root.status

    def _record(self, visited: list[Behaviour]) -> None:
        # only ticked nodes and nodes that were running can have changed: cost follows the tick, not the tree
        now = self.sim.time
        candidates: dict[int, Behaviour] = {}
        for node in visited:
            if hasattr(node, "bt_path"):
                candidates.setdefault(id(node), node)
        for node in self._running:
            candidates.setdefault(id(node), node)
        running = []
        for key, node in candidates.items():
            old = self._last_status.get(key, Status.INVALID)
            if node.status is not old:
                self.events.status(now, node.bt_path, old.name, node.status.name, node.feedback_message)
                self._last_status[key] = node.status
            if node.status is Status.RUNNING:
                running.append(node)
        self._running = running

    def advance(self, duration: float | None = None) -> None:
        """Run controllers and physics for one tick period (or ``duration``)."""
        periods = self.controls_per_tick
        if duration is not None:
            periods = max(1, math.ceil(duration / (self.steps_per_control * self.sim.timestep)))
        for _ in range(periods):
            self.robot.step()
            self.sim.step(self.steps_per_control)
            for observer in self.observers:
                observer()

    # --- whole runs ------------------------------------------------------------------

    def run(self, max_time: float) -> Status:
        """Tick until the tree finishes or ``max_time`` of simulation time passes, then brake to rest."""
        self.events.add(self.sim.time, "start", mission=self.compiled.spec.header.mission)
        status = Status.RUNNING
        while True:
            status = self.tick()
            if status in (Status.SUCCESS, Status.FAILURE):
                break
            if self.sim.time >= max_time:
                self.events.add(self.sim.time, "timeout", message=f"no result after {max_time:.0f} s")
                status = Status.FAILURE
                break
            self.advance()
        self.speed_at_end = self.robot.max_speed()  # measured before halt() brakes and waits for rest
        self.halt()
        self.events.add(self.sim.time, "end", status=status.name, speed_at_finish=round(self.speed_at_end, 4))
        return status

    def halt(self) -> None:
        """Stop every running leaf (cancelling its motion), brake, and wait for rest."""
        if self.root.status is Status.RUNNING:
            self.root.stop(Status.INVALID)
            self._record([])
        self.robot.brake()
        deadline = self.sim.time + BRAKE_TIMEOUT
        while not self.robot.at_rest() and self.sim.time < deadline:
            self.advance(self.steps_per_control * self.sim.timestep)
        speed = self.robot.max_speed()
        self.events.add(self.sim.time, "rest" if speed < REST_SPEED else "moving", max_speed=round(speed, 4))
