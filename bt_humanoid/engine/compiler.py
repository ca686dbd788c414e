"""MissionSpec → py_trees tree, every composite and leaf wrapped as Safety(Recovery(node)).

The compiler owns safety: whatever produced the spec (a person, a behaviour
library, a planner), each node it emits sits under a SafetyGuard reading the
one SafetySupervisor and a RecoveryPolicy configured from the node, the
mission's ``recovery:`` section (per skill, then mission-wide) and the
robot's defaults, in that order.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields, replace
from typing import Any

import py_trees
from py_trees.behaviour import Behaviour
from py_trees.common import ParallelPolicy

from bt_humanoid.engine.composites import RoundRobin
from bt_humanoid.engine.decorators import RecoveryPolicy, RecoverySteps, SafetyGuard, SimTimeout
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


def resolve_recovery(*layers: Mapping[str, Any]) -> RecoverySteps:
    """Each field from the first layer that sets it (layers: most specific first); unset fields keep defaults."""
    found = {}
    for name in (f.name for f in fields(RecoverySteps)):
        value = next((layer[name] for layer in layers if layer.get(name) is not None), None)
        if value is not None:
            found[name] = value
    return RecoverySteps(**found)


class Compiler:
    def __init__(
        self,
        context: SkillContext,
        supervisor: SafetySupervisor,
        on_recovery: Callable[[RecoveryPolicy, str], None] | None = None,
    ) -> None:
        self.context = context
        self.supervisor = supervisor
        self.on_recovery = on_recovery

    def compile(self, spec: MissionSpec) -> CompiledMission:
        section = spec.header.recovery
        self.robot_recovery = self.context.robot_config.recovery.model_dump()
        self.mission_recovery = section.model_dump(exclude={"skills"})
        self.skill_recovery = {name: s.model_dump(exclude={"alternative"}) for name, s in section.skills.items()}
        self.skill_alternatives = spec.skill_alternatives
        self.nodes: list[tuple[Behaviour, str]] = []
        self.awaiting_target: list[RecoveryPolicy] = []  # policies that may replan, waiting for their sequence
        root = self._wrapped(spec.tree)
        return CompiledMission(root, spec, self.supervisor, self.nodes)

    def _recovery_for(self, node: NodeSpec) -> RecoverySteps:
        own = node.recovery.model_dump(exclude={"alternative"}) if node.recovery is not None else {}
        if node.category != "skill":  # a composite's failure was already recovered below
            backoff = {"backoff": self.mission_recovery["backoff"]}
            return resolve_recovery(own, backoff, self.robot_recovery)
        info = REGISTRY[node.kind]
        per_skill = self.skill_recovery.get(node.kind, {})
        if info.is_condition:  # a condition's answer is not a fault: mission-wide settings do not apply
            return resolve_recovery(own, per_skill, info.recovery)
        return resolve_recovery(own, per_skill, self.mission_recovery, info.recovery, self.robot_recovery)

    def _alternative_for(self, node: NodeSpec) -> NodeSpec | None:
        if node.alternative is not None:
            return node.alternative
        if node.category == "skill" and not node.path.startswith("recovery."):  # no alternative of an alternative
            return self.skill_alternatives.get(node.kind)
        return None

    def _policy(self, child: Behaviour, steps: RecoverySteps, what: str) -> RecoveryPolicy:
        context = self.context
        return RecoveryPolicy(
            RECOVERY_NAME, child, steps, context.clock, self.supervisor, context.questions, self.on_recovery, what
        )

    def _wrapped(self, node: NodeSpec) -> Behaviour:
        waiting = len(self.awaiting_target)
        inner = self._build(node)
        inner.bt_path = node.path  # type: ignore[attr-defined]
        self.nodes.append((inner, node.path))
        steps = self._recovery_for(node)
        what = node.name or node.kind
        alternative = self._alternative_for(node)
        if alternative is None:
            policy = self._policy(inner, steps, what)
        else:
            # retries stay with the node; its alternative runs when they are spent; replan and ask come after both
            first = SafetyGuard(
                GUARD_NAME,
                self._policy(inner, replace(steps, replan=0, ask=False), what),
                self.supervisor,
                leaf=node.category == "skill",
            )
            either = py_trees.composites.Selector(
                f"{what}, or else", memory=True, children=[first, self._wrapped(alternative)]
            )
            either.bt_path = f"{node.path}.or_else"  # type: ignore[attr-defined]
            self.nodes.append((either, either.bt_path))  # type: ignore[attr-defined]
            policy = self._policy(either, replace(steps, retries=0), what)
        if isinstance(inner, py_trees.composites.Sequence) and node.category != "behavior":
            # a sequence starts over for the nodes below it that replan (up to the next sequence down)
            for below in self.awaiting_target[waiting:]:
                below.replan_target = policy
            del self.awaiting_target[waiting:]
        if steps.replan:
            self.awaiting_target.append(policy)
        return SafetyGuard(GUARD_NAME, policy, self.supervisor, leaf=node.category == "skill" and alternative is None)

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
