"""The tree as it will run, as text: every Safety guard and recovery step the compiler adds, with the values it
resolved and the layer each came from (``bt-validate --expand FILE``)."""

from __future__ import annotations

from py_trees.behaviour import Behaviour

from bt_humanoid.engine.compiler import CompiledMission, Compiler
from bt_humanoid.engine.decorators import Ask, FaultWatch, OrElse, Replan, Retry, SafetyGuard
from bt_humanoid.engine.settings import resolve_safety
from bt_humanoid.mission.spec import MissionSpec
from bt_humanoid.safety.monitors import SafetySupervisor
from bt_humanoid.skills.context import SkillContext

GUARDED = "stop request, collision, joint limit, workspace or time budget violation"
WATCHED = "dropped object, joint strain or lack of progress"


def expand(spec: MissionSpec) -> str:
    """The compiled tree of ``spec`` with its wrappers, one node a line, and the run's safety settings."""
    known = spec.known
    context = SkillContext(known.robot_config, known.world, known.joint_ranges)
    supervisor = SafetySupervisor([], lambda: 0.0)
    compiled = Compiler(context, supervisor).compile(spec)
    limits = resolve_safety(spec.header.safety, known.robot_config.safety)
    lines = [
        f"mission: {spec.header.mission}  ({spec.header.world}, {spec.header.robot})",
        "safety: "
        + "; ".join(
            f"{name} {setting.value:g} {unit} (from {setting.source})"
            for name, unit, setting in (
                ("max_base_speed", "m/s", limits.max_base_speed),
                ("joint_limit_margin", "rad", limits.joint_limit_margin),
                ("time_budget", "s", limits.time_budget),
            )
        ),
        f"safety guard: halts its branch on a {GUARDED}; never recovered",
        f"fault watch: a {WATCHED} fails the skill with the reason, and the recovery above it takes over",
        "",
    ]
    _lines(compiled.root, compiled, "", "", lines)
    return "\n".join(lines) + "\n"


def _lines(node: Behaviour, compiled: CompiledMission, lead: str, indent: str, out: list[str]) -> None:
    out.append(f"{lead}{_describe(node, compiled)}")
    children = node.children
    for index, child in enumerate(children):
        last = index == len(children) - 1
        _lines(child, compiled, indent + ("└─ " if last else "├─ "), indent + ("   " if last else "│  "), out)


def _describe(node: Behaviour, compiled: CompiledMission) -> str:
    """One line for ``node``: a wrapper and what it does, or a mission node with its resolved recovery."""
    if isinstance(node, SafetyGuard):
        return "safety guard"
    if isinstance(node, FaultWatch):
        return "fault watch"
    if isinstance(node, Retry):
        return f"retry ×{node.retries}, {node.backoff:g} s apart"
    if isinstance(node, Replan):
        budgets = ", ".join(f"{b.node} (×{b.limit})" for b in node.budgets.values())
        return f"replan: start this sequence over {node.backoff:g} s later when one of these fails: {budgets}"
    if isinstance(node, Ask):
        when = " once its replans are spent" if node.replan is not None and node.replan.sequence else ""
        return f"ask whether to try {node.what} again{when} (where someone can answer)"
    if isinstance(node, OrElse):
        return "or else: the alternative below, once the node and its retries failed"
    path = getattr(node, "bt_path", "")
    resolved = compiled.recovery[path]
    steps, sources = resolved.steps, resolved.sources
    values = {"retries": steps.retries, "backoff": f"{steps.backoff:g} s", "replan": steps.replan}
    values["ask"] = "yes" if steps.ask else "no"
    shown = ", ".join(f"{name} {value} ({sources[name]})" for name, value in values.items())
    return f"{node.name}  [{path}]  recovery: {shown}"
