"""MissionSpec → py_trees tree, every composite and leaf wrapped as Safety(Recovery(node)).

The compiler owns safety: whatever produced the spec (a person, a behaviour
library, a planner), each node it emits sits under a SafetyGuard reading the
one SafetySupervisor and a RecoveryPolicy configured from the node, the
mission's ``recovery:`` section (per skill, then mission-wide) and the
robot's defaults, in that order.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import py_trees
from py_trees.behaviour import Behaviour
from py_trees.common import ParallelPolicy

from bt_humanoid.engine.composites import RoundRobin
from bt_humanoid.engine.decorators import RecoveryPolicy, SafetyGuard, SimTimeout
from bt_humanoid.mission.schema import RecoverySettings
from bt_humanoid.mission.spec import MissionSpec, NodeSpec
from bt_humanoid.safety.monitors import SafetySupervisor
from bt_humanoid.skills import REGISTRY
from bt_humanoid.skills.context import SkillContext

GUARD_NAME = "safety"
RECOVERY_NAME = "recovery"


@dataclass
class CompiledMission:
    root: Behaviour
    spec: MissionSpec
    supervisor: SafetySupervisor
    #: (node, path) of every node the mission describes, wrappers excluded
    nodes: list[tuple[Behaviour, str]] = field(default_factory=list)


def _label(node: NodeSpec) -> str:
    """What the live tree shows for a node."""
    if node.name:
        return node.name
    if node.category == "skill":
        shown = ", ".join(f"{k}={v}" for k, v in node.raw.items())
        return f"{node.kind}({shown})" if shown else node.kind
    if node.category == "behavior":
        return f"{node.kind} ▸"
    return node.kind


class Compiler:
    def __init__(
        self,
        context: SkillContext,
        supervisor: SafetySupervisor,
        on_retry: Callable[[RecoveryPolicy], None] | None = None,
    ) -> None:
        self.context = context
        self.supervisor = supervisor
        self.on_retry = on_retry

    def compile(self, spec: MissionSpec) -> CompiledMission:
        robot_defaults = self.context.robot_config.recovery
        section = spec.header.recovery
        self.default_recovery = RecoverySettings(
            retries=section.retries if section.retries is not None else robot_defaults.retries,
            backoff=section.backoff if section.backoff is not None else robot_defaults.backoff,
        )
        self.skill_recovery = section.skills
        self.nodes: list[tuple[Behaviour, str]] = []
        root = self._wrapped(spec.tree)
        return CompiledMission(root, spec, self.supervisor, self.nodes)

    def _recovery_for(self, node: NodeSpec) -> RecoverySettings:
        if node.recovery is not None:
            return node.recovery
        if node.category == "skill":
            if node.kind in self.skill_recovery:
                return self.skill_recovery[node.kind]
            if REGISTRY[node.kind].is_condition:
                return RecoverySettings(retries=0, backoff=0.0)  # a condition's answer is not a fault
            return self.default_recovery
        return RecoverySettings(retries=0, backoff=self.default_recovery.backoff)

    def _wrapped(self, node: NodeSpec) -> Behaviour:
        inner = self._build(node)
        inner.bt_path = node.path  # type: ignore[attr-defined]
        self.nodes.append((inner, node.path))
        policy = self._recovery_for(node)
        recovery = RecoveryPolicy(
            RECOVERY_NAME, inner, policy.retries, policy.backoff, self.context.clock, self.supervisor, self.on_retry
        )
        return SafetyGuard(GUARD_NAME, recovery, self.supervisor)

    def _build(self, node: NodeSpec) -> Behaviour:
        label = _label(node)
        children = [self._wrapped(child) for child in node.children]
        kind, settings = node.kind, node.settings
        if node.category == "skill":
            info = REGISTRY[kind]
            return info.behaviour(label, node.raw, self.context, node.path)
        if node.category == "behavior":
            return py_trees.composites.Sequence(label, memory=True, children=children)
        if kind in ("sequence", "reactive_sequence"):
            return py_trees.composites.Sequence(label, memory=kind == "sequence", children=children)
        if kind in ("fallback", "reactive_fallback"):
            return py_trees.composites.Selector(label, memory=kind == "fallback", children=children)
        if kind == "round_robin":
            return RoundRobin(label, children)
        if kind == "parallel":
            policy = ParallelPolicy.SuccessOnAll() if settings.policy == "all" else ParallelPolicy.SuccessOnOne()
            return py_trees.composites.Parallel(label, policy=policy, children=children)
        if kind == "guard":
            # the condition is re-ticked before the child every tick; a failing condition halts the child
            return py_trees.composites.Sequence(label, memory=False, children=children)
        (child,) = children
        if kind == "retry":
            return py_trees.decorators.Retry(label, child, num_failures=settings.attempts)
        if kind == "timeout":
            return SimTimeout(label, child, settings.seconds, self.context.clock)
        if kind == "repeat":
            return py_trees.decorators.Repeat(label, child, num_success=settings.times)
        if kind == "invert":
            return py_trees.decorators.Inverter(label, child)
        if kind == "force_success":
            return py_trees.decorators.FailureIsSuccess(label, child)
        if kind == "force_failure":
            return py_trees.decorators.SuccessIsFailure(label, child)
        raise AssertionError(f"no compiler rule for node kind '{kind}'")
