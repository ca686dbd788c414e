"""The event log: what happened, in simulation time, one JSON object per line."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any


class EventLog:
    """Status changes, safety violations and run milestones, in order.

    Nothing here reads the wall clock, so the same mission and seed give the
    same log.
    """

    def __init__(self) -> None:
        self.events: list[dict[str, Any]] = []
        self.listeners: list[Callable[[dict[str, Any]], None]] = []

    def add(self, time: float, event: str, **fields: Any) -> None:
        entry = {"t": round(time, 4), "event": event, **fields}
        self.events.append(entry)
        for listener in self.listeners:
            listener(entry)

    def status(self, time: float, node: str, old: str, new: str, feedback: str) -> None:
        self.add(time, "status", node=node, old=old, new=new, feedback=feedback)

    def lines(self) -> list[str]:
        return [json.dumps(event, sort_keys=True) for event in self.events]

    def write(self, path: Path) -> None:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("\n".join(self.lines()) + "\n")
