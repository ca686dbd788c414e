"""Composites that py_trees does not have."""

from __future__ import annotations

from collections.abc import Iterator

import py_trees
from py_trees.common import Status


class RoundRobin(py_trees.composites.Composite):
    """One child per run, taking turns (Nav2's RoundRobin): its status is that child's.

    The first time the node starts it runs its first child, the next time its
    second, and so on, wrapping around. Used for recovery: each failure of
    the task gets the next recovery action instead of the same one again.
    """

    def __init__(self, name: str, children: list[py_trees.behaviour.Behaviour]) -> None:
        super().__init__(name, children)
        self.turn = 0  # how many runs have started

    def tick(self) -> Iterator[py_trees.behaviour.Behaviour]:
        if not self.children:
            self.stop(Status.FAILURE)
            yield self
            return
        if self.status != Status.RUNNING:
            self.current_child = self.children[self.turn % len(self.children)]
            self.turn += 1
            self.initialise()
        child = self.current_child
        yield from child.tick()
        if child.status != Status.RUNNING:
            self.stop(child.status)
        else:
            self.status = Status.RUNNING
        yield self
