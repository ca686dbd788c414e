"""The behaviour tree, live in the terminal (rich), or as plain status lines."""

from __future__ import annotations

import time
from typing import Any

from py_trees.behaviour import Behaviour
from py_trees.common import Status
from rich.console import Console, Group
from rich.live import Live
from rich.text import Text
from rich.tree import Tree

from bt_humanoid.engine.decorators import RECOVERY_STEPS, Ask, OrElse, Replan, Retry, SafetyGuard
from bt_humanoid.engine.executor import Executor

STYLE = {
    Status.RUNNING: ("●", "bold yellow"),
    Status.SUCCESS: ("✔", "green"),
    Status.FAILURE: ("✘", "bold red"),
    Status.INVALID: ("○", "dim"),
}


def _unwrap(node: Behaviour) -> tuple[Behaviour, SafetyGuard | None, list[Behaviour]]:
    """The mission node under its Safety guard and recovery steps (an "or else" is a node of its own)."""
    guard = None
    steps: list[Behaviour] = []
    if isinstance(node, SafetyGuard):
        guard, node = node, node.decorated
    while isinstance(node, RECOVERY_STEPS) and not isinstance(node, OrElse):
        steps.append(node)
        node = node.decorated
    return node, guard, steps


def _badges(steps: list[Behaviour]) -> str:
    """What the recovery steps are doing: retries made, replans made, a question out."""
    shown = []
    for step in steps:
        if isinstance(step, Retry) and step.failures:
            shown.append(f"↻ {step.failures}/{step.retries}")
        elif isinstance(step, Replan):
            used = [f"{b.used}/{b.limit}" for b in step.budgets.values() if b.used]
            shown += [f"⟲ replan {u}" for u in used]
        elif isinstance(step, Ask) and step.asking:
            shown.append("? asking")
    return "  ".join(shown)


def _line(node: Behaviour, guard: SafetyGuard | None, steps: list[Behaviour]) -> Text:
    icon, style = STYLE[node.status]
    text = Text(f"{icon} ", style=style)
    text.append(node.name, style=style if node.status is not Status.INVALID else "")
    badges = _badges(steps)
    if badges:
        text.append(f"  {badges}", style="magenta")
    if guard is not None and guard.status is Status.FAILURE and guard.feedback_message.startswith("safety"):
        text.append(f"  ⛔ {guard.feedback_message}", style="bold red")
    elif node.status is Status.RUNNING and node.feedback_message and not node.children:
        text.append(f"  {node.feedback_message}", style="cyan")
    elif node.status is Status.FAILURE and node.feedback_message:
        text.append(f"  {node.feedback_message}", style="red")
    return text


def render_tree(root: Behaviour) -> Tree:
    """A rich Tree of the mission's nodes with status colours, wrappers folded into badges."""
    node, guard, steps = _unwrap(root)
    tree = Tree(_line(node, guard, steps), guide_style="dim")

    def add(branch: Tree, parent: Behaviour) -> None:
        for child in parent.children:
            inner, child_guard, child_steps = _unwrap(child)
            sub = branch.add(_line(inner, child_guard, child_steps))
            add(sub, inner)

    add(tree, node)
    return tree


class LiveTreeView:
    """Redraws the tree at most ``fps`` times per wall-clock second while the executor ticks."""

    def __init__(self, executor: Executor, console: Console | None = None, fps: float = 8.0) -> None:
        self.executor = executor
        self.console = console or Console()
        self.period = 1.0 / fps
        self.last_draw = 0.0
        self.started = time.perf_counter()
        self.live = Live(self._render(), console=self.console, auto_refresh=False, transient=False)

    def _render(self) -> Group:
        sim_time = self.executor.sim.time
        wall = max(time.perf_counter() - self.started, 1e-9)
        header = Text.assemble(
            (f"{self.executor.compiled.spec.header.mission}", "bold"),
            f"   sim {sim_time:6.2f} s   ×{sim_time / wall:5.1f} real time",
        )
        return Group(header, render_tree(self.executor.root))

    def on_tick(self, executor: Executor) -> None:
        now = time.perf_counter()
        if now - self.last_draw >= self.period:
            self.last_draw = now
            self.live.update(self._render(), refresh=True)

    def __enter__(self) -> LiveTreeView:
        self.started = time.perf_counter()
        self.live.__enter__()
        self.executor.tick_listeners.append(self.on_tick)
        return self

    def __exit__(self, *exc: Any) -> None:
        self.live.update(self._render(), refresh=True)
        self.live.__exit__(*exc)
        self.executor.tick_listeners.remove(self.on_tick)


def print_event(console: Console, event: dict[str, Any]) -> None:
    """One plain line per status change, utterance or safety stop."""
    stamp = f"[{event['t']:8.2f}s]"
    kind = event["event"]
    if kind == "status":
        feedback = f"  {event['feedback']}" if event["feedback"] else ""
        console.print(f"{stamp} {event['new']:<8} {event['node']}{feedback}", markup=False, highlight=False)
    elif kind == "say":
        console.print(f"{stamp} SAY      {event['text']}", markup=False, highlight=False)
    elif kind == "retry":
        console.print(f"{stamp} RETRY    {event['node']}  {event['message']}", markup=False, highlight=False)
    elif kind == "safety":
        console.print(f"{stamp} SAFETY   {event['monitor']}: {event['message']}", markup=False, highlight=False)
    elif kind in ("rest", "moving"):
        state = "robot at rest" if kind == "rest" else "robot STILL MOVING"
        console.print(
            f"{stamp} {kind.upper():<8} {state} (max speed {event['max_speed']:.3f})", markup=False, highlight=False
        )
    elif kind == "timeout":
        console.print(f"{stamp} TIMEOUT  {event['message']}", markup=False, highlight=False)
