"""Condition and assignment leaves on blackboard values."""

from __future__ import annotations

from typing import Any, Literal

from py_trees.common import Status
from pydantic import Field

from bt_humanoid.skills.base import Skill
from bt_humanoid.skills.registry import skill
from bt_humanoid.strict_model import StrictModel

_COMPARISONS = {
    "equals": lambda a, b: a == b,
    "not_equals": lambda a, b: a != b,
    "less": lambda a, b: a < b,
    "greater": lambda a, b: a > b,
}


class CheckParams(StrictModel):
    key: str = Field(description="blackboard key")
    op: Literal["exists", "equals", "not_equals", "less", "greater"] = Field("equals", description="comparison")
    value: Any = Field(None, description="value to compare with (not used by exists)")


@skill("check", "succeed if a blackboard value passes a comparison, fail otherwise", condition=True)
class Check(Skill):
    Params = CheckParams

    def poll(self) -> Status:
        p: CheckParams = self.params
        board = self.context.blackboard
        if p.op == "exists":
            ok = p.key in board
        elif p.key not in board:
            ok = False
        else:
            try:
                ok = bool(_COMPARISONS[p.op](board.get(p.key), p.value))
            except TypeError:
                ok = False
        if p.op == "exists":
            self.feedback_message = f"{p.key} is {'' if ok else 'not '}on the blackboard"
        else:
            self.feedback_message = f"{p.key} {p.op} {p.value!r}: {'yes' if ok else 'no'}"
        return Status.SUCCESS if ok else Status.FAILURE


class SetParams(StrictModel):
    key: str = Field(description="blackboard key")
    value: Any = Field(description="value to store")


@skill("set", "store a value on the blackboard")
class Set(Skill):
    Params = SetParams

    def start(self) -> None:
        self.context.blackboard.set(self.params.key, self.params.value)
        self.feedback_message = f"{self.params.key} = {self.params.value!r}"
