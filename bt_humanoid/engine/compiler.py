"""MissionSpec → py_trees tree, every composite and leaf under a Safety guard and its recovery steps.

The compiler owns safety: whatever produced the spec (a person, a behaviour library, a planner), each node it
emits sits under a SafetyGuard reading the one SafetySupervisor, and between the two the recovery steps the
node's settings ask for (engine/decorators.py: ask, or else, retry, replan on sequences, a fault watch on
skills). Each setting is resolved once, here, from the first layer that sets it: the node's ``recovery:``, the
mission's ``recovery.skills.<skill>``, the mission's ``recovery:``, the skill's own default, the robot's
``recovery:`` in robot.yaml; ``CompiledMission.recovery`` keeps what was resolved and from where
(``bt-validate --expand`` prints it).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any

import py_trees
from py_trees.behaviour import Behaviour
from py_trees.common import ParallelPolicy

from bt_humanoid.engine.composites import RoundRobin
from bt_humanoid.engine.decorators import (
    Ask,
    FaultWatch,
    OrElse,
    RecoveryLog,
    RecoverySteps,
    Replan,
    ReplanBudget,
    Retry,
    SafetyGuard,
    SimTimeout,
)
from bt_humanoid.mission.spec import MissionSpec, NodeSpec
from bt_humanoid.safety.monitors import SafetySupervisor
from bt_humanoid.skills import REGISTRY
from bt_humanoid.skills.context import SkillContext

GUARD_NAME = "safety"
DEFAULT = "built-in default"

#: a layer of recovery settings: (where it is written, its fields)
Layer = tuple[str, Mapping[str, Any]]


@dataclass(frozen=True)
class ResolvedRecovery:
    """A node's recovery steps, and the layer each came from."""

    steps: RecoverySteps
    sources: dict[str, str]


@dataclass
class CompiledMission:
    root: Behaviour
    spec: MissionSpec
    supervisor: SafetySupervisor
    #: (node, path) of every node the mission describes, wrappers excluded
    nodes: list[tuple[Behaviour, str]] = field(default_factory=list)
    #: path → the recovery resolved for the node there
    recovery: dict[str, ResolvedRecovery] = field(default_factory=dict)


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


def resolve_recovery(*layers: Layer) -> ResolvedRecovery:
    """Each field from the first layer that sets it (layers: most specific first); unset fields keep defaults."""
    found: dict[str, Any] = {}
    sources: dict[str, str] = {}
    for name in (f.name for f in fields(RecoverySteps)):
        where, value = next(((w, layer[name]) for w, layer in layers if layer.get(name) is not None), (DEFAULT, None))
        if value is not None:
            found[name] = value
        sources[name] = where
    return ResolvedRecovery(RecoverySteps(**found), sources)


class Compiler:
    def __init__(self, context: SkillContext, supervisor: SafetySupervisor, log: RecoveryLog | None = None) -> None:
        self.context = context
        self.supervisor = supervisor
        self.log = log

    def compile(self, spec: MissionSpec) -> CompiledMission:
        section = spec.header.recovery
        self.robot_recovery = ("robot.yaml recovery:", self.context.robot_config.recovery.model_dump())
        self.mission_recovery = ("mission recovery:", section.model_dump(exclude={"skills"}))
        self.skill_recovery = {name: s.model_dump(exclude={"alternative"}) for name, s in section.skills.items()}
        self.skill_alternatives = spec.skill_alternatives
        self.compiled = CompiledMission(None, spec, self.supervisor)  # type: ignore[arg-type]
        self.replanning: list[tuple[Behaviour, ReplanBudget]] = []  # nodes that may replan, awaiting their sequence
        self.compiled.root = self._wrapped(spec.tree)
        return self.compiled

    def _recovery_for(self, node: NodeSpec) -> ResolvedRecovery:
        own = ("node recovery:", node.recovery.model_dump(exclude={"alternative"}) if node.recovery else {})
        if node.category != "skill":  # a composite's failure was already recovered below
            backoff = (self.mission_recovery[0], {"backoff": self.mission_recovery[1]["backoff"]})
            return resolve_recovery(own, backoff, self.robot_recovery)
        info = REGISTRY[node.kind]
        per_skill = (f"mission recovery.skills.{node.kind}:", self.skill_recovery.get(node.kind, {}))
        default = (f"{node.kind}'s default", info.recovery)
        if info.is_condition:  # a condition's answer is not a fault: mission-wide settings do not apply
            return resolve_recovery(own, per_skill, default)
        return resolve_recovery(own, per_skill, self.mission_recovery, default, self.robot_recovery)

    def _alternative_for(self, node: NodeSpec) -> NodeSpec | None:
        if node.alternative is not None:
            return node.alternative
        if node.category == "skill" and not node.path.startswith("recovery."):  # no alternative of an alternative
            return self.skill_alternatives.get(node.kind)
        return None

    def _wrapped(self, node: NodeSpec) -> Behaviour:
        """``node`` compiled, under its recovery steps and its Safety guard (outermost)."""
        below = len(self.replanning)
        inner = self._build(node)
        inner.bt_path = node.path  # type: ignore[attr-defined]
        self.compiled.nodes.append((inner, node.path))
        resolved = self._recovery_for(node)
        self.compiled.recovery[node.path] = resolved
        steps, what = resolved.steps, node.name or node.kind
        clock, supervisor = self.context.clock, self.supervisor
        wrapped = inner
        if node.category == "skill":
            wrapped = FaultWatch("faults", wrapped, supervisor)
        if steps.retries:
            wrapped = self._logged(Retry(wrapped, node.path, steps.retries, steps.backoff, clock, supervisor))
        if isinstance(inner, py_trees.composites.Sequence) and node.category != "behavior":
            # this sequence starts over for the nodes below it that may replan (up to the next sequence down),
            # once its own retries are spent (outside them, so a retry does not renew the replans)
            claimed, self.replanning[below:] = self.replanning[below:], []
            if claimed:
                wrapped = self._logged(Replan(wrapped, node.path, what, steps.backoff, clock, supervisor))
                for top, budget in claimed:
                    wrapped.watch(top, budget)
        alternative = self._alternative_for(node)
        if alternative is not None:
            wrapped = OrElse(what, wrapped, self._wrapped(alternative))
            wrapped.bt_path = f"{node.path}.or_else"  # type: ignore[attr-defined]
            self.compiled.nodes.append((wrapped, wrapped.bt_path))  # type: ignore[attr-defined]
        budget = ReplanBudget(node.path, what, steps.replan) if steps.replan else None
        if steps.ask:
            questions = self.context.questions
            wrapped = self._logged(Ask(wrapped, node.path, what, questions, budget, clock, supervisor))
        guard = SafetyGuard(GUARD_NAME, wrapped, supervisor)
        if budget is not None:
            self.replanning.append((guard, budget))
        return guard

    def _logged(self, step):
        step.log = self.log
        return step

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
