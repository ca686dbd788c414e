"""Errors a user can cause. The CLI prints them as one line and exits 2."""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from typing import Any

from pydantic import ValidationError


class UserError(Exception):
    """Invalid input: a mission, a parameter, a name. Carries where and what would be valid."""

    def __init__(self, message: str, where: str | None = None, hint: str | None = None) -> None:
        self.message = message
        self.where = where
        self.hint = hint
        super().__init__(str(self))

    def __str__(self) -> str:
        text = f"{self.where}: {self.message}" if self.where else self.message
        if self.hint:
            text += f" ({self.hint})"
        return text


def did_you_mean(name: str, options: Iterable[str]) -> str:
    """'did you mean X?' plus the valid choices, for unknown-name messages."""
    options = sorted(set(options))
    close = difflib.get_close_matches(name, options, n=1, cutoff=0.6)
    valid = ", ".join(options)
    if close:
        return f"did you mean '{close[0]}'? valid: {valid}"
    return f"valid: {valid}"


def describe_validation_error(error: ValidationError) -> tuple[tuple[Any, ...], str]:
    """The first pydantic error as (location, message phrased for people).

    The location points at the offending key, or at the mapping that lacks a
    required one.
    """
    first = error.errors()[0]
    location = tuple(first["loc"])
    field = ".".join(str(part) for part in location)
    kind = first["type"]
    if kind == "missing":
        return location[:-1], f"missing required parameter '{field}'"
    if kind == "extra_forbidden":
        return location, f"unknown parameter '{field}'"
    got = first.get("input")
    shown = f" (got {got!r})" if got is not None and not isinstance(got, dict | list) else ""
    return location, f"{field + ': ' if field else ''}{first['msg']}{shown}"
